// engine/step.cpp — one rigid step, the paper's Algorithm 1 as a table of contents.
//
//   (1) moments take their world poses from their bodies     place_moments.cpp
//   (1b) the frame splits into n rigid sub-steps              substeps.cpp
//   per sub-step of Δt_r/n:
//   (2) magnetization dynamics until converged or capped      magnetize.cpp
//   (3) magnetic forces and torques onto the bodies           apply_forces.cpp
//   (3b) eddy-current loss (scenes that set a conductivity)   eddy.cpp
//   (4) collide + QuickStep                                   ode_bridge.cpp
//   assemble_next: read back, check for non-finite values      safety.cpp
//   (2)+(3) again at the end state: its converged magnetization, U*, and the forces the
//   next step starts with (so a frame solves once per sub-step, as before)
//   the energy guard: E = K + U_g + U* rose too much → retake in more sub-steps
//   commit, with the energy audit of the step                  energy.cpp
//
// The step works on ws_.next — the magnetics solvers on its magnetization, the eddy loss on
// its memory, both taken from state_ when an attempt begins — and swaps it into state_ only
// when every check passes, so state_ is always the last good state; on failure ODE is
// rewound to it.
#include "engine/simulation.hpp"

#include "engine/ode_bridge.hpp"
#include "engine/sleep.hpp"
#include "engine/stages.hpp"
#include "magnetics/coenergy.hpp"
#include "magnetics/forces.hpp"
#include "magnetics/forces_total.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace magsim::engine {

namespace {

// The engine's OpenMP thread count for the span of one step: the caller's count
// (omp_get_max_threads of the calling thread) is back when the step returns or throws, so a
// Simulation with its own `threads` does not change the threads of the caller's own regions.
class OmpThreadScope {
 public:
  explicit OmpThreadScope(int threads) : saved_(omp_get_max_threads()) { omp_set_num_threads(threads); }
  ~OmpThreadScope() { omp_set_num_threads(saved_); }
  OmpThreadScope(const OmpThreadScope&) = delete;
  OmpThreadScope& operator=(const OmpThreadScope&) = delete;

 private:
  int saved_;
};

}  // namespace

double Simulation::coenergy(const mag::Magnetization& mz) {
  const Model& m = *model_;
  if (ws_.mag.H.size() != moments_.size()) return 0.0;
  // the potential of the force where it has its own (zeeman-total: E_sys, forces_total.hpp)
  if (m.resolved.force == mag::ForceModel::ZeemanTotal)
    return mag::zeeman_total_energy(moments_, mz, m.resolved.curve, ws_.mag.H,
                                    ws_.mag.total.perm, ws_.mag.total.Hp);
  // the pair model's pairs and geometry: the field evaluation's cache, of these same poses
  return mag::magnetic_coenergy(moments_, mz, m.resolved.curve, ws_.mag.H, m.options.magnetics.field.near_field,
                                &ws_.mag.field.near);
}

void Simulation::solve_magnetics(mag::Magnetization* mz, bool solve, long n) {
  const Model& m = *model_;
  StepProfile& prof = profile_;
  // (2) magnetization dynamics on the Δt_m clock, warm-started from the last (sub-)step
  if (solve) {
    ScopedTimer t(&prof.T_i);
    magnetize(m, moments_, mz, &ws_, &prof);
  }
  check_magnetization(m, *mz, n);
  // (3) forces (eqs. 13–14 or eq. 4) and torques on the moments
  if (m.dynamic_moments) {
    ScopedTimer t(&prof.T_f);
    compute_magnetic_forces(m, moments_, *mz, &ws_);
    check_forces(m, ws_, n);
  }
}

void Simulation::attempt(int nsub, int nsub_soft, long n) {
  const Model& m = *model_;
  StepProfile& prof = profile_;
  begin_audit_step(energy_, &ws_.audit);
  State& next = ws_.next;
  mag::Magnetization& mz = next.mag;  // the magnetization the step evolves

  // (1) ODE takes the state; the next state starts from its magnetization and eddy memory;
  //     moments take world positions (and permanent moments their world orientation) from
  //     their bodies
  {
    ScopedTimer t(&prof.sync_ms);
    ode_->write_state(state_);
    if (inject_body_ >= 0) ode_->set_velocity(inject_body_, inject_velocity_);
    mz = state_.mag;
    next.eddy = state_.eddy;
    next.contact_depth = 0.0;
    next.still_time = state_.still_time;
    next.still_vel = state_.still_vel;
    next.still_angvel = state_.still_angvel;
    next.sleep_island = state_.sleep_island;
    next.H_sleep = state_.H_sleep;
    next.enabled = state_.enabled;
    place_moments(m, state_, &moments_, &mz);
    freeze_sleeping(m, state_, &moments_);
  }

  const double h = m.options.dt / nsub;
  prof.substeps = nsub;
  for (int k = 0; k < nsub; ++k) {
    if (k > 0) {  // later sub-steps: the moments follow the bodies ODE has moved
      ScopedTimer t(&prof.sync_ms);
      ode_->read_state(&next);
      place_moments(m, next, &moments_, &mz);
      // energy audit of the sub-step just taken (its forces are still in ws_)
      audit_substep(m, k == 1 ? state_ : ws_.sub_prev, next, ws_.body_force,
                    ws_.body_torque, ws_.eddy_force, ws_.eddy_torque, h, &ws_.audit);
      ws_.sub_prev = next;
    }
    const State& now = k == 0 ? state_ : next;  // the poses this sub-step starts from

    // (2), (3): the first sub-step takes the forces the last step left for this state (or,
    // after a restore or rollback, evaluates them from its converged magnetization)
    if (k > 0 || !ws_.forces_ready) {
      solve_magnetics(&mz, k > 0 || !state_.magnetized, n);
      if (k == 0) ws_.coenergy_start = coenergy(mz);
    } else {
      ws_.coenergy_start = energy_.magnetic_energy;  // the last step's audit, from this field
    }
    ws_.forces_ready = false;  // the moments move on from here

    if (m.dynamic_moments) {
      ScopedTimer t(&prof.T_f);
      apply_magnetic_forces(m, moments_, mz, &ws_, ode_.get());
      // (3b) the eddy-current loss of conducting bodies (off unless the scene sets σ)
      apply_eddy_losses(m, moments_, mz, now, h, &next.eddy, &ws_, ode_.get());
    }

    // (4) collide and step the rigid bodies over h
    {
      ScopedTimer t(&prof.T_r);
      {
        ScopedTimer c(&prof.collide_ms);
        ode_->update_margins(now, ws_.body_force, h);
        double depth = 0.0;
        std::vector<std::pair<int, int>>* joined = m.options.sleep ? &ws_.joined : nullptr;
        prof.contacts = ode_->collide(&next.contact_pairs, h, m.options.dt / nsub_soft, &depth, joined);
        next.contact_depth = std::max(next.contact_depth, depth);
        // a sleeping island that a moving body's contact joint ties (ODE would enable the
        // sleeper alone) joins this sub-step; a woken island may touch another: until none wakes
        while (joined && wake_touched(m, *joined, moments_, ws_.F, ws_.tau, &next, ode_.get()) > 0) {
          freeze_sleeping(m, next, &moments_);
          // the woken bodies' contacts with sleeping and static bodies were skipped: again
          ode_->discard_contacts();
          prof.contacts = ode_->collide(&next.contact_pairs, h, m.options.dt / nsub_soft, &depth, joined);
          next.contact_depth = std::max(next.contact_depth, depth);
        }
        carry_sleeping_pairs(m, state_.contact_pairs, &next);
      }
      ScopedTimer q(&prof.quickstep_ms);
      try {
        // the first sub-step keeps the seed of an unsplit step
        ode_->quickstep(static_cast<unsigned long>(n) ^ (static_cast<unsigned long>(k) << 40), h);
      } catch (const OdeFailure& e) {
        // name the body that went bad when there is one, else report ODE's own words
        ode_->read_state(&next);
        check_bodies(m, next, n);
        throw SimulationError(n, -1, "", "rigid step",
                              "step " + std::to_string(n) + ": rigid step failed: " + e.what());
      }
    }
  }
  assemble_next(nsub, h, n);
}

void Simulation::assemble_next(int nsub, double h, long n) {
  const Model& m = *model_;
  StepProfile& prof = profile_;
  State& next = ws_.next;
  // read back and check the end state
  {
    ScopedTimer t(&prof.check_ms);
    ode_->read_state(&next);
    next.step = n;
    check_bodies(m, next, n);
    settle(m, &next, &ws_.fell_asleep);  // islands still for long enough fall asleep (v = 0)
    next.dvel.resize(m.nbody);
    for (int b = 0; b < m.nbody; ++b) next.dvel[b] = next.vel[b] - state_.vel[b];
    // energy audit: the work of the last ODE step (O(bodies)), with the forces it was given
    audit_substep(m, nsub == 1 ? state_ : ws_.sub_prev, next, ws_.body_force, ws_.body_torque,
                  ws_.eddy_force, ws_.eddy_torque, h, &ws_.audit);
  }
  // (2)+(3) at the end state: its converged magnetization, U*, and the next step's forces
  {
    ScopedTimer t(&prof.sync_ms);
    place_moments(m, next, &moments_, &next.mag);
    freeze_sleeping(m, next, &moments_);
  }
  solve_magnetics(&next.mag, true, n);
  next.magnetized = true;
  // sleepers that an awake source's field moved wake; the new ones keep this field
  finish_sleep(m, ws_.fell_asleep, ws_.mag.H, &next);
  // the load term of the next step's sub-steps: |Σ F_j|/m_b of the forces it starts with
  next.mag_accel.assign(m.nbody, 0.0);
  if (m.dynamic_moments)
    for (int b : m.dynamic_bodies) {
      Vec3 F = Vec3::Zero();
      for (int j = m.body_moment_adr[b]; j < m.body_moment_adr[b] + m.body_moment_num[b]; ++j) F += ws_.F[j];
      next.mag_accel[b] = F.norm() / m.body_mass[b];
    }
  ws_.audit.magnetic_energy = coenergy(next.mag);
}

void Simulation::commit(long retakes, long unresolved) {
  profile_.guard_retakes = static_cast<int>(retakes);
  ws_.audit.guard_retakes += retakes;
  ws_.audit.guard_unresolved += unresolved;
  ws_.audit.total.energy_created += ws_.audit.last.energy_created;
  ws_.audit.total.energy_dissipated += ws_.audit.last.energy_dissipated;
  if (energy_.substeps == 0)  // the audit's first step: E at its start
    ws_.audit.initial_total = energy_.kinetic + energy_.gravitational + ws_.coenergy_start;
  std::swap(energy_, ws_.audit);
  std::swap(state_, ws_.next);
  ws_.forces_ready = true;  // the forces of assemble_next's solve belong to the new state_
  inject_body_ = -1;
}

void Simulation::step() {
  const Model& m = *model_;
  profile_ = StepProfile{};
  ScopedTimer total(&profile_.total_ms);
  const long n = state_.step + 1;  // the step being taken, as named in errors
  const OmpThreadScope threads(omp_threads_);  // several Simulations may differ
  const SimOptions& o = m.options;
  const bool guard = o.energy_guard && m.resolved.force_has_energy;

  // every body asleep and nothing moving: the step only advances the clock
  if (inject_body_ < 0 && ws_.forces_ready && world_asleep(m, state_)) {
    state_.step = n;
    std::fill(state_.dvel.begin(), state_.dvel.end(), Vec3::Zero());
    energy_.last = EnergyFlow{};
    profile_.asleep = static_cast<int>(m.dynamic_bodies.size());
    return;
  }
  try {
    // (1b) the frame's rigid sub-steps (1 unless the scene allows more and bodies move fast)
    int nsub = choose_substeps(m, state_);
    const int nsub_scene = nsub;  // the guard's retakes keep its contact softness
    long retakes = 0, unresolved = 0;
    int best_nsub = nsub;  // the attempt whose E rose least
    double best_dE = 0.0;
    bool redo_best = false;
    for (;;) {
      attempt(nsub, nsub_scene, n);
      // the energy guard: ΔE = E_end − E_start of the whole frame, E = K + U_g + U*
      const double e_start = energy_.kinetic + energy_.gravitational + ws_.coenergy_start;
      const double dE = total_energy(ws_.audit) - e_start;
      const double tol = o.energy_guard_tolerance *
                             (energy_.kinetic + ws_.audit.kinetic + std::abs(ws_.coenergy_start)) +
                         o.energy_guard_floor;
      ws_.audit.last.energy_created = std::max(0.0, dE);
      ws_.audit.last.energy_dissipated = std::max(0.0, -dE);
      if (!guard || !(dE > tol) || redo_best) break;
      const bool better = retakes == 0 || dE < best_dE;
      if (better) {
        best_nsub = nsub;
        best_dE = dE;
      }
      if (!better || nsub >= o.energy_guard_max_substeps) {
        // finer sub-steps did not help, or the cap: keep the attempt that rose least (retaken:
        // states are a function of the start and the sub-step count)
        ++unresolved;
        if (best_nsub == nsub) break;
        rollback();
        nsub = best_nsub;
        redo_best = true;
        continue;
      }
      // retake the frame from state_ in twice as many sub-steps
      ++retakes;
      rollback();
      nsub = std::min(2 * nsub, o.energy_guard_max_substeps);
    }
    commit(retakes, unresolved);
    profile_.asleep = asleep_count(state_);
  } catch (const SimulationError&) {
    inject_body_ = -1;
    rollback();
    throw;
  } catch (const OdeFailure& e) {  // ODE failed outside the step (e.g. in collision)
    ode_->mark_broken();
    inject_body_ = -1;
    rollback();
    throw SimulationError(n, -1, "", "rigid step",
                          "step " + std::to_string(n) + ": ODE failed: " + e.what());
  }
}

}  // namespace magsim::engine
