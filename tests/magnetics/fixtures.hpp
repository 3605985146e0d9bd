// tests/magnetics/fixtures.hpp — small magnetic configurations shared by the core tests.
#pragma once

#include "magnetics/moments.hpp"

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

}  // namespace magsim::test
