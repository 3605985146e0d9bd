// tests/magnetics/barnes_hut_helpers.hpp — what the Barnes–Hut tests share: the error of
// one field evaluation against another, the evaluations they compare (Barnes–Hut against
// the direct sum, SIMD against portable kernels) and the "letters" configuration.
#pragma once

#include "magnetics/barnes_hut.hpp"
#include "magnetics/dipole_field.hpp"
#include "magnetics/field_kernel.hpp"
#include "magnetics/fields.hpp"
#include "tests/magnetics/fixtures.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace magsim::test::bh {

using namespace magsim::mag;


struct Errors {
  double h_max = 0, h_rms = 0;  // max_j |ΔH_j|/|H_j|, √(Σ|ΔH|²/Σ|H|²)
  double j_max = 0, j_rms = 0;  // the same for J (Frobenius)
};

inline Errors compare(const std::vector<Vec3>& H, const std::vector<Mat3>& J,
               const std::vector<Vec3>& Href, const std::vector<Mat3>& Jref) {
  Errors e;
  double hn = 0, hd = 0, jn = 0, jd = 0;
  for (std::size_t i = 0; i < H.size(); ++i) {
    const double dh = (H[i] - Href[i]).norm(), dj = (J[i] - Jref[i]).norm();
    e.h_max = std::max(e.h_max, dh / Href[i].norm());
    e.j_max = std::max(e.j_max, dj / Jref[i].norm());
    hn += dh * dh;
    hd += Href[i].squaredNorm();
    jn += dj * dj;
    jd += Jref[i].squaredNorm();
  }
  e.h_rms = std::sqrt(hn / hd);
  e.j_rms = std::sqrt(jn / jd);
  return e;
}

inline Errors bh_errors(const MomentSet& s, FieldOptions bh) {
  FieldOptions direct = bh;
  direct.solver = FieldSolver::Direct;
  bh.solver = FieldSolver::BarnesHut;
  FieldWorkspace ws;
  std::vector<Vec3> H0, H1;
  std::vector<Mat3> J0, J1;
  compute_fields(s, direct, &H0, &J0, &ws);
  compute_fields(s, bh, &H1, &J1, &ws);
  return compare(H1, J1, H0, J0);
}

// The same evaluation on the fastest kernel path and on each slower one (FMA, generic):
// the largest difference from the fastest.
inline Errors simd_vs_portable(const MomentSet& s, const FieldOptions& o) {
  MAGSIM_NOTE_IF_NO_SIMD();
  FieldWorkspace ws;
  std::vector<Vec3> H1, H2;
  std::vector<Mat3> J1, J2;
  compute_fields(s, o, &H1, &J1, &ws);
  Errors worst;
  for (detail::KernelPath p : {detail::KernelPath::Fma, detail::KernelPath::Generic}) {
    detail::limit_kernel_path(p);
    compute_fields(s, o, &H2, &J2, &ws);
    const Errors e = compare(H1, J1, H2, J2);
    worst.h_max = std::max(worst.h_max, e.h_max);
    worst.h_rms = std::max(worst.h_rms, e.h_rms);
    worst.j_max = std::max(worst.j_max, e.j_max);
    worst.j_rms = std::max(worst.j_rms, e.j_rms);
  }
  detail::limit_kernel_path(detail::KernelPath::Avx512);
  return worst;
}

inline FieldOptions bh_options(double theta) {
  FieldOptions o;
  o.solver = FieldSolver::BarnesHut;
  o.bh_theta = theta;
  return o;
}

// 160 rigid "letters" of 5 moments each (group ids 0…159, a 1 cm cross) scattered in a
// 40 cm box, plus 200 free balls (no group) and some zero moments.
inline MomentSet letters() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 0.4);
  std::normal_distribution<double> g;
  MomentSet s;
  const double V = magsim::test::ball_volume(2e-3), Ms = magsim::test::kIronMs;
  for (int l = 0; l < 160; ++l) {
    const Vec3 c(u(rng), u(rng), u(rng));
    for (const Vec3& o : {Vec3(0, 0, 0), Vec3(5e-3, 0, 0), Vec3(-5e-3, 0, 0), Vec3(0, 5e-3, 0),
                          Vec3(0, 0, 5e-3)}) {
      const int j = s.add_induced(c + o, V, Ms, l);
      s.set_magnetization(j, 0.5 * Ms * Vec3(g(rng), g(rng), g(rng)).normalized());
    }
  }
  for (int k = 0; k < 220; ++k) {
    const int j = s.add_induced(Vec3(u(rng), u(rng), u(rng)), V, Ms);
    if (k < 200) s.set_magnetization(j, 0.3 * Ms * Vec3(g(rng), g(rng), g(rng)).normalized());
  }
  return s;
}

inline bool same_bits(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}
inline bool same_bits(const std::vector<Mat3>& a, const std::vector<Mat3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Mat3)) == 0;
}

}  // namespace magsim::test::bh
