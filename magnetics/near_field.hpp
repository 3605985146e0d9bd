// magnetics/near_field.hpp — the near-field pair model: two touching iron spheres coupled as
// exact linear magnetostatics says, not as two point dipoles, at a wider gap as the contact
// saturates.
//
// One point dipole per ball is weakest where balls touch: in an axial field the dipole pair
// attracts 2.8× too weakly at g = 0.1a and 36× at 0.003a (μr = 1000), and in a transverse
// field it repels up to 42 % too strongly (magnetics/PHYSICS.md, "The near field"). The pair
// model adds to every pair of induced spheres closer than kPairCutoffGap the energy
//   E_ij = −μ0 S(g) ν^−β m_iᵀ ΔT(r_ij) m_j,
//   ΔT(r) = [Δt∥(G) r̂ r̂ᵀ + Δt⊥(G) (I − r̂ r̂ᵀ)] / a³,   G = G(g_e(g), κ h^q),   h = h(ζ̄),
// in the co-energy's pair sum (coenergy.hpp), so that every force stays −∇U*:
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
//     gap's flux density would exceed μ0 Ms the iron cannot carry it and acts as air, so the
//     correction is the exact linear one at a gap G widened by the saturated layer κ h^q
//     (G = g_e + κ h^q on eq. 10's balls, a blend of the two on the iron's: PairWidening).
//     The flux is the balls' own:
//     h = ζ̄ / (3 √(1 − ζ̄²)), ζ̄ = (|M_i|/Ms_i + |M_j|/Ms_j)/2 (pair_flux_field), the field in
//     Ms that magnetizes a lone ball to ζ̄ to first order (ζ ≈ 3h), growing without bound as
//     the iron saturates. A contact in a chain, whose balls carry the chain's flux, thus
//     saturates at a lower applied field than a lone pair. κ and q are fitted to the
//     nonlinear finite-element table (tools/findings/near_field_reference.md), once per
//     curve of the balls (pair_widening). At low field
//     G = g_e and the pair is exact linear; dG/dg ≥ (1 − λ) dg_e/dg > 0 and Δt falls with
//     the gap, so the correction always attracts;
//   * ν: the contacts the pair shares its balls' flux with, ν = 1 + (n_i + n_j)/2 − S_c(g),
//     n_i = Σ_k S_c(g_ik) the smooth contact count of ball i (S_c: 1 up to kPairCountFullGap,
//     a quintic step to 0 at kPairCountCutoffGap). ν = 1 for a lone pair, 1.5 for a chain's
//     end contact, 2 inside a chain: each contact's exact pair coupling, added as if its pair
//     were alone, over-counts in a chain, so each couples as ν^−β (β fitted to the
//     finite-element 3- and 4-chains, checked on longer chains and at other gaps). ν depends
//     on positions only, so the forces carry its gap derivatives: every contact of either
//     ball moves the pair's energy.
// Since G depends on M, E_ij is not bilinear in the moments: the field the magnetization
// feels, −(1/μ0) ∂E/∂m, gains a term along each ball's own moment, and U* computed as
// ½ m·H over the fields needs near_field_coenergy_excess added (coenergy.hpp).
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
  /// The balls' curve M = f(H) (kCurveOptionNames): tanh = eq. 10, iron = a sphere of bulk
  /// iron (curves.hpp). The methods that take a curve (anderson, exact) read it here, and the
  /// pair model's widening κ h^q is fitted per curve (pair_widening).
  Curve curve = Curve::Tanh;
};

/// Empty when usable, else a one-line reason.
std::string validate(const NearFieldOptions& o);

/// The model's constants (gaps in radii, fields in Ms).
inline constexpr double kPairFullGap = 1.0;       ///< S = 1 up to this gap
inline constexpr double kPairCutoffGap = 2.0;     ///< S = 0 from this gap on: pure dipoles
inline constexpr double kPairContactGap = 1.5e-3; ///< g_m: what contact reads as, 7.5 µm at a = 5 mm
inline constexpr double kPairSmoothGap = 5e-4;    ///< g_s: the width of the step to g_m
inline constexpr double kPairWidenScale = 0.3425;  ///< κ (gap widening per h^q, radii), eq. 10's balls
inline constexpr double kPairWidenPower = 1.277;   ///< q (κ and q fitted to the FEM table)
inline constexpr double kPairWidenScaleIron = 0.4274;  ///< κ of Curve::Iron's balls
inline constexpr double kPairWidenPowerIron = 1.470;   ///< q of Curve::Iron's balls
inline constexpr double kPairWidenShareIron = 0.3876;  ///< λ of Curve::Iron's balls (the blend below)
inline constexpr double kPairCountFullGap = 0.5;  ///< S_c = 1 up to this gap
inline constexpr double kPairCountCutoffGap = 1.0; ///< S_c = 0 from this gap on
inline constexpr double kPairShareCoupling = 0.4;  ///< β: the coupling ν^−β

/// g_e of a gap g and dg_e/dg.
double pair_effective_gap(double g, double* dge_dg = nullptr);

/// The widening of balls of curve c: the saturated layer w = κ h^q and how it meets the gap,
///   G = (1 − λ) g_e + ((λ g_e)⁴ + w⁴)^{1/4}   (λ = 0: G = g_e + w),
/// a layer thinner than about λ g_e widens nothing (the gap's own flux is too weak to
/// saturate the iron there), one much thicker adds to (1 − λ) g_e. dG/dg_e ≥ 1 − λ > 0, so
/// the correction attracts at every gap. Fitted per curve on the same training half: eq. 10's
/// balls keep the sum (λ = 0); the iron's knee (g = 0.03a–0.1a at 0.03–0.1 Ms) needs the
/// blend. The exponent 4 is fixed: a fitted one (6.4) and 8 fit as well, and 4 costs two
/// square roots where a general one costs pow.
struct PairWidening {
  double scale, power;  ///< κ, q
  double share = 0.0;   ///< λ ∈ [0, 1)
};
PairWidening pair_widening(Curve c);

/// G of an effective gap g_e at the saturation field h ≥ 0, with dG/dg_e and dG/dh.
double pair_blended_gap(const PairWidening& k, double ge, double h, double* dG_dge, double* dG_dh);

/// The widened gap G (radii) of a gap g at the saturation field h ≥ 0 (pair_flux_field), with
/// dG/dg and dG/dh; the widening of curve c.
double pair_widened_gap(double g, double h, double* dG_dg = nullptr, double* dG_dh = nullptr,
                        Curve c = Curve::Tanh);

/// The saturation field h = ζ/(3 √(1 − ζ²)) (in Ms) of a pair's mean reduced magnetization
/// ζ = |M|/Ms ∈ [0, 1], and dh/dζ = (1 − ζ²)^{−3/2}/3. ζ is held just below 1 (h ≈ 7e3 there,
/// where Δt(G) is below 1e-25 of its contact value), with dh/dζ = 0 beyond.
double pair_flux_field(double zeta, double* dh_dzeta = nullptr);

/// Δt∥ a³, Δt⊥ a³ at the widened gap G(g, h) and their derivatives, for relative
/// permeability mu_r (g in radii, g > −2; h ≥ 0 the saturation field, 0 = the linear limit).
/// Interpolated: natural cubic splines in ln G through the table's nodes, linear in ln μr
/// between its rows; beyond the last node (G > 2.2, wide or saturated) a power tail in G
/// that continues the spline's value and slope.
struct PairCoupling {
  double par = 0, perp = 0;        ///< Δt∥ a³, Δt⊥ a³
  double dpar = 0, dperp = 0;      ///< their derivatives in g
  double dpar_dh = 0, dperp_dh = 0;  ///< their derivatives in h
};
class PairCouplingTable {
 public:
  explicit PairCouplingTable(double mu_r, Curve curve = Curve::Tanh);
  double mu_r() const { return mu_r_; }
  Curve curve() const { return curve_; }
  PairCoupling at(double g, double h = 0.0) const;
  /// The same from g_e(g) and dg_e/dg (a pair's cached effective gap).
  PairCoupling at_effective(double ge, double dge_dg, double h) const;

 private:
  double mu_r_;
  Curve curve_;
  PairWidening widen_;
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
/// One near pair's geometry, which the magnetization does not move (gaps in radii).
struct PairStatic {
  Vec3 rhat = Vec3::Zero();  ///< (p_i − p_j)/ρ
  double rho = 0, a = 0, g = 0;
  double ge = 0, dge = 0;  ///< g_e(g) and dg_e/dg
  double S = 0, dS = 0;  ///< the cut-off step and dS/dρ
  double w = 1, dw = 0;  ///< ν^−β and d/dν
  double dSc = 0;        ///< dS_c/dρ of the pair's own gap
};
/// A 3×3 block ∂H_a/∂M_b of the pair model's field (dimensionless).
struct NearBlock {
  int a, b;
  Mat3 D;
};
/// Pair list, geometry and table. The geometry depends on the description only (positions,
/// radii, …), so it is kept while the description stays the same: the magnetization solve
/// evaluates the field many times per step at one set of positions.
struct NearFieldWorkspace {
  std::vector<NearPair> pairs;
  std::vector<PairStatic> statics;  ///< of `key`'s near pairs, when `cached`
  MomentDesc key;                   ///< the description the geometry is of
  bool cached = false;
  std::vector<double> a;  ///< (n) sphere radius of each eligible moment, 0 = not eligible
  std::vector<double> count;  ///< (n) contact count n_i of `pairs`
  std::vector<std::pair<long long, int>> cells;  ///< scratch: (grid cell, moment)
  std::vector<PairCouplingTable> table;          ///< 0 or 1 entry
  const PairCouplingTable& table_for(const NearFieldOptions& opt);
};

/// Lists the eligible pairs (i < j, in that order) of `set` closer than the cut-off (and
/// drops the cached geometry: it is of the pairs last listed for their description).
void find_near_pairs(const MomentDesc& set, NearFieldWorkspace* ws);

/// The blocks ∂H_a/∂M_b (a, b ∈ {i, j}) of every near pair's field at mz, by central
/// differences of the pair's field in M_b (steps of 1e-6 Ms; the Newton ground truth's
/// matrix, whose error only slows its convergence). Empty for NearField::Dipole.
void near_field_jacobian(const MomentDesc& set, const Magnetization& mz, const NearFieldOptions& opt,
                         NearFieldWorkspace* ws, std::vector<NearBlock>* out);

/// Adds the pair model's field −(1/μ0) ∂E_ij/∂m to H_i and H_j of every near pair (the field
/// the magnetization feels: S ν^−β ΔT m_j, and the saturation term along m̂_i). No-op for
/// NearField::Dipole.
void add_near_field(const MomentDesc& set, const Magnetization& mz, const NearFieldOptions& opt,
                    NearFieldWorkspace* ws, std::vector<Vec3>* H);
/// Σ E_ij (J), the pair model's part of U*. 0 for NearField::Dipole.
double near_field_energy(const MomentDesc& set, const Magnetization& mz,
                         const NearFieldOptions& opt, NearFieldWorkspace* ws);
/// Σ E_ij + ½ μ0 Σ m·H_near (J): what U* computed as ½ m·H over the fields (H including
/// add_near_field's) misses because E_ij is not bilinear in the moments. 0 for Dipole.
double near_field_coenergy_excess(const MomentDesc& set, const Magnetization& mz,
                                  const NearFieldOptions& opt, NearFieldWorkspace* ws);
/// Adds −∂(Σ E_ij)/∂p to F of both balls of every pair, at fixed magnetizations (the envelope
/// theorem: U is stationary in M). Σ F = 0; no torque (E depends on the balls' positions
/// and moments only). No-op for NearField::Dipole.
void add_near_field_forces(const MomentDesc& set, const Magnetization& mz,
                           const NearFieldOptions& opt, NearFieldWorkspace* ws,
                           std::vector<Vec3>* F, std::vector<Vec3>* tau);

}  // namespace magsim::mag
