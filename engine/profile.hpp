// engine/profile.hpp — what one rigid step cost, stage by stage.
//
// T_i, T_f and T_r are the paper's Table 1 columns: magnetization dynamics, magnetic forces,
// rigid-body collide + step. The finer fields split T_r and account for the engine's own
// bookkeeping, so that total ≈ sync + T_i + T_f + T_r + check.
#pragma once

#include <chrono>

namespace magsim::engine {

struct StepProfile {
  // paper Table 1 (ms of wall time)
  double T_i = 0.0;  ///< magnetization dynamics (or the Newton solve for Method::Exact)
  double T_f = 0.0;  ///< magnetic forces and torques, applied to the bodies
  double T_r = 0.0;  ///< rigid step: collide + contact joints + QuickStep

  // finer stages (ms)
  double sync_ms = 0.0;       ///< state → ODE and bodies → moment positions
  double collide_ms = 0.0;    ///< broad + narrow phase, contact sorting, joint creation
  double quickstep_ms = 0.0;  ///< dWorldQuickStep
  double check_ms = 0.0;      ///< read back + non-finite checks + state copy
  double total_ms = 0.0;      ///< the whole step

  // magnetization solve
  int iterations = 0;        ///< Jacobi sweeps (or Newton steps for Method::Exact)
  bool converged = true;     ///< false when the solve stopped at its cap
  bool cap_hit = false;      ///< the iteration cap was reached without convergence
  double last_change = 0.0;  ///< max_j |ΔM_j|/Ms_j of the last sweep (Exact: residual)

  int contacts = 0;  ///< contact joints created this step (its last sub-step)
  int substeps = 1;  ///< rigid sub-steps the frame was split into (SimOptions::max_substeps)
  int guard_retakes = 0;  ///< times the energy guard retook this frame (SimOptions::energy_guard)
  int asleep = 0;  ///< bodies asleep at the end of the step (SimOptions::sleep)
};

/// Adds the wall time of its scope (ms) to *out. steady_clock, so immune to clock jumps.
class ScopedTimer {
 public:
  explicit ScopedTimer(double* out) : out_(out), t0_(std::chrono::steady_clock::now()) {}
  ~ScopedTimer() {
    *out_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0_)
                 .count();
  }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  double* out_;
  std::chrono::steady_clock::time_point t0_;
};

}  // namespace magsim::engine
