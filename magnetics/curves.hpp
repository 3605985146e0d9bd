// magnetics/curves.hpp — magnetization curves M = f(H), their Jacobians and inverses.
#pragma once

#include "magnetics/types.hpp"

namespace magsim::mag {

/// γ_D of Kim 2018 (eq. 5): the self-demagnetizing factor of a sphere.
inline constexpr double kGammaD = 1.0 / 3.0;

/// M = f(H) for the chosen curve (eq. 10, eq. 7, or the iron sphere).
Vec3 curve_M(Curve c, const Vec3& H, double Ms);
/// ∂M/∂H (3×3, symmetric). For eq. 7 at the kink the saturated branch is used.
Mat3 curve_dMdH(Curve c, const Vec3& H, double Ms);

/// Curve::Iron's u = atanh(|M|/Ms) at η = |H|/Ms ≥ 0: the root of u/χ + tanh(u)/3 = η.
double iron_u(double eta);

/// The scalar inverse of the tanh curve: |H| = (Ms/3) atanh(|M|/Ms). Infinite at |M| ≥ Ms.
double tanh_inverse_norm(double Mnorm, double Ms);
/// γ_C of eq. 11, read as γ_C M = f⁻¹(M): γ_C = atanh(x)/(3x), x = |M|/Ms (→ 1/3 at x → 0),
/// clamped to gamma_max near saturation (paper §3.3). Dimensionless.
double gamma_c(double x, double gamma_max);

}  // namespace magsim::mag
