// engine/simulation.hpp — the engine's facade: a SceneDesc in, steps, state, metrics and
// frames out.
//
//   magsim::engine::Simulation sim(scene);      // validates (std::invalid_argument)
//   while (sim.time() < 2.0) sim.step();        // SimulationError on a non-finite value
//   sim.metrics(); sim.frame(); sim.state_hash();
//
// Determinism: the same scene, options and OpenMP thread count give bit-identical states
// (ODE is re-fed the whole State every step, contacts are sorted into a fixed order, and
// ODE's constraint-order RNG is seeded from the step number). save_state/restore_state
// round-trip exactly, and stepping after a restore reproduces the original continuation
// (except with auto_disable, whose sleep counters ODE does not expose).
#pragma once

#include "engine/energy.hpp"
#include "engine/frame_builder.hpp"
#include "engine/metrics.hpp"
#include "engine/profile.hpp"
#include "engine/safety.hpp"
#include "engine/state.hpp"
#include "engine/workspace.hpp"
#include "magnetics/moments.hpp"

#include <cstdint>
#include <memory>
#include <string>

namespace magsim::engine {

class OdeBridge;

class Simulation {
 public:
  /// Compiles and validates the scene (std::invalid_argument naming body and field) and
  /// builds the ODE world. Induced moments start unmagnetized.
  explicit Simulation(const SceneDesc& scene);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// One rigid step of Δt_r (paper Algorithm 1, see step.cpp). On a non-finite value the
  /// state is rolled back to the last good one and SimulationError is thrown.
  void step();
  /// n steps.
  void run(long n);

  double time() const;  ///< steps() · Δt_r (s)
  long steps() const;
  const StepProfile& last_profile() const { return profile_; }
  Metrics metrics() const;
  /// The energy audit since t = 0 (energy.hpp): K, U_g, the magnetic interaction energy,
  /// the cumulative work of the magnetic forces, gravity and the contacts, and the same for
  /// the last step. restore_state() starts it afresh from the restored state.
  const EnergyAudit& energy() const { return energy_; }
  std::uint64_t state_hash() const;

  State save_state() const { return state_; }
  /// Restores a state saved from this simulation (std::invalid_argument when it does not
  /// fit the model or holds non-finite values).
  void restore_state(const State& s);

  render::Frame frame(const FrameOptions& opt = {}) const;

  /// Wakes every sleeping body (SimOptions::sleep), e.g. after the caller moved or edited one
  /// through restore_state; their moments are solved free again from the next step on.
  void wake_all();

  /// The moments' description at the poses of the last step (world positions, permanent
  /// moments); their magnetizations are state().mag.
  const mag::MomentDesc& moments() const { return moments_; }
  const Model& model() const { return *model_; }
  const State& state() const { return state_; }
  /// The step's scratch: the last step's magnetic forces per moment and body, and the fields
  /// at the moments (ws.mag.H) of the evaluation at the committed state. Stale after a
  /// restore_state until the next step.
  const Workspace& workspace() const { return ws_; }

  int body_count() const;
  /// Index of the body with this name, −1 when none.
  int find_body(const std::string& name) const;
  Vec3 body_position(int i) const;          ///< centre of mass (m)
  Quat body_orientation(int i) const;
  Vec3 body_velocity(int i) const;          ///< of the centre of mass (m/s)
  Vec3 body_angular_velocity(int i) const;  ///< world frame (rad/s)
  /// The BodyDesc frame's origin, x − R c (differs from the COM for composite bodies).
  Vec3 body_origin(int i) const;

  /// OpenMP threads the next step's magnetics run with.
  int threads() const { return omp_threads_; }
  /// Caps the thread count the simulation chose itself (SimOptions::threads = 0) at n >= 1,
  /// e.g. from a ThreadGovernor (tools/cli/cpu_share.hpp) on a busy machine; never raises it
  /// above that choice, and an explicit SimOptions::threads is kept. States do not depend on
  /// it (the kernels are bitwise the same for any thread count).
  void limit_default_threads(int n);

  /// Test hook of the safety check: the next step overwrites body i's linear velocity in
  /// ODE with v just before the rigid step (v may be NaN).
  void inject_velocity_for_testing(int body, const Vec3& v);

 private:
  /// One try at the step from state_ in nsub rigid sub-steps, into ws_.next and ws_.audit
  /// (E at both ends, ws_.coenergy_start and ws_.audit.magnetic_energy); nothing committed.
  /// The contacts are as soft as at nsub_soft sub-steps (the count the scene chose).
  void attempt(int nsub, int nsub_soft, long n);
  /// The end of an attempt whose last ODE sub-step (of length h, nsub sub-steps) is taken:
  /// reads ws_.next back from ODE and checks it, then completes it — velocity change,
  /// converged magnetization, the forces the next step starts with (ws_.F), their load
  /// (mag_accel) — and the audit's last sub-step and U*.
  void assemble_next(int nsub, double h, long n);
  /// Makes the assembled ws_.next and its audit the current state_ and energy_, with the
  /// energy guard's statistics of the step (retakes, and retakes that did not resolve).
  void commit(long retakes, long unresolved);
  /// Stages 2 and 3 at the moments' current poses: the solve of *mz (unless it is already
  /// the converged magnetization) and the forces into ws_ (not applied).
  void solve_magnetics(mag::Magnetization* mz, bool solve, long n);
  /// U* (or zeeman-total's E_sys) of the magnetization mz from the field of the last force
  /// evaluation (J). Not const: the pair model reads its pairs from the field's workspace.
  double coenergy(const mag::Magnetization& mz);
  void rollback();
  void check_body_index(int i) const;

  std::unique_ptr<const Model> model_;
  State state_;             ///< the last good state (end of the last successful step)
  mag::MomentDesc moments_;  ///< placed at the poses of the (sub-)step being taken
  Workspace ws_;
  std::unique_ptr<OdeBridge> ode_;
  StepProfile profile_;
  EnergyAudit energy_;      ///< committed with state_ at the end of each step
  int omp_threads_ = 1;     ///< OpenMP threads the magnetics run with (see step.cpp)
  int chosen_threads_ = 1;  ///< the count chosen at construction (the cap's ceiling)
  int inject_body_ = -1;
  Vec3 inject_velocity_ = Vec3::Zero();
};

}  // namespace magsim::engine
