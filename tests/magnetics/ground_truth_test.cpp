// Tests for magnetics/ground_truth.cpp: Newton on M = f(H(M)) and the analytic answers.
#include "magnetics/ground_truth.hpp"
#include "magnetics/curves.hpp"
#include "tests/magnetics/fixtures.hpp"

#include <catch2/catch.hpp>

using namespace magsim::mag;
using magsim::test::ball_volume;
using magsim::test::kIronMs;

TEST_CASE("soft-iron sphere: M = 3 H0 in a weak field, |M| → Ms in a strong one", "[exact]") {
  for (Curve c : {Curve::Tanh, Curve::Kim}) {
    MomentSet s;
    s.add_induced(Vec3::Zero(), ball_volume(), kIronMs);
    s.H0 = Vec3(300.0, -400.0, 1200.0);  // 1.3 kA/m ≪ Ms
    REQUIRE(solve_exact(&s, c, FieldOptions{}).converged);
    CHECK(s.M[0].isApprox(3.0 * s.H0, 1e-5));
    s.H0 = Vec3(0, 0, 10 * kIronMs);
    REQUIRE(solve_exact(&s, c, FieldOptions{}).converged);
    CHECK(s.M[0].norm() == Approx(kIronMs).epsilon(1e-9));
  }
}

TEST_CASE("two touching spheres along a weak field: moment is 4/3 of the isolated one",
          "[exact]") {
  // point dipoles at 2a on the field axis: H = H0 + 2 V M/(4π (2a)³) = H0 + M/12, and
  // M = 3H gives M = 4 H0 = (4/3)·3 H0
  const double a = magsim::test::kBallRadius;
  MomentSet s;
  s.add_induced(Vec3(0, 0, -a), ball_volume(a), kIronMs);
  s.add_induced(Vec3(0, 0, a), ball_volume(a), kIronMs);
  s.H0 = Vec3(0, 0, 1000.0);
  REQUIRE(solve_exact(&s, Curve::Tanh, FieldOptions{}).converged);
  for (int j = 0; j < 2; ++j) CHECK(s.M[j].isApprox(Vec3(0, 0, 4.0 / 3.0 * 3.0 * 1000.0), 1e-5));
}

TEST_CASE("ground truth residual ≤ 1e-12 on a strong cluster, both curves", "[exact]") {
  for (Curve c : {Curve::Tanh, Curve::Kim}) {
    MomentSet s = magsim::test::cluster(500.0);
    const ExactStats st = solve_exact(&s, c, FieldOptions{});
    INFO("Newton steps " << st.newton_steps << ", residual " << st.residual);
    CHECK(st.converged);
    CHECK(st.residual <= 1e-12);
    CHECK(st.newton_steps <= 10);
    // independent check of the residual with the field kernel
    MagWorkspace ws;
    compute_fields(s, FieldOptions{}, &ws.H, nullptr, &ws.field);
    double num = 0, den = 0;
    for (std::size_t j = 0; j < s.size(); ++j) {
      if (s.kind[j] != MomentKind::Induced) continue;
      num += (s.M[j] - curve_M(c, ws.H[j], s.Ms[j])).squaredNorm();
      den += s.M[j].squaredNorm();
    }
    CHECK(std::sqrt(num / den) <= 1e-12);
  }
}
