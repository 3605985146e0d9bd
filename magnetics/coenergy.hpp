// magnetics/coenergy.hpp — the magnetic co-energy U*, the energy of the classic force.
//
// With every induced magnetization converged, M_j = f(H_j), the classic force F_k = μ0 J_k m_k
// (eqs. 13–14) and the torques μ0 m × H of forces.hpp are exactly −∇U* (magnetics/PHYSICS.md,
// "The co-energy"). U* is the stationary value over the induced magnetizations of
//   U(M; p) = μ0 Σ_induced V_j Ψ(M_j) − ½ μ0 Σ_j m_j·(H_j − H0) − μ0 Σ_j m_j·H0,
// H_j the field at moment j of all other moments plus H0, Ψ = ∫ f⁻¹ the curve's energy
// density. ∂U/∂M_j = 0 is M_j = f(H_j), so at that point the envelope theorem leaves only
// the explicit position dependence of the pair sum: the classic pair force. U is stationary
// in M, so a residual r = M − f(H) changes U* by O(|r|²) only.
#pragma once

#include "magnetics/moments.hpp"
#include "magnetics/near_field.hpp"

#include <vector>

namespace magsim::mag {

/// Ψ(|M|) = ∫₀^|M| |f⁻¹(s)| ds (J/m³ divided by μ0: A²/m²), the curve's stored energy density.
///   tanh (eq. 10): Ψ = (Ms²/3)[x atanh x + ½ ln(1 − x²)]
///                    = (Ms²/6)[(1 + x) ln(1 + x) + (1 − x) ln(1 − x)],  x = |M|/Ms ≤ 1;
///   iron:          Ψ = (Ms²/χ)[x atanh x + ½ ln(1 − x²)] + |M|²/6
///   eq. 7:         Ψ = |M|²/6 (M = 3H below saturation; |M| ≤ Ms is a constraint).
/// |M| above Ms (never produced by the methods) is taken as Ms.
double curve_energy_density(Curve c, double Mnorm, double Ms);

/// U* (J) of the moments in `set` given H_j, the field at each moment (H0 included, as
/// compute_fields returns it). Same-body pairs are included (constant for rigid bodies of
/// permanent moments). Returns 0 when H does not match the set (no field evaluated yet).
double magnetic_coenergy(const MomentDesc& set, const Magnetization& mz, Curve curve,
                         const std::vector<Vec3>& H);
inline double magnetic_coenergy(const MomentSet& set, Curve curve, const std::vector<Vec3>& H) {
  return magnetic_coenergy(set, set, curve, H);
}
/// U* as above with the near-field pair model on: its energy is not bilinear in the moments,
/// so ½ m·H over the fields misses near_field_coenergy_excess. The same as the form above for
/// NearField::Dipole.
inline double magnetic_coenergy(const MomentDesc& set, const Magnetization& mz, Curve curve,
                                const std::vector<Vec3>& H, const NearFieldOptions& near,
                                NearFieldWorkspace* ws) {
  const double U = magnetic_coenergy(set, mz, curve, H);
  return H.size() == set.size() ? U + near_field_coenergy_excess(set, mz, near, ws) : U;
}

}  // namespace magsim::mag
