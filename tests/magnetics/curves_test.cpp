// Tests for magnetics/curves.cpp: eq. 10 and eq. 7, their Jacobians, the γ_C of eq. 11.
#include "magnetics/curves.hpp"

#include <catch2/catch.hpp>
#include <cmath>

using namespace magsim::mag;

namespace {
Mat3 fd_dMdH(Curve c, const Vec3& H, double Ms, double h) {
  Mat3 A;
  for (int b = 0; b < 3; ++b) {
    Vec3 d = Vec3::Zero();
    d[b] = h;
    A.col(b) = (curve_M(c, H + d, Ms) - curve_M(c, H - d, Ms)) / (2 * h);
  }
  return A;
}
}  // namespace

TEST_CASE("tanh curve: slope 3 at the origin, saturates at Ms, dM/dH by finite differences",
          "[curves][fd]") {
  const double Ms = 1.6e6;
  const Vec3 dir = Vec3(0.3, -0.5, 0.8).normalized();
  CHECK(curve_M(Curve::Tanh, 1e-3 * dir, Ms).isApprox(3e-3 * dir, 1e-12));
  CHECK(curve_M(Curve::Tanh, 10 * Ms * dir, Ms).norm() == Approx(Ms).epsilon(1e-12));
  CHECK(curve_dMdH(Curve::Tanh, Vec3::Zero(), Ms).isApprox(3 * Mat3::Identity()));
  double worst = 0;
  for (double s : {1e-5, 1e-2, 0.1, 0.33, 1.0, 2.0, 5.0}) {
    const Vec3 H = s * Ms * dir;
    const Mat3 A = curve_dMdH(Curve::Tanh, H, Ms);
    const Mat3 Afd = fd_dMdH(Curve::Tanh, H, Ms, 1e-6 * Ms);
    worst = std::max(worst, (A - Afd).norm() / A.norm());
    CHECK((A - A.transpose()).norm() <= 1e-14 * A.norm());
  }
  INFO("worst relative FD error of dM/dH: " << worst);
  CHECK(worst <= 1e-6);
}

TEST_CASE("Kim 2018 curve (eq. 7): linear with slope 1/γ_D, then saturated", "[curves][fd]") {
  const double Ms = 1.6e6;
  const Vec3 dir = Vec3(1, 2, 2) / 3.0;
  CHECK(curve_M(Curve::Kim, 0.2 * Ms * dir, Ms).isApprox(0.6 * Ms * dir, 1e-14));
  CHECK(curve_M(Curve::Kim, 0.5 * Ms * dir, Ms).isApprox(Ms * dir, 1e-14));
  for (double s : {0.1, 0.6, 3.0}) {
    const Vec3 H = s * Ms * dir;
    const Mat3 A = curve_dMdH(Curve::Kim, H, Ms);
    CHECK((A - fd_dMdH(Curve::Kim, H, Ms, 1e-6 * Ms)).norm() <= 1e-6 * A.norm());
  }
}

TEST_CASE("γ_C of eq. 11 is |f⁻¹(M)|/|M|, 1/3 at the origin, clamped near saturation",
          "[curves]") {
  const double Ms = 1.6e6;
  CHECK(gamma_c(0.0, 1.0) == Approx(1.0 / 3.0));
  for (double s : {0.05, 0.3, 0.9}) {
    const double Mn = curve_M(Curve::Tanh, Vec3(s * Ms, 0, 0), Ms).norm();
    // γ_C M = f⁻¹(M) = H
    CHECK(gamma_c(Mn / Ms, 10.0) * Mn == Approx(s * Ms).epsilon(1e-9));
    CHECK(tanh_inverse_norm(Mn, Ms) == Approx(s * Ms).epsilon(1e-9));
  }
  CHECK(gamma_c(0.9999, 1.0) == 1.0);
  CHECK(gamma_c(1.0, 1.0) == 1.0);
  CHECK(std::isinf(tanh_inverse_norm(Ms, Ms)));
}
