// magnetics/near_field.hpp — the near-field pair model: two touching iron spheres coupled as
// exact linear magnetostatics says, not as two point dipoles, at a wider gap as the contact
// saturates.
//
// One point dipole per ball is weakest where balls touch: in an axial field the dipole pair
// attracts 2.8× too weakly at g = 0.1a and 36× at 0.003a (μr = 1000), and in a transverse
// field it repels up to 42 % too strongly (magnetics/PHYSICS.md, "The near field"). The pair
// model adds to every pair of induced spheres closer than kPairCutoffGap the energy
//   E_ij = −μ0 S(g) ν^−β m_iᵀ ΔT(r_ij) m_j,
//   ΔT(r) = [Δt∥(G) r̂ r̂ᵀ + Δt⊥(G) (I − r̂ r̂ᵀ)] / a³,   G = g_e(g) + κ ν^γ h^q,
// in the co-energy's pair sum (coenergy.hpp), so that the field a ball feels from its partner
// is (T + S ν^−β ΔT) m_j and every force stays −∇U*:
//   * Δt∥, Δt⊥: the exact two-sphere coupling corrections (tools/reference/
//     near_field_table.py) that make the pair's linear polarizability C∥(d), C⊥(d) exact for
//     the material's initial μr, so that two balls in a weak uniform field feel the exact
//     linear force, axial, transverse and in between (the tangential force included);
//   * g: the gap in radii, g = |r|/a − 2, taken through g_e = g_m + g_s ln(1 + e^{(g − g_m)/g_s}):
//     g_e ≈ g from a few g_s above g_m on, and contact and every overlap read as g_m, a
//     surface roughness. The well this leaves at contact is as wide as g_s: narrower ones
//     made steps that the contact solver and the pull trade energy in (the energy guard's
//     retakes could not resolve them at g_m = 1e-4, g_s = 2.5e-4);
//   * S(g): 1 for g ≤ kPairFullGap, a quintic step to 0 at kPairCutoffGap (C² throughout);
//   * G: the saturated contact read as a wider gap (PHYSICS.md, "The near field"). Where the
//     linear gap field would exceed Ms the iron cannot carry the flux and acts as air, so the
//     correction is the exact linear one at G = g_e + κ h^q (ν = 1), h = |H_app|/Ms at the pair's
//     midpoint, H_app the field of the permanent moments and H0 (not of the induced ones: G
//     must not depend on M, or the magnetization equation would change). κ and q are fitted
//     to the nonlinear finite-element table (tools/findings/near_field_reference.md). At low
//     field G = g_e and the pair is exact linear; dG/dg = dg_e/dg > 0 and Δt falls with the
//     gap, so the correction always attracts;
//   * ν: the contacts the pair shares its balls' flux with, ν = 1 + (n_i + n_j)/2 − S_c(g),
//     n_i = Σ_k S_c(g_ik) the smooth contact count of ball i (S_c: 1 up to kPairCountFullGap,
//     a quintic step to 0 at kPairCountCutoffGap). ν = 1 for a lone pair, 1.5 for a chain's
//     end contact, 2 inside a chain: in a chain of high-μ iron the contacts share the flux,
//     so each couples less (ν^−β) and saturates earlier (ν^γ) than a lone pair. β and γ are
//     fitted to the finite-element 3-chains (tools/findings/near_field_reference.md) and
//     checked on its 5-chains. ν depends on positions only, so the forces
//     carry its gap derivatives: every contact of either ball moves the pair's energy.
// Eligible: induced moments that are the only moment of their body (group −1 or a group of
// one), with a radius equal to the sphere of their volume, a = (3V/4π)^{1/3} (or no radius
// set), pairs of equal radii. Every other pair keeps the dipole interaction.
#pragma once

#include "magnetics/moments.hpp"

#include <string>
#include <vector>

namespace magsim::mag {

/// The near-field model of induced sphere pairs.
enum class NearField : std::uint8_t {
  Dipole,  ///< one point dipole per ball, no correction (the default)
  Pair     ///< the pair model above
};
inline constexpr NameTable<NearField, 2> kNearFieldNames{
    {{NearField::Dipole, "dipole"}, {NearField::Pair, "pair"}}};

struct NearFieldOptions {
  NearField model = NearField::Dipole;
  /// Initial relative permeability of the induced material, μr ∈ [10, 10000]: iron's is
  /// in the hundreds to thousands (1000 here). Only the pair model reads it; the engine's
  /// own law M = f(H) (initial slope 3) is μr = ∞.
  double mu_r = 1000.0;
};

/// Empty when usable, else a one-line reason.
std::string validate(const NearFieldOptions& o);

/// The model's constants (gaps in radii, fields in Ms).
inline constexpr double kPairFullGap = 1.0;       ///< S = 1 up to this gap
inline constexpr double kPairCutoffGap = 2.0;     ///< S = 0 from this gap on: pure dipoles
inline constexpr double kPairContactGap = 1.5e-3; ///< g_m: what contact reads as, 7.5 µm at a = 5 mm
inline constexpr double kPairSmoothGap = 5e-4;    ///< g_s: the width of the step to g_m
inline constexpr double kPairWidenScale = 0.553;  ///< κ (gap widening per h^q, radii)
inline constexpr double kPairWidenPower = 1.22;   ///< q (κ and q fitted to the FEM table)
inline constexpr double kPairCountFullGap = 0.5;  ///< S_c = 1 up to this gap
inline constexpr double kPairCountCutoffGap = 1.0; ///< S_c = 0 from this gap on
inline constexpr double kPairShareCoupling = 0.4;  ///< β: the coupling ν^−β
inline constexpr double kPairShareWiden = 1.0;     ///< γ: the widening κ ν^γ h^q

/// g_e of a gap g and dg_e/dg.
double pair_effective_gap(double g, double* dge_dg = nullptr);

/// The widened gap G = g_e(g) + s κ h^q (radii) of a gap g at h = |H_app|/Ms ≥ 0 and a
/// sharing factor s (ν^γ; 1 for a lone pair), with dG/dg and dG/dh.
double pair_widened_gap(double g, double h, double* dG_dg = nullptr, double* dG_dh = nullptr,
                        double s = 1.0);

/// Δt∥ a³, Δt⊥ a³ at the widened gap G(g, h, s) and their derivatives, for relative
/// permeability mu_r (g in radii, g > −2; h = |H_app|/Ms ≥ 0, 0 = the linear limit).
/// Interpolated: natural cubic splines in ln G through the table's nodes, linear in ln μr
/// between its rows; beyond the last node (G > 2.2, wide or saturated) a power tail in G
/// that continues the spline's value and slope.
struct PairCoupling {
  double par = 0, perp = 0;        ///< Δt∥ a³, Δt⊥ a³
  double dpar = 0, dperp = 0;      ///< their derivatives in g
  double dpar_dh = 0, dperp_dh = 0;  ///< their derivatives in h
  double dpar_ds = 0, dperp_ds = 0;  ///< their derivatives in s
};
class PairCouplingTable {
 public:
  explicit PairCouplingTable(double mu_r);
  double mu_r() const { return mu_r_; }
  PairCoupling at(double g, double h = 0.0, double s = 1.0) const;

 private:
  double mu_r_;
  std::vector<double> par_, perp_, par2_, perp2_;  // node values and spline second derivatives
};

/// The cut-off step S(g) and dS/dg.
double pair_switch(double g, double* dS_dg = nullptr);
/// The contact count's step S_c(g) and dS_c/dg.
double pair_count_switch(double g, double* dS_dg = nullptr);

/// A pair of eligible moments closer than the cut-off (i < j).
struct NearPair {
  int i, j;
};
/// The pair model's coupling of one near pair: the field at i is K m_j and at j is K m_i,
/// K = S ν^−β ΔT(r_ij) (symmetric, even in r; 1/m³).
struct NearCoupling {
  int i, j;
  Mat3 K;
};
/// Pair list, couplings and table. The couplings depend on the description only (positions,
/// permanent moments, H0, …), so they are kept while it and μr stay the same: the
/// magnetization solve evaluates the field many times per step at one set of positions.
struct NearFieldWorkspace {
  std::vector<NearPair> pairs;
  std::vector<NearCoupling> couplings;  ///< of `key`'s near pairs, when `cached`
  MomentDesc key;                       ///< the description the couplings are of
  double key_mu_r = 0;
  bool cached = false;
  std::vector<double> a;  ///< (n) sphere radius of each eligible moment, 0 = not eligible
  std::vector<double> count;  ///< (n) contact count n_i of `pairs`
  std::vector<int> perm;  ///< the permanent moments (the sources of H_app)
  std::vector<std::pair<long long, int>> cells;  ///< scratch: (grid cell, moment)
  std::vector<PairCouplingTable> table;          ///< 0 or 1 entry
  const PairCouplingTable& table_for(double mu_r);
};

/// Lists the eligible pairs (i < j, in that order) of `set` closer than the cut-off (and
/// drops the cached couplings: they are of the pairs last listed for their description).
void find_near_pairs(const MomentDesc& set, NearFieldWorkspace* ws);

/// Every near pair's coupling (the Newton ground truth adds them to its interaction matrix).
/// Depends on positions and permanent moments only. Empty for NearField::Dipole.
void near_field_couplings(const MomentDesc& set, const NearFieldOptions& opt,
                          NearFieldWorkspace* ws, std::vector<NearCoupling>* out);

/// Adds the pair model's field K m_j to H_i and K m_i to H_j of every near pair
/// (the field −(1/μ0) ∂E/∂m the magnetization feels). No-op for NearField::Dipole.
void add_near_field(const MomentDesc& set, const Magnetization& mz, const NearFieldOptions& opt,
                    NearFieldWorkspace* ws, std::vector<Vec3>* H);
/// Σ E_ij (J), the pair model's part of U*. 0 for NearField::Dipole.
double near_field_energy(const MomentDesc& set, const Magnetization& mz,
                         const NearFieldOptions& opt, NearFieldWorkspace* ws);
/// Adds −∂(Σ E_ij)/∂p to F of both balls of every pair and of every permanent moment (through
/// H_app), and −∂/∂θ to τ of the permanent moments, at fixed magnetizations (the envelope
/// theorem: U is stationary in M). Σ F = 0. No-op for NearField::Dipole.
void add_near_field_forces(const MomentDesc& set, const Magnetization& mz,
                           const NearFieldOptions& opt, NearFieldWorkspace* ws,
                           std::vector<Vec3>* F, std::vector<Vec3>* tau);

}  // namespace magsim::mag
