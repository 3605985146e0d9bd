// magnetics/magnetization.hpp — magnetization dynamics (paper §3.2–3.3, magnetics/PHYSICS.md),
// and the dispatch of the magnetization solve: Method::Anderson goes down to anderson.hpp,
// which shares only magnetization_types.hpp with this header.
#pragma once

#include "magnetics/magnetization_types.hpp"

#include <functional>
#include <string>

namespace magsim::mag {

/// Empty when the options are usable, else a one-line reason.
std::string validate(const DynamicsOptions& opt);

/// What one sweep measured.
struct SweepStats {
  double change = 0.0;    ///< max_j |ΔM_j|/Ms_j
  double residual = 0.0;  ///< max_j |M_j − f(H_j)|/Ms_j of the iterate before the sweep
};

/// One Jacobi sweep (every moment updates from the fields of the previous iterate):
/// fields → H_eff → sub-magnetization update per the method; returns the sweep's change
/// and the residual of the iterate before it.
/// Fields are left in ws->H (they belong to the iterate *before* the update).
/// Method::Anderson has no history here: its sweep is the plain Picard step M ← f(H(M)).
SweepStats magnetization_iteration(const MomentDesc& set, Magnetization* mz,
                                   const DynamicsOptions& opt, MagWorkspace* ws);
inline SweepStats magnetization_iteration(MomentSet* set, const DynamicsOptions& opt,
                                          MagWorkspace* ws) {
  return magnetization_iteration(*set, set, opt, ws);
}

/// The one entry point that solves the magnetization by opt.method, so that no caller chooses
/// between the solvers: the dynamics sweep until converged or opt.max_iter, warm-started from
/// the magnetization *mz of the moments `set`, `on_iteration(k, *mz)` (optional) called after
/// sweep k = 1, 2, …; Method::Anderson runs the Anderson-accelerated Picard solve of
/// magnetics/anderson.hpp (one field evaluation per iteration, the same stopping rule and cap);
/// Method::Exact the Newton ground truth (ground_truth.hpp, its own tolerance and cap:
/// iterations = Newton steps, last_change = last_residual = its final residual, on_iteration
/// called once at the end).
RelaxStats relax_magnetization(
    const MomentDesc& set, Magnetization* mz, const DynamicsOptions& opt, MagWorkspace* ws,
    const std::function<void(int, const Magnetization&)>& on_iteration = {});
/// The same on a MomentSet, `on_iteration(k, *set)`.
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
/// the part of H_eff transverse to M ("ours-realigned", magnetics/PHYSICS.md).
void realign_pair(const Vec3& Heff, double Ms, Vec3* M1, Vec3* M2);

}  // namespace magsim::mag
