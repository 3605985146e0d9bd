// engine/step.cpp — one rigid step, the paper's Algorithm 1 as a table of contents.
//
//   (1) moments take their world poses from their bodies     place_moments.cpp
//   (1b) the frame splits into n rigid sub-steps              substeps.cpp
//   per sub-step of Δt_r/n:
//   (2) magnetization dynamics until converged or capped      magnetize.cpp
//   (3) magnetic forces and torques onto the bodies           apply_forces.cpp
//   (3b) eddy-current loss (scenes that set a conductivity)   eddy.cpp
//   (4) collide + QuickStep                                   ode_bridge.cpp
//   then read back, check for non-finite values, commit       safety.cpp
//   (and the energy audit of the step, committed with it)     energy.cpp
//
// The step works on ws_.next and swaps it into state_ only when every check passes, so
// state_ is always the last good state; on failure ODE and the moments are rewound to it.
#include "engine/simulation.hpp"

#include "engine/ode_bridge.hpp"
#include "engine/stages.hpp"
#include "magnetics/forces.hpp"

#include <omp.h>
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

void Simulation::step() {
  const Model& m = *model_;
  profile_ = StepProfile{};
  StepProfile& prof = profile_;
  ScopedTimer total(&prof.total_ms);
  const long n = state_.step + 1;  // the step being taken, as named in errors
  const OmpThreadScope threads(omp_threads_);  // several Simulations may differ

  // energy audit (energy.hpp) of this step, committed with the state
  begin_audit_step(energy_, &ws_.audit);

  try {
    // (1) ODE takes the state; moments take world positions (and permanent moments their
    //     world orientation) from their bodies
    {
      ScopedTimer t(&prof.sync_ms);
      ode_->write_state(state_);
      if (inject_body_ >= 0) {
        ode_->set_velocity(inject_body_, inject_velocity_);
        inject_body_ = -1;
      }
      place_moments(m, state_, &moments_);
    }

    // (1b) the frame's rigid sub-steps (1 unless the scene allows more and bodies move fast)
    const int nsub = choose_substeps(m, state_);
    const double h = m.options.dt / nsub;
    prof.substeps = nsub;
    for (int k = 0; k < nsub; ++k) {
      if (k > 0) {  // later sub-steps: the moments follow the bodies ODE has moved
        ScopedTimer t(&prof.sync_ms);
        ode_->read_state(&ws_.next);
        place_moments(m, ws_.next, &moments_);
        // energy audit of the sub-step just taken (its forces are still in ws_)
        audit_substep(m, k == 1 ? state_ : ws_.sub_prev, ws_.next, ws_.body_force,
                      ws_.body_torque, ws_.eddy_force, ws_.eddy_torque, h, &ws_.audit);
        ws_.sub_prev = ws_.next;
      }
      const State& now = k == 0 ? state_ : ws_.next;

      // (2) magnetization dynamics on the Δt_m clock, warm-started from the last (sub-)step
      {
        ScopedTimer t(&prof.T_i);
        magnetize(m, &moments_, &ws_, &prof);
      }
      check_magnetization(m, moments_, n);

      // (3) forces (eq. 4 or eqs. 13–14) and torques on the dynamic bodies
      if (m.dynamic_moments) {
        ScopedTimer t(&prof.T_f);
        compute_magnetic_forces(m, moments_, &ws_);
        check_forces(m, ws_, n);
        apply_magnetic_forces(m, moments_, &ws_, ode_.get());
        // (3b) the eddy-current loss of conducting bodies (off unless the scene sets σ)
        apply_eddy_losses(m, moments_, now, h, &ws_, ode_.get());
      }

      // (4) collide and step the rigid bodies over h
      {
        ScopedTimer t(&prof.T_r);
        {
          ScopedTimer c(&prof.collide_ms);
          ode_->update_margins(now, ws_.body_force, h);
          prof.contacts = ode_->collide(&ws_.next.contact_pairs, h);
        }
        ScopedTimer q(&prof.quickstep_ms);
        try {
          // the first sub-step keeps the seed of an unsplit step
          ode_->quickstep(static_cast<unsigned long>(n) ^ (static_cast<unsigned long>(k) << 40), h);
        } catch (const OdeFailure& e) {
          // name the body that went bad when there is one, else report ODE's own words
          ode_->read_state(&ws_.next);
          check_bodies(m, ws_.next, n);
          throw SimulationError(n, -1, "", "rigid step",
                                "step " + std::to_string(n) + ": rigid step failed: " + e.what());
        }
      }
    }

    // read back, check, commit
    {
      ScopedTimer t(&prof.check_ms);
      State& next = ws_.next;
      ode_->read_state(&next);
      store_magnetization(moments_, &next);
      next.step = n;
      check_bodies(m, next, n);
      next.dvel.resize(m.nbody);
      for (int b = 0; b < m.nbody; ++b) next.dvel[b] = next.vel[b] - state_.vel[b];
      next.mag_accel.assign(m.nbody, 0.0);
      if (m.dynamic_moments)
        for (int b : m.dynamic_bodies) next.mag_accel[b] = ws_.body_force[b].norm() / m.body_mass[b];
      // energy audit: the work of the last ODE step (O(bodies)); U_mag from the forces' field
      audit_substep(m, nsub == 1 ? state_ : ws_.sub_prev, next, ws_.body_force, ws_.body_torque,
                    ws_.eddy_force, ws_.eddy_torque, h, &ws_.audit);
      // the potential of the force where it has one (zeeman-total: E_sys, forces.hpp)
      ws_.audit.magnetic_energy =
          m.options.force_model == ForceChoice::ZeemanTotal && ws_.mag.H.size() == moments_.size()
              ? mag::zeeman_total_energy(moments_, mag::curve_of(m.options.method), ws_.mag.H,
                                         ws_.mag.total.perm, ws_.mag.total.Hp)
              : magnetic_energy(moments_, ws_.mag.H);
      std::swap(energy_, ws_.audit);
      std::swap(state_, next);
      place_moments(m, state_, &moments_);  // moments() follows the new poses
    }
  } catch (const SimulationError&) {
    rollback();
    throw;
  } catch (const OdeFailure& e) {  // ODE failed outside the step (e.g. in collision)
    ode_->mark_broken();
    rollback();
    throw SimulationError(n, -1, "", "rigid step",
                          "step " + std::to_string(n) + ": ODE failed: " + e.what());
  }
}

}  // namespace magsim::engine
