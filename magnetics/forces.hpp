// magnetics/forces.hpp — magnetic forces and torques on moments (paper eqs. 4, 13–14).
// The dispatcher of the force models: ForceModel::ZeemanTotal goes down to forces_total.hpp,
// and both use the one-moment formulas of force_laws.hpp.
#pragma once

#include "magnetics/magnetization_types.hpp"

#include <vector>

namespace magsim::mag {

/// Forces (N) and torques (N·m) on every moment from the fields in ws (the fields and
/// Jacobians are evaluated here from the current magnetizations, into ws->H and ws->J).
/// Induced: the model's force, no torque (M ∥ H). Permanent: F = μ0 J m, τ = μ0 m × H.
/// F_classic (optional) receives the classic force of every moment as well.
///
/// Classic, bodies of several moments (a group of ≥ 2): the moments of a group exert no force
/// on each other, but rotating the body at fixed induced M (the envelope theorem's variation,
/// coenergy.hpp) changes their pair energy by −δθ·μ0 Σ_induced m_j × H_j^same, H^same the field
/// of the moment's own group. The torques that make the body's torque exactly −∂U*/∂θ:
///   τ_j = μ0 m_j × (H_j − H_j^same)   (permanent: the field of the other bodies and H0),
///   τ_j = −μ0 m_j × H_j^same          (induced: the shape anisotropy of a letter).
/// With one moment per body H^same = 0 and these are the torques above.
/// Classic with bounded pairs (FieldOptions::bounded_pairs): the clamped pair energy's
/// gradient, F_j = μ0 Σ_i (∂r_b/∂r)ᵀ J(r_b) m_j, ∂r_b/∂r = (R/|r|)(I − r̂ r̂ᵀ) inside the bound:
/// no pull deeper into an overlap, so the force stays −∇U* (the field, and so U*, is the
/// clamped one already). eq. 4 keeps the clamp of the force (not a gradient there).
///
/// reaction_symmetric (Zeeman only): the Zeeman force on j is the classic pair force with m_j
/// replaced by the effective moment m̃_j = V_j [A_j(2M_j + H_j) + M_j] (m̃ = m for permanent
/// moments), so per pair it is F_{j←i} = μ0 J(r_ji; m_i) m̃_j and F_{i←j} ≠ −F_{j←i}: the
/// set of moments pushes itself (a dynamic magnet with iron stuck to it flies off). The
/// symmetric force applies each pair's antisymmetric part,
///   F_j = ½ μ0 Σ_i [J(r_ji; m_i) m̃_j + J(r_ji; m̃_i) m_j] = ½ (F_zeeman,j + μ0 J̃_j m_j),
/// J̃ the Jacobian of the field of the effective moments: one more field evaluation, and
/// Σ_j F_j = 0 exactly (Algorithm 1 computes F "for each pair of magnetic moments"). The
/// torque on a permanent moment is that of the same pair energy, τ_j = ½ μ0 m_j × (H_j + H̃_j)
/// (induced moments: none, M does not turn with its body). Angular momentum is then
/// conserved up to the torques the pair energy would put on induced moments,
/// ½ μ0 Σ m_j × H̃_j over induced j (a test measures it).
///
/// ForceModel::ZeemanTotal — eq. 4 taken over the whole system: the exact negative gradient
/// of the system's Zeeman energy E_sys with every magnetization re-solved (the derivation and
/// its adjoint solve: forces_total.hpp). The adjoint conjugate gradients stop at |residual| ≤
/// total_tol |right side| or after total_max_iter iterations (one field evaluation each);
/// statistics in ws->total. reaction_symmetric is ignored (momentum is conserved already).
void compute_forces(const MomentDesc& set, const Magnetization& mz, ForceModel model,
                    Curve curve, const FieldOptions& field, MagWorkspace* ws,
                    std::vector<Vec3>* F, std::vector<Vec3>* tau,
                    std::vector<Vec3>* F_classic = nullptr, bool reaction_symmetric = false,
                    double total_tol = 1e-4, int total_max_iter = 100);
inline void compute_forces(const MomentSet& set, ForceModel model, Curve curve,
                           const FieldOptions& field, MagWorkspace* ws, std::vector<Vec3>* F,
                           std::vector<Vec3>* tau, std::vector<Vec3>* F_classic = nullptr,
                           bool reaction_symmetric = false, double total_tol = 1e-4,
                           int total_max_iter = 100) {
  compute_forces(set, set, model, curve, field, ws, F, tau, F_classic, reaction_symmetric,
                 total_tol, total_max_iter);
}

}  // namespace magsim::mag
