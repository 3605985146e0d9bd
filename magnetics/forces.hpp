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
/// Zeeman energy of one induced moment at equilibrium, E = −μ0 V f(H)·(f(H) + H) (eq. 3–4).
double zeeman_energy(Curve curve, double V, double Ms, const Vec3& H);
/// Classic force (eq. 13): F = μ0 (m·∇) H = μ0 J m, m held constant.
Vec3 classic_force(const Vec3& m, const Mat3& J);

/// Forces (N) and torques (N·m) on every moment from the fields in ws (the fields and
/// Jacobians are evaluated here from the current magnetizations, into ws->H and ws->J).
/// Induced: the model's force, no torque (M ∥ H). Permanent: F = μ0 J m, τ = μ0 m × H.
/// F_classic (optional) receives the classic force of every moment as well.
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
void compute_forces(const MomentSet& set, ForceModel model, Curve curve,
                    const FieldOptions& field, MagWorkspace* ws, std::vector<Vec3>* F,
                    std::vector<Vec3>* tau, std::vector<Vec3>* F_classic = nullptr,
                    bool reaction_symmetric = false);

}  // namespace magsim::mag
