// magnetics/force_laws.hpp — the force and energy of one moment in a given field and
// Jacobian: eq. 4's Zeeman force and its effective magnetization, the Zeeman energy
// (eqs. 3–4) and the classic force (eq. 13).
// Below both force modules, compute_forces (forces.hpp) and ZeemanTotal (forces_total.hpp),
// which share these formulas; it includes neither.
#pragma once

#include "magnetics/types.hpp"

namespace magsim::mag {

/// Zeeman force on an induced moment (ours, eq. 4, derived with the sources held fixed):
///   E = −μ0 V M·(M + H), M = f(H(p))
///   F = −∂E/∂p = μ0 V J [ A (2M + H) + M ],  A = ∂M/∂H (symmetric), J = ∂H/∂p (symmetric).
/// The printed eq. 4 reads A J (2M + H); the chain rule gives J A (2M + H) — the two
/// differ when A is anisotropic (near saturation). Proven by a finite-difference test.
Vec3 zeeman_force(Curve curve, double V, double Ms, const Vec3& M, const Vec3& H, const Mat3& J);
/// The magnetization in eq. 4's bracket, A (2M + H) + M (A = ∂M/∂H at H): the induced moment's
/// "effective" magnetization, −∂e/∂H / (μ0 V) with e its Zeeman energy. Used by the Zeeman
/// force, its reaction-symmetric form and ZeemanTotal.
inline Vec3 zeeman_effective_magnetization(const Mat3& A, const Vec3& M, const Vec3& H) {
  return A * (2.0 * M + H) + M;
}
/// Zeeman energy of one induced moment at equilibrium, E = −μ0 V f(H)·(f(H) + H) (eq. 3–4).
double zeeman_energy(Curve curve, double V, double Ms, const Vec3& H);
/// Classic force (eq. 13): F = μ0 (m·∇) H = μ0 J m, m held constant.
Vec3 classic_force(const Vec3& m, const Mat3& J);

}  // namespace magsim::mag
