// magnetics/magnetization.hpp — magnetization dynamics (paper §3.2–3.3, DESIGN §1.5).
#pragma once

#include "magnetics/dipole_field.hpp"

#include <functional>
#include <string>

namespace magsim::mag {

/// How ours integrates eq. 8 over one iteration.
enum class ThetaIntegrator : std::uint8_t {
  Exact,  ///< closed form for constant |H_eff| (default; cannot overshoot θ = 0)
  Euler   ///< the paper's literal explicit step θ ← max(0, θ − Δt β |H_eff| Θ(θ))
};

struct DynamicsOptions {
  Method method = Method::Ours;
  double dt = 100e-9;          ///< Δt_m, magnetization clock step (s); allowed [1 ns, 1 µs]
  double beta = 5.0;           ///< β of eq. 8 (m·A⁻¹·s⁻¹); 0.005 per (ns·MA/m), DESIGN §1.5
  double alpha = 0.2;          ///< LLG damping constant α of eq. 6 (Kim 2018: 0.2–0.25)
  double gamma_c_max = 1.0;    ///< upper bound of γ_C in eq. 11 (engages at |M| ≳ 0.995 Ms)
  /// Raise the bound to γ_C's value at the solution, |H|/|f(H)|, where that is larger: the
  /// fixed point of eq. 11 stays exactly M = f(H) (a fixed bound moves it by up to 0.5 %
  /// where |H| ≈ Ms). false = the paper's fixed bound.
  bool adaptive_gamma_bound = true;
  /// The raised bound is used only while it is ≤ min(adaptive_gamma_cap, 2/k), k = β Δt Ms
  /// (beyond, |H| ≳ 2.5 Ms and the fixed bound applies again: |M| = Ms to < 1e-6).
  double adaptive_gamma_cap = 2.5;
  double tol = 1e-6;           ///< converged when every |ΔM_j|/Ms_j < tol in one iteration
  int max_iter = 999;          ///< iteration cap per solve
  /// Floor (rad) of the half-angle between M_j1 and M_j2: a pair closer than this is spread
  /// back to it about M (|M| changes by < φ²/2 = 5e-13 relative), so the two
  /// sub-magnetizations can never collapse onto each other (DESIGN §6).
  double min_pair_angle = 1e-6;
  ThetaIntegrator theta_integrator = ThetaIntegrator::Exact;
  FieldOptions field;
};

/// Empty when the options are usable, else a one-line reason.
std::string validate(const DynamicsOptions& opt);

/// Scratch of a solve: fields, Jacobians and the packed sources. Reused across steps.
struct MagWorkspace {
  FieldWorkspace field;
  std::vector<Vec3> H;  ///< (n) field at each moment from the latest evaluation (A/m)
  std::vector<Mat3> J;  ///< (n) ∂H/∂p at each moment (A/m²), filled by force evaluation
  std::vector<Mat3> A;  ///< (n) scratch for the Newton solver
};

struct RelaxStats {
  int iterations = 0;        ///< Jacobi sweeps taken
  bool converged = false;    ///< the last sweep changed every M by less than tol
  double last_change = 0.0;  ///< max_j |ΔM_j|/Ms_j of the last sweep
};

/// One Jacobi sweep (every moment updates from the fields of the previous iterate):
/// fields → H_eff → sub-magnetization update per the method. Returns max_j |ΔM_j|/Ms_j.
/// Fields are left in ws->H (they belong to the iterate *before* the update).
double magnetization_iteration(MomentSet* set, const DynamicsOptions& opt, MagWorkspace* ws);

/// Sweeps until converged or opt.max_iter; warm-starts from the state in `set`.
/// `on_iteration(k, set)` (optional) is called after sweep k = 1, 2, …
RelaxStats relax_magnetization(MomentSet* set, const DynamicsOptions& opt, MagWorkspace* ws,
                               const std::function<void(int, const MomentSet&)>& on_iteration = {});

/// eq. 8–9 for one sub-magnetization: the angle θ' after one step from θ ∈ [0, π] with
/// rate c·Δt = β |H_eff| Δt (exact or Euler).
double advance_theta(double theta, double c_dt, ThetaIntegrator integ);

/// Update of one moment's sub-pair for the given method and H_eff (exposed for tests and
/// the Fig. 9 sweep): M1, M2 in/out, |M_k| = Ms preserved.
void update_pair(Method method, const DynamicsOptions& opt, double Ms, const Vec3& Heff,
                 Vec3* M1, Vec3* M2);

/// H_eff of eq. 11 (ours, damping-only LLG) or eq. 5 (Kim 2018).
Vec3 effective_field(Method method, const DynamicsOptions& opt, const Vec3& H, const Vec3& M,
                     double Ms);

/// Re-aligns the sub-pair about M (M unchanged) so that the pair axis is perpendicular to
/// the part of H_eff transverse to M (DESIGN §6, "ours-realigned").
void realign_pair(const Vec3& Heff, double Ms, Vec3* M1, Vec3* M2);

}  // namespace magsim::mag
