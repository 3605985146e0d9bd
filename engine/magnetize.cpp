// engine/magnetize.cpp — stage 2 of a step (Algorithm 1, "repeat … until every M
// converges"): the induced magnetizations relax on the Δt_m clock, warm-started from the
// previous rigid step (the State's magnetization), until every |ΔM_j|/Ms_j < tol or the cap.
// Method::Exact instead solves M = f(H(M)) with Newton (the ground truth, no dynamics).
#include "engine/stages.hpp"

#include "magnetics/ground_truth.hpp"

namespace magsim::engine {

void magnetize(const Model& m, const mag::MomentDesc& set, mag::Magnetization* mz,
               Workspace* ws, StepProfile* prof) {
  if (m.induced_count == 0) return;  // nothing to magnetize: permanent moments only
  const mag::DynamicsOptions& opt = m.options.magnetics;
  if (m.resolved.exact) {
    const mag::ExactStats st = mag::solve_exact(set, mz, m.resolved.curve, opt.field);
    prof->iterations += st.newton_steps;
    prof->converged = prof->converged && st.converged;
    prof->cap_hit = prof->cap_hit || !st.converged;
    prof->last_change = st.residual;
    return;
  }
  const mag::RelaxStats st = mag::relax_magnetization(set, mz, opt, &ws->mag);
  prof->iterations += st.iterations;  // summed over the frame's sub-steps
  prof->converged = prof->converged && st.converged;
  prof->cap_hit = prof->cap_hit || !st.converged;
  prof->last_change = st.last_change;
}

}  // namespace magsim::engine
