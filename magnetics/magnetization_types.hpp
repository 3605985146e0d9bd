// magnetics/magnetization_types.hpp — what the magnetization solvers share: their options
// (DynamicsOptions), their workspace (MagWorkspace, also the forces' scratch) and statistics
// (RelaxStats). It sits below magnetization.hpp and the solver that one dispatches to,
// anderson.hpp: both include it, so Anderson needs nothing from the header above it.
#pragma once

#include "magnetics/fields.hpp"

#include <cstdint>
#include <utility>
#include <vector>

namespace magsim::mag {

/// How ours integrates eq. 8 over one iteration.
enum class ThetaIntegrator : std::uint8_t {
  Exact,  ///< closed form for constant |H_eff| (default; cannot overshoot θ = 0)
  Euler   ///< the paper's literal explicit step θ ← max(0, θ − Δt β |H_eff| Θ(θ))
};
inline constexpr NameTable<ThetaIntegrator, 2> kThetaIntegratorNames{
    {{ThetaIntegrator::Exact, "exact"}, {ThetaIntegrator::Euler, "euler"}}};

/// The magnetization solve's options. The in-class defaults are the engine's, equal to the
/// table of run options (engine/options_table.cpp, whose test holds them equal): a caller that
/// wants another method, tolerance or cap (the paper's ours at 1e-6, magsolve) sets it.
struct DynamicsOptions {
  /// Anderson-accelerated M = f(H(M)) with the classic force converges every rigid (sub-)step
  /// and makes the force −∇U* (magnetics/coenergy.hpp), so passive scenes lose energy and come
  /// to rest; `ours` is the paper as printed (θ dynamics eqs. 8–11, eq. 4), with no energy.
  Method method = Method::Anderson;
  double dt = 100e-9;          ///< Δt_m, magnetization clock step (s); allowed [1 ns, 1 µs]
  double beta = 5.0;           ///< β of eq. 8 (m·A⁻¹·s⁻¹); 0.005 per (ns·MA/m), our reading of the unit
  double alpha = 0.2;          ///< LLG damping constant α of eq. 6 (Kim 2018: 0.2–0.25)
  double gamma_c_max = 1.0;    ///< upper bound of γ_C in eq. 11 (engages at |M| ≳ 0.995 Ms)
  /// Raise the bound to γ_C's value at the solution, |H|/|f(H)|, where that is larger: the
  /// fixed point of eq. 11 stays exactly M = f(H) (a fixed bound moves it by up to 0.5 %
  /// where |H| ≈ Ms). false = the paper's fixed bound.
  bool adaptive_gamma_bound = true;
  /// The raised bound is used only while it is ≤ min(adaptive_gamma_cap, 2/k), k = β Δt Ms
  /// (beyond, |H| ≳ 2.5 Ms and the fixed bound applies again: |M| = Ms to < 1e-6).
  double adaptive_gamma_cap = 2.5;
  /// Converged when the criterion's value < tol: warm-started from the last rigid step, a
  /// converging method needs a handful of sweeps to 1e-4.
  double tol = 1e-4;
  /// What tol bounds. Residual (default): max_j |M_j − f(H_j)|/Ms_j of the iterate the
  /// sweep's fields came from — free, since H is computed anyway, and it does not stop a
  /// slow method early the way a small per-sweep change does. Change: max_j |ΔM_j|/Ms_j over
  /// one sweep (magnetics/PHYSICS.md's wording).
  enum class Criterion : std::uint8_t { Residual, Change } criterion = Criterion::Residual;
  int max_iter = 100;          ///< iteration cap per solve (a hit is counted in the profile)
  /// Floor (rad) of the half-angle between M_j1 and M_j2: a pair closer than this is spread
  /// back to it about M (|M| changes by < φ²/2 = 5e-13 relative), so the two
  /// sub-magnetizations can never collapse onto each other.
  double min_pair_angle = 1e-6;
  ThetaIntegrator theta_integrator = ThetaIntegrator::Exact;
  /// Method::Anderson: how many past residuals the least-squares mixing uses (0 = plain
  /// Picard iteration M ← f(H(M))).
  int anderson_depth = 5;
  /// Method::Anderson: damping β ∈ (0, 1] of the mixing x + β (f(H(x)) − x).
  double anderson_damping = 1.0;
  /// Method::Anderson: the history is dropped (restart) when the residual grows by more
  /// than this factor in one iteration.
  double anderson_restart_growth = 2.0;
  FieldOptions field;
};
inline constexpr NameTable<DynamicsOptions::Criterion, 2> kCriterionNames{
    {{DynamicsOptions::Criterion::Residual, "residual"}, {DynamicsOptions::Criterion::Change, "change"}}};
/// The curve these options converge to: the method's, or the chosen one where it takes it.
inline Curve curve_of(const DynamicsOptions& o) { return curve_of(o.method, o.field.near_field.curve); }

/// History of the Anderson solve (Method::Anderson, magnetics/anderson.cpp). Vectors stack
/// the induced magnetizations divided by Ms (3k entries for k induced moments); sized on the
/// first iteration of a solve, not reallocated after.
struct AndersonHistory {
  std::vector<int> idx;                 ///< (k) induced moment indices
  std::vector<double> x, g, f;          ///< (3k) iterate, its Picard image f(H(x)), g − x
  std::vector<double> x_prev, f_prev;   ///< (3k) the previous iterate and residual
  std::vector<double> dX, dF;           ///< (3k × depth) ring of iterate / residual differences
  std::vector<double> Q;                ///< (3k × depth) orthonormal basis of the dF columns
  std::vector<double> R, gamma;         ///< (depth × depth), (depth) least-squares scratch
  int cols = 0;                         ///< differences held
  int head = 0;                         ///< ring slot of the next difference
  double beta = 1.0;                    ///< current damping
};

/// Scratch and statistics of ForceModel::ZeemanTotal (forces_total.hpp). Reused across
/// steps; w warm-starts the next adjoint solve.
struct ZeemanTotalScratch {
  std::vector<int> idx;            ///< (k) induced moment indices
  std::vector<Mat3> B;             ///< (k) (V A)^{1/2}
  std::vector<Vec3> mt, c, w, r, p, q, z;  ///< (k) m̃, right side, iterate, CG vectors
  std::vector<int> perm;           ///< permanent moment indices
  std::vector<Vec3> Hp;            ///< field of the permanent moments (and H0) at them
  std::vector<Mat3> Jp;            ///< its Jacobian
  MomentSet src;                   ///< scratch: the adjoint moments as sources
  std::vector<Vec3> Hs;            ///< (n) field of src
  std::vector<Mat3> Js;            ///< (n) its Jacobian
  int iterations = 0;              ///< CG iterations of the last solve
  double residual = 0.0;           ///< its relative residual |c − S w| / |c|
  bool converged = true;           ///< residual ≤ tolerance
};

/// Scratch of a solve: fields, Jacobians and the packed sources. Reused across steps.
struct MagWorkspace {
  FieldWorkspace field;
  std::vector<Vec3> H;  ///< (n) field at each moment from the latest evaluation (A/m)
  std::vector<Mat3> J;  ///< (n) ∂H/∂p at each moment (A/m²), filled by force evaluation
  MomentSet effective;          ///< scratch: effective moments (reaction-symmetric forces)
  std::vector<Vec3> H_eff_src;  ///< (n) field of the effective moments (scratch)
  std::vector<Mat3> J_eff_src;  ///< (n) its Jacobian (scratch)
  std::vector<Mat3> A;  ///< (n) scratch for the Newton solver
  std::vector<int> group_order;  ///< scratch: moments sorted by group (classic torques)
  /// scratch: (grid cell, moment) of the bounded moments (classic force, bounded pairs)
  std::vector<std::pair<std::uint64_t, int>> bounded_cells;
  AndersonHistory anderson;  ///< Method::Anderson only
  ZeemanTotalScratch total;  ///< ForceModel::ZeemanTotal only
};

struct RelaxStats {
  int iterations = 0;          ///< Jacobi sweeps taken
  bool converged = false;      ///< the criterion fell below tol
  double last_change = 0.0;    ///< max_j |ΔM_j|/Ms_j of the last sweep
  double last_residual = 0.0;  ///< max_j |M_j − f(H_j)|/Ms_j before the last sweep
};

}  // namespace magsim::mag
