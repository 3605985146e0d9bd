// tests/magnetics/fixtures.hpp — small magnetic configurations shared by the core tests.
#pragma once

#include "magnetics/field_kernel.hpp"
#include "magnetics/moments.hpp"

#include <cmath>
#include <random>

namespace magsim::test {

using mag::MomentSet;
using mag::Vec3;

inline constexpr double kBallRadius = 5e-3;  // iron ball, 5 mm
inline constexpr double kIronMs = 1.6e6;     // A/m
inline double ball_volume(double a = kBallRadius) { return 4.0 / 3.0 * mag::kPi * a * a * a; }

/// 3×3×4 iron balls (radius 5 mm, pitch 11 mm) below a 1 cm cube permanent magnet of
/// moment m_z (A·m²) centred 1 cm above the top layer's gap. m_z = 10: weak (|H| ≤ 0.09 Ms,
/// |M| ≤ 0.26 Ms); m_z = 500: strong (|H| up to 4.7 Ms, balls near the magnet saturated).
inline MomentSet cluster(double m_z) {
  MomentSet s;
  const double a = kBallRadius;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 4; ++k)
        s.add_induced(Vec3((i - 1) * 2.2 * a, (j - 1) * 2.2 * a, -0.012 - k * 2.2 * a),
                      ball_volume(), kIronMs);
  const double L = 0.01;
  s.add_permanent(Vec3(0, 0, L), L * L * L, Vec3(0, 0, m_z));
  return s;
}

/// n induced moments at random, at least 2.5 radii apart, in a 6 cm box, plus two
/// permanent magnets; seeded, so the same every run.
inline MomentSet random_cloud(int n, unsigned seed, double magnet_strength = 30.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  MomentSet s;
  std::vector<Vec3> pts;
  while (static_cast<int>(pts.size()) < n) {
    const Vec3 p(u(rng), u(rng), u(rng));
    bool ok = true;
    for (const Vec3& q : pts) ok = ok && (p - q).norm() > 2.5 * kBallRadius;
    if (ok && p.norm() > 0.012) pts.push_back(p);
  }
  for (const Vec3& p : pts) s.add_induced(p, ball_volume(), kIronMs);
  s.add_permanent(Vec3(0, 0, 0), 1e-6, Vec3(0.3, -0.2, 1.0).normalized() * magnet_strength);
  s.add_permanent(Vec3(0.05, 0.0, 0.0), 1e-6, Vec3(0, 1, 0) * magnet_strength * 0.5);
  s.H0 = Vec3(2e3, -1e3, 5e2);
  return s;
}

/// n iron balls (radius 5 mm) at random in a cube at 5 % volume fraction (no overlaps),
/// each magnetized independently: |M| uniform in [0.05, 0.6] Ms, any direction. No external
/// field: H is the dipole sum alone — the hard case for a far-field approximation.
inline MomentSet sparse_cloud(int n, unsigned seed) {
  const double L = std::cbrt(n * ball_volume() / 0.05);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, L), x(0.05, 0.6);
  std::normal_distribution<double> g;
  std::vector<Vec3> pts;
  while (static_cast<int>(pts.size()) < n) {
    const Vec3 p(u(rng), u(rng), u(rng));
    bool ok = true;
    for (const Vec3& q : pts) ok = ok && (p - q).squaredNorm() >= 4 * kBallRadius * kBallRadius;
    if (ok) pts.push_back(p);
  }
  MomentSet s;
  for (const Vec3& p : pts) {
    const int j = s.add_induced(p, ball_volume(), kIronMs);
    s.set_magnetization(j, x(rng) * kIronMs * Vec3(g(rng), g(rng), g(rng)).normalized());
  }
  return s;
}

/// n touching iron balls (radius 5 mm) in an FCC packing filled layer by layer on a square
/// footprint (a pile about three times as wide as high), with a permanent magnet (m = 10
/// A·m², along −z) 2 cm above the middle of the top and a uniform H0 = 0.01 Ms ẑ; each ball
/// magnetized to f(H_magnet + H0) (eq. 10) — a smooth, scene-like state.
inline MomentSet fcc_pile(int n) {
  const double d = 2.0 * kBallRadius * 1.001;
  const double a = d * std::sqrt(2.0);
  const double W = std::cbrt(3.0 * n * ball_volume() / 0.74);
  const int nxy = static_cast<int>(std::ceil(W / a));
  std::vector<Vec3> pts;
  for (int k = 0; static_cast<int>(pts.size()) < n; ++k)
    for (const Vec3& b : {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0), Vec3(0.5, 0, 0.5), Vec3(0, 0.5, 0.5)})
      for (int i = 0; i < nxy; ++i)
        for (int j = 0; j < nxy; ++j)
          if (static_cast<int>(pts.size()) < n) pts.push_back(a * (Vec3(i, j, k) + b));
  Vec3 hi = pts[0];
  for (const Vec3& p : pts) hi = hi.cwiseMax(p);
  const Vec3 pm(0.5 * hi.x(), 0.5 * hi.y(), hi.z() + 0.02), mm(0, 0, -10.0);
  MomentSet s;
  s.H0 = Vec3(0, 0, 0.01 * kIronMs);
  for (const Vec3& p : pts) {
    const int j = s.add_induced(p, ball_volume(), kIronMs);
    const Vec3 r = p - pm;
    const double r2 = r.squaredNorm();
    const Vec3 Hm = (3.0 * r * r.dot(mm) / r2 - mm) / (4.0 * mag::kPi * r2 * std::sqrt(r2));
    const Vec3 H = s.H0 + Hm;  // eq. 10 on the magnet's field (eq. 1) and H0
    s.set_magnetization(j, kIronMs * std::tanh(3.0 * H.norm() / kIronMs) * H.normalized());
  }
  s.add_permanent(pm, 8e-6, mm);
  return s;
}

/// Says so in the test output when this CPU has no AVX-512 (or it is switched off): then a
/// SIMD-vs-portable comparison compares the FMA or generic path with itself and the slower
/// ones, and proves nothing about the AVX-512 kernels. Call at the top of such a test.
#define MAGSIM_NOTE_IF_NO_SIMD()                                                              \
  do {                                                                                      \
    if (!magsim::mag::detail::simd_kernel_active())                                         \
      WARN("no AVX-512 here: the SIMD-vs-portable comparison compares the portable path "   \
           "with itself");                                                                  \
  } while (0)

}  // namespace magsim::test
