// magnetics/curves.cpp — the smooth (eq. 10) and non-smooth (eq. 7) magnetization curves.
#include "magnetics/curves.hpp"
#include "magnetics/det_math.hpp"

#include <cmath>
#include <limits>

namespace magsim::mag {

namespace {

// tanh(x)/x, with its series near 0 (relative error < 1e-16 for x < 1e-4)
double tanh_over_x(double x) {
  if (x < 1e-4) return 1.0 - x * x / 3.0;
  return dmath::tanh(x) / x;
}

}  // namespace

// Curve::Iron along H: u = atanh(|M|/Ms) solves G(u) = u/χ + tanh(u)/3 − η = 0, η = |H|/Ms
// (the bulk law M = Ms tanh(χ H_in/Ms) with H_in = |H| − |M|/3). G' = 1/χ + sech²u/3 > 0 and
// G(0) = −η < 0 ≤ G(χη), so Newton kept inside that bracket (bisecting a step that leaves it)
// converges from any η; u, not M, because M rounds to Ms from u ≈ 19 on.
double iron_u(double eta) {
  if (!(eta > 0)) return 0.0;
  constexpr double chi = kIronChi;
  double lo = 0.0, hi = chi * eta;
  double u = eta / (1.0 / chi + 1.0 / 3.0);  // the linear law, inside the bracket
  for (int k = 0; k < 200; ++k) {
    const double t = dmath::tanh(u);
    const double G = u / chi + t / 3.0 - eta;
    if (G == 0.0) return u;
    (G > 0.0 ? hi : lo) = u;
    double next = u - G / (1.0 / chi + (1.0 - t) * (1.0 + t) / 3.0);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - u) <= 4e-16 * u || next == lo || next == hi) return next;
    u = next;
  }
  return u;
}

Vec3 curve_M(Curve c, const Vec3& H, double Ms) {
  const double h = H.norm();
  if (c == Curve::Tanh) {
    // eq. 10: f(H) = Ms tanh(3|H|/Ms) H/|H| = 3 [tanh(x)/x] H,  x = 3|H|/Ms
    return 3.0 * tanh_over_x(3.0 * h / Ms) * H;
  }
  if (c == Curve::Iron) {
    if (h == 0.0) return Vec3::Zero();
    return (Ms * dmath::tanh(iron_u(h / Ms)) / h) * H;
  }
  // eq. 7: M = H/γ_D if |H| < γ_D Ms, else Ms H/|H|
  if (h < kGammaD * Ms) return H / kGammaD;
  return (Ms / h) * H;
}

Mat3 curve_dMdH(Curve c, const Vec3& H, double Ms) {
  const double h = H.norm();
  const Mat3 I = Mat3::Identity();
  if (c == Curve::Tanh) {
    // f = g(h) Ĥ, g = Ms tanh(3h/Ms):  ∂f/∂H = g'(h) ĤĤᵀ + (g/h)(I − ĤĤᵀ),
    // g' = 3 sech²(3h/Ms), g/h = 3 tanh(x)/x
    const double x = 3.0 * h / Ms;
    const double g_over_h = 3.0 * tanh_over_x(x);
    if (h == 0.0) return g_over_h * I;
    const double sech = 1.0 / dmath::cosh(x);
    const double gp = 3.0 * sech * sech;
    const Vec3 u = H / h;
    const Mat3 P = u * u.transpose();
    return gp * P + g_over_h * (I - P);
  }
  if (c == Curve::Iron) {
    // g(h) = Ms tanh u(h/Ms): g' = 1/(cosh²u/χ + 1/3) (η = u/χ + tanh(u)/3 differentiated);
    // g/h → g'(0) = 1/(1/χ + 1/3) as h → 0
    const double g0 = 1.0 / (1.0 / kIronChi + 1.0 / 3.0);
    if (h == 0.0) return g0 * I;
    const double u = iron_u(h / Ms);
    const double ch = dmath::cosh(u);
    const double gp = 1.0 / (ch * ch / kIronChi + 1.0 / 3.0);
    const double g_over_h = u > 0.0 ? Ms * dmath::tanh(u) / h : g0;
    const Vec3 w = H / h;
    const Mat3 P = w * w.transpose();
    return gp * P + g_over_h * (I - P);
  }
  // eq. 7: 3 I below saturation; (Ms/h)(I − ĤĤᵀ) above
  if (h < kGammaD * Ms) return I / kGammaD;
  const Vec3 u = H / h;
  return (Ms / h) * (I - u * u.transpose());
}

double tanh_inverse_norm(double Mnorm, double Ms) {
  const double x = Mnorm / Ms;
  if (x >= 1.0) return std::numeric_limits<double>::infinity();
  return Ms / 3.0 * dmath::atanh(x);
}

// eq. 11: γ_C = |f⁻¹(M)|/|M| = atanh(x)/(3x), bounded above by gamma_max
double gamma_c(double x, double gamma_max) {
  if (x >= 1.0) return gamma_max;
  double g;
  if (x < 1e-4) g = (1.0 + x * x / 3.0) / 3.0;  // atanh(x)/x = 1 + x²/3 + …
  else g = dmath::atanh(x) / (3.0 * x);
  return g < gamma_max ? g : gamma_max;
}

}  // namespace magsim::mag
