// magnetics/ground_truth.hpp — the self-consistent magnetization M = f(H(M)) (magnetics/PHYSICS.md).
#pragma once

#include <functional>

#include "magnetics/magnetization.hpp"

namespace magsim::mag {

struct ExactStats {
  int newton_steps = 0;
  bool converged = false;
  double residual = 0.0;  ///< ‖M − f(H(M))‖ / ‖M‖ over all induced moments at the end
};

/// Solves M_j = f(H_j(M)) for every induced moment at once with Newton's method (dense
/// LU of I − (∂f/∂H) T, backtracking line search) to ‖R‖/‖M‖ ≤ rel_tol. Starts from the
/// magnetization in `set` (zero is fine) and writes the solution back (sub-pairs set about
/// it). The curve decides which ground truth: eq. 10 for ours, eq. 7 for Kim 2018.
/// Dense: use for up to a few thousand induced moments.
/// `on_step(k, residual)` (optional) is called after Newton step k = 1, 2, … (progress of
/// long solves: a step of 3000 induced moments factors a dense 9000 x 9000 matrix).
ExactStats solve_exact(const MomentDesc& set, Magnetization* mz, Curve curve,
                       const FieldOptions& field, double rel_tol = 1e-12, int max_steps = 60,
                       const std::function<void(int, double)>& on_step = {});
inline ExactStats solve_exact(MomentSet* set, Curve curve, const FieldOptions& field,
                              double rel_tol = 1e-12, int max_steps = 60,
                              const std::function<void(int, double)>& on_step = {}) {
  return solve_exact(*set, set, curve, field, rel_tol, max_steps, on_step);
}

/// eq. 12: e_M = ‖M_gt − M‖ / ‖M_gt‖ over the stacked induced magnetizations.
double magnetization_error(const MomentSet& set, const std::vector<Vec3>& M_gt);
/// max_j ‖M_gt,j − M_j‖ / ‖M_gt,j‖ over induced moments with M_gt,j ≠ 0.
double max_moment_error(const MomentSet& set, const std::vector<Vec3>& M_gt);

}  // namespace magsim::mag
