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

// The worst relative FD error of ∂M/∂H along dir at each |H|/Ms in s (central step h·Ms),
// checking on the way that ∂M/∂H is symmetric
double worst_dMdH_error(Curve c, const Vec3& dir, double Ms, std::initializer_list<double> s, double h) {
  double worst = 0;
  for (double x : s) {
    const Vec3 H = x * Ms * dir;
    const Mat3 A = curve_dMdH(c, H, Ms);
    const Mat3 Afd = fd_dMdH(c, H, Ms, h * Ms);
    worst = std::max(worst, (A - Afd).norm() / A.norm());
    CHECK((A - A.transpose()).norm() <= 1e-14 * A.norm());
  }
  return worst;
}
}  // namespace

TEST_CASE("tanh curve: slope 3 at the origin, saturates at Ms, dM/dH by finite differences",
          "[curves][fd]") {
  const double Ms = 1.6e6;
  const Vec3 dir = Vec3(0.3, -0.5, 0.8).normalized();
  CHECK(curve_M(Curve::Tanh, 1e-3 * dir, Ms).isApprox(3e-3 * dir, 1e-12));
  CHECK(curve_M(Curve::Tanh, 10 * Ms * dir, Ms).norm() == Approx(Ms).epsilon(1e-12));
  CHECK(curve_dMdH(Curve::Tanh, Vec3::Zero(), Ms).isApprox(3 * Mat3::Identity()));
  const double worst = worst_dMdH_error(Curve::Tanh, dir, Ms, {1e-5, 1e-2, 0.1, 0.33, 1.0, 2.0, 5.0}, 1e-6);
  INFO("worst relative FD error of dM/dH: " << worst);
  CHECK(worst <= 1e-6);
}

TEST_CASE("iron curve: a bulk-iron sphere's law, dM/dH by finite differences", "[curves][fd]") {
  const double Ms = 1.6e6, chi = kIronChi;
  const Vec3 dir = Vec3(-0.2, 0.6, 0.7).normalized();
  // slope 1/(1/χ + 1/3) at the origin (the sphere's demagnetization caps it near 3)
  const double g0 = 1.0 / (1.0 / chi + 1.0 / 3.0);
  CHECK(curve_M(Curve::Iron, 1e-3 * dir, Ms).isApprox(g0 * 1e-3 * dir, 1e-9));
  CHECK(curve_dMdH(Curve::Iron, Vec3::Zero(), Ms).isApprox(g0 * Mat3::Identity()));
  CHECK(curve_M(Curve::Iron, Vec3::Zero(), Ms).norm() == 0.0);
  // M = Ms tanh(χ(|H| − |M|/3)/Ms) along H, from the linear range through the knee to saturation
  for (double s : {1e-6, 1e-3, 0.1, 0.3, 0.333, 1.0 / 3.0, 0.334, 0.34, 1.0, 10.0}) {
    const Vec3 H = s * Ms * dir;
    const Vec3 M = curve_M(Curve::Iron, H, Ms);
    const double m = M.norm() / Ms;
    INFO("|H|/Ms " << s << ", |M|/Ms " << m);
    CHECK(M.normalized().isApprox(dir, 1e-14));
    CHECK(m == Approx(std::tanh(chi * (s - m / 3.0))).epsilon(1e-12));
    CHECK(m < 1.0 + 1e-15);
  }
  // at 0.3 Ms a lone sphere is at 0.8956 Ms; eq. 10 gives tanh(0.9) = 0.716
  CHECK(curve_M(Curve::Iron, 0.3 * Ms * dir, Ms).norm() / Ms == Approx(0.8956).epsilon(1e-3));
  const double worst =
      worst_dMdH_error(Curve::Iron, dir, Ms, {1e-5, 1e-2, 0.1, 0.3, 0.33, 0.336, 0.4, 1.0, 5.0}, 1e-7);
  INFO("worst relative FD error of dM/dH: " << worst);
  CHECK(worst <= 1e-6);
  // u = atanh(|M|/Ms) is the root of u/χ + tanh(u)/3 = η, even where |M| rounds to Ms
  for (double eta : {1e-9, 0.2, 0.4, 3.0, 100.0}) {
    const double u = iron_u(eta);
    CHECK(u / chi + std::tanh(u) / 3.0 == Approx(eta).epsilon(1e-14));
  }
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
