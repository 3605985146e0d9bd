// Paper Fig. 8 and §6.3 on crystal_balls (178 fixed balls around a bar magnet): the
// magnetization dynamics alone, against each method's own ground truth (eq. 12).
#include "magnetics/ground_truth.hpp"
#include "scenes/moment_set.hpp"
#include "scenes/registry.hpp"

#include <catch2/catch.hpp>

using namespace magsim;
using mag::Method;

namespace {

mag::MomentSet crystal(double strength) {
  scenes::SceneParams p;
  p.strength = strength;
  return scenes::moment_set_at_rest(scenes::find_scene("crystal_balls")->build(p));
}

struct Fig8 {
  int to_1e4 = -1;  // first iteration with e_M ≤ 1e-4 (−1: never within the window)
  double final_e = 0;
  mag::MomentSet end;
};

Fig8 fig8(double strength, Method m, int iters = 999) {
  const mag::MomentSet base = crystal(strength);
  mag::MomentSet gt = base;
  REQUIRE(mag::solve_exact(&gt, mag::curve_of(m), {}).converged);
  Fig8 r;
  r.end = base;
  mag::DynamicsOptions o;
  o.method = m;
  o.max_iter = iters;
  o.tol = 1e-300;  // the whole window: e_M is what is measured
  mag::MagWorkspace ws;
  mag::relax_magnetization(&r.end, o, &ws, [&](int k, const mag::MomentSet& s) {
    r.final_e = mag::magnetization_error(s, gt.M);
    if (r.to_1e4 < 0 && r.final_e <= 1e-4) r.to_1e4 = k;
  });
  return r;
}

constexpr double kStrong = 1.0;  // |H| up to 6 Ms at the balls nearest the poles
constexpr double kWeak = 0.05;   // |H| ≤ 0.24 Ms

}  // namespace

TEST_CASE("crystal_balls strong magnet: ours converges and Kim 2018 and damping-only LLG do not",
          "[stability][fig8]") {
  // measured: ours and ours-realigned reach e_M ≤ 1e-4 at sweep 15; Kim 2018 and
  // damping-only LLG end the 999 sweeps at e_M ≈ 0.24 (paper Fig. 8, red curves)
  for (Method m : {Method::Ours, Method::OursRealigned}) {
    const Fig8 r = fig8(kStrong, m);
    INFO(mag::method_name(m) << ": e_M ≤ 1e-4 at " << r.to_1e4);
    CHECK(r.to_1e4 > 0);
    CHECK(r.to_1e4 <= 60);
  }
  for (Method m : {Method::Kim2018, Method::DampingLLG}) {
    const Fig8 r = fig8(kStrong, m);
    INFO(mag::method_name(m) << ": final e_M " << r.final_e);
    CHECK(r.to_1e4 < 0);
    CHECK(r.final_e > 1e-2);
  }
}

TEST_CASE("crystal_balls weak magnet: every dynamics converges within 999 sweeps",
          "[stability][fig8]") {
  // measured sweeps to e_M ≤ 1e-4: ours-realigned 35, ours 315, Kim 2018 554, damping-only
  // LLG 566 (paper Fig. 8 green curves: Kim slow, ours fast)
  const Fig8 re = fig8(kWeak, Method::OursRealigned);
  const Fig8 ours = fig8(kWeak, Method::Ours);
  const Fig8 kim = fig8(kWeak, Method::Kim2018);
  const Fig8 dll = fig8(kWeak, Method::DampingLLG);
  INFO("sweeps to 1e-4: realigned " << re.to_1e4 << ", ours " << ours.to_1e4 << ", kim "
                                    << kim.to_1e4 << ", damping-llg " << dll.to_1e4);
  CHECK(re.to_1e4 > 0);
  CHECK(re.to_1e4 <= 80);
  CHECK(ours.to_1e4 > 0);
  CHECK(kim.to_1e4 > 0);
  CHECK(dll.to_1e4 > 0);
  CHECK(ours.to_1e4 < kim.to_1e4);
}

TEST_CASE("crystal_balls weak magnet: the gap between Kim 2018 and ours is the curves' gap",
          "[stability][uniqueness]") {
  // paper §6.3: mean |M_K − M_O|/|M_K| ≈ 0.08 %. Measured here: 3.1 %, and the two curves'
  // own ground truths (eq. 7 against eq. 10) differ by the same 3.1 %: both dynamics reach
  // their own curve's unique solution; the 1 % agreement does not reproduce because
  // tanh(x)/x departs from 1 at |H| ≈ 0.1–0.24 Ms.
  const Fig8 kim = fig8(kWeak, Method::Kim2018);
  const Fig8 ours = fig8(kWeak, Method::OursRealigned);
  mag::MomentSet gk = crystal(kWeak), go = gk;
  REQUIRE(mag::solve_exact(&gk, mag::Curve::Kim, {}).converged);
  REQUIRE(mag::solve_exact(&go, mag::Curve::Tanh, {}).converged);
  double dyn = 0, gt = 0;
  int n = 0;
  for (std::size_t j = 0; j < gk.size(); ++j) {
    if (gk.kind[j] != mag::MomentKind::Induced) continue;
    dyn += (kim.end.M[j] - ours.end.M[j]).norm() / kim.end.M[j].norm();
    gt += (gk.M[j] - go.M[j]).norm() / gk.M[j].norm();
    ++n;
  }
  dyn /= n;
  gt /= n;
  INFO("mean |M_K − M_O|/|M_K|: dynamics " << dyn << ", ground truths " << gt);
  CHECK(dyn == Approx(gt).epsilon(0.02));
  CHECK(gt > 0.01);
}
