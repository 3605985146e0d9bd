// magnetics/forces_total.hpp — ForceModel::ZeemanTotal: the forces as the exact gradient of
// the system's Zeeman energy E_sys, and E_sys itself.
// The force model compute_forces (forces.hpp) dispatches to: it builds on the shared types
// (magnetization_types.hpp) and the one-moment formulas (force_laws.hpp), never on forces.hpp.
//
// eq. 4 taken over the whole system ("magnetic moments and equivalently magnetizations are
// taken as variables", §6.1): the forces are the exact negative gradient of
//   E_sys = Σ_{i induced} e_i(H_i) + U_pp,   e_i = −μ0 V_i f(H_i)·(f(H_i) + H_i)  (eqs. 3–4),
//   U_pp = −μ0 [½ Σ_p m_p·H^perm_p + Σ_p m_p·H0]   (permanent pairs, the physical energy),
// with every induced M_j = f(H_j) at equilibrium, so a change of one position moves every
// magnetization. eq. 4's per-moment force is the part of this gradient where the sources
// stay fixed; what it leaves out (the neighbours' energies and magnetizations) makes it
// non-conservative in a pile: measured in falling_magnet, eq. 4 does 2.7× the work of the
// energy it releases (tools/findings/energy.md). The gradient, by the adjoint method:
//   m̃_i = V_i [A_i (2M_i + H_i) + M_i]                       (−∂e_i/∂H_i / μ0)
//   λ̃ = m̃ + V A T λ̃   (T: the dipole field of moments at induced moments, eq. 1)
//   F_k = μ0 [J_kᵀ λ̃_k + J̃_kᵀ m_k]          (k induced; J̃ = ∂H̃/∂p, H̃ the field of λ̃)
//   F_p = μ0 (J̃_p + J^perm_p)ᵀ m_p,  τ_p = μ0 m_p × (H̃_p + H^perm_p)   (p permanent)
// For one induced moment in a fixed field λ̃ = m̃ and F is eq. 4 exactly. Σ F = 0 (E_sys
// is translation invariant). The adjoint system is solved symmetrically, with
// B = (V A)^{1/2} and λ̃ = m̃ + B w: (I − B T B) w = B T m̃ by conjugate gradients
// (I − B T B is positive definite where the magnetization equilibrium is stable),
// warm-started from the last call, to |residual| ≤ tol |right side|; each CG iteration is
// one field evaluation. Same-body pairs (one group) add no force, as for the other models.
#pragma once

#include "magnetics/magnetization_types.hpp"

#include <vector>

namespace magsim::mag {

/// E_sys of ForceModel::ZeemanTotal at the magnetizations in `set` (the equilibrium ones:
/// the force is its gradient there). J.
double zeeman_total_energy(const MomentDesc& set, const Magnetization& mz, Curve curve,
                           const FieldOptions& field, FieldWorkspace* ws);
inline double zeeman_total_energy(const MomentSet& set, Curve curve, const FieldOptions& field,
                                  FieldWorkspace* ws) {
  return zeeman_total_energy(set, set, curve, field, ws);
}
/// The same from fields already evaluated: H at every moment, Hp the permanent moments' own
/// field (with H0) at the permanent moments perm (ws->total.perm and .Hp after a
/// ZeemanTotal force evaluation).
double zeeman_total_energy(const MomentDesc& set, const Magnetization& mz, Curve curve,
                           const std::vector<Vec3>& H, const std::vector<int>& perm,
                           const std::vector<Vec3>& Hp);
inline double zeeman_total_energy(const MomentSet& set, Curve curve, const std::vector<Vec3>& H,
                                  const std::vector<int>& perm, const std::vector<Vec3>& Hp) {
  return zeeman_total_energy(set, set, curve, H, perm, Hp);
}

namespace detail {

/// The ZeemanTotal forces and torques (compute_forces with ForceModel::ZeemanTotal); ws->H
/// and ws->J already hold the fields of `set`. The adjoint solve stops at |residual| ≤
/// tol |right side| or after max_iter iterations; its statistics go to ws->total.
void zeeman_total_forces(const MomentDesc& set, const Magnetization& mz, Curve curve,
                         const FieldOptions& field, MagWorkspace* ws, std::vector<Vec3>* F,
                         std::vector<Vec3>* tau, std::vector<Vec3>* F_classic, double tol,
                         int max_iter);

/// The permanent moments' own field (with H0; and its Jacobian when Jp != nullptr) at the
/// permanent moments, listed in *perm; *scratch receives `set` with every induced M zeroed.
void permanent_field(const MomentDesc& set, const Magnetization& mz, const FieldOptions& field,
                     MomentSet* scratch, std::vector<int>* perm, std::vector<Vec3>* Hp,
                     std::vector<Mat3>* Jp, FieldWorkspace* ws);

}  // namespace detail

}  // namespace magsim::mag
