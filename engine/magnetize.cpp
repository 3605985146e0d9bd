// engine/magnetize.cpp — stage 2 of a step (Algorithm 1, "repeat … until every M
// converges"): the induced magnetizations relax on the Δt_m clock, warm-started from the
// previous rigid step (the State's magnetization), until every |ΔM_j|/Ms_j < tol or the cap.
// mag::relax_magnetization chooses the solver by the method (dynamics, Anderson, or Newton
// for Method::Exact), so this stage does not.
#include "engine/stages.hpp"

namespace magsim::engine {

void magnetize(const Model& m, const mag::MomentDesc& set, mag::Magnetization* mz,
               Workspace* ws, StepProfile* prof) {
  if (m.induced_count == 0) return;  // nothing to magnetize: permanent moments only
  const mag::RelaxStats st = mag::relax_magnetization(set, mz, m.options.magnetics, &ws->mag);
  prof->iterations += st.iterations;  // summed over the frame's sub-steps
  prof->converged = prof->converged && st.converged;
  prof->cap_hit = prof->cap_hit || !st.converged;
  prof->last_change = st.last_change;
}

}  // namespace magsim::engine
