// magnetics/forces.hpp — magnetic forces and torques on moments (paper eqs. 4, 13–14).
#pragma once

#include "magnetics/magnetization.hpp"

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
/// ForceModel::ZeemanTotal — eq. 4 taken over the whole system ("magnetic moments and
/// equivalently magnetizations are taken as variables", §6.1): the forces are the exact
/// negative gradient of
///   E_sys = Σ_{i induced} e_i(H_i) + U_pp,   e_i = −μ0 V_i f(H_i)·(f(H_i) + H_i)  (eqs. 3–4),
///   U_pp = −μ0 [½ Σ_p m_p·H^perm_p + Σ_p m_p·H0]   (permanent pairs, the physical energy),
/// with every induced M_j = f(H_j) at equilibrium, so a change of one position moves every
/// magnetization. eq. 4's per-moment force is the part of this gradient where the sources
/// stay fixed; what it leaves out (the neighbours' energies and magnetizations) makes it
/// non-conservative in a pile: measured in falling_magnet, eq. 4 does 2.7× the work of the
/// energy it releases (tools/findings/energy.md). The gradient, by the adjoint method:
///   m̃_i = V_i [A_i (2M_i + H_i) + M_i]                       (−∂e_i/∂H_i / μ0)
///   λ̃ = m̃ + V A T λ̃   (T: the dipole field of moments at induced moments, eq. 1)
///   F_k = μ0 [J_kᵀ λ̃_k + J̃_kᵀ m_k]          (k induced; J̃ = ∂H̃/∂p, H̃ the field of λ̃)
///   F_p = μ0 (J̃_p + J^perm_p)ᵀ m_p,  τ_p = μ0 m_p × (H̃_p + H^perm_p)   (p permanent)
/// For one induced moment in a fixed field λ̃ = m̃ and F is eq. 4 exactly. Σ F = 0 (E_sys
/// is translation invariant). The adjoint system is solved symmetrically, with
/// B = (V A)^{1/2} and λ̃ = m̃ + B w: (I − B T B) w = B T m̃ by conjugate gradients
/// (I − B T B is positive definite where the magnetization equilibrium is stable),
/// warm-started from the last call, to |residual| ≤ total_tol |right side|; each CG
/// iteration is one field evaluation. Statistics in ws->total. reaction_symmetric is
/// ignored (momentum is conserved already). Same-body pairs (one group) add no force, as for
/// the other models.
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

}  // namespace magsim::mag
