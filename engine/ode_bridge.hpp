// engine/ode_bridge.hpp — the engine's only door to ODE. No ODE type leaks
// out of this header: the world, space, bodies, geoms and contact group live behind a pimpl.
//
// ODE is treated as a pure function of State: each step the bridge writes every body's pose
// and velocity from the State, collides, steps, and the caller reads the result back. So a
// restored State continues bit-identically (ODE re-normalizes a quaternion on every write;
// writing every step makes that happen on every path alike), and the contact order is fixed
// by sorting contacts on (shape, shape, index) rather than trusting the broad phase's order.
#pragma once

#include "engine/state.hpp"

#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

namespace magsim::engine {

/// ODE reported an internal error or a failed assertion (e.g. normalizing a NaN
/// quaternion). ODE would abort(); the bridge installs handlers that throw this instead, so
/// the Simulation can roll back and report (and rebuild the ODE world, see broken()).
class OdeFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class OdeBridge {
 public:
  /// Creates the world, the space (SimOptions::space), one ODE body per dynamic or
  /// kinematic body, one geom per shape (static bodies: geoms without a body), the ground.
  explicit OdeBridge(const Model& model);
  ~OdeBridge();
  OdeBridge(const OdeBridge&) = delete;
  OdeBridge& operator=(const OdeBridge&) = delete;

  /// Sets pose, velocity and enabled flag of every ODE body from s.
  void write_state(const State& s);
  /// Reads pose, velocity and enabled flag of every ODE body into s (static bodies untouched).
  void read_state(State* s) const;

  /// dBodyAddForceAtPos / dBodyAddTorque on body i (dynamic bodies only; world frame).
  void add_force_at(int body, const Vec3& F, const Vec3& p);
  void add_torque(int body, const Vec3& tau);
  /// Wakes a body put to sleep by auto-disable.
  void enable(int body);
  bool enabled(int body) const;
  /// The ODE body's position (its centre of mass, m): what write_state() set until the step.
  Vec3 position(int body) const;
  /// Overwrites a body's linear velocity (the test hook of the safety check).
  void set_velocity(int body, const Vec3& v);

  /// Grows each dynamic body's collision geoms by the contact margin plus the distance it
  /// can cover in a step of h seconds under its velocity, magnetic force (N, per body) and
  /// gravity.
  void update_margins(const State& s, const std::vector<Vec3>& magnetic_force, double h);
  /// Broad + narrow phase, contacts sorted into a fixed order, contact joints created for a
  /// step of h seconds (speculative contacts close their gap within h).
  /// Writes the touching body pairs (a < b, −1 = ground) to *pairs; returns the number of
  /// contact joints. The contacts are as soft as SimOptions::erp and cfm make them at a step
  /// of h_soft (the same spring and damper at h; h_soft ≤ 0: at h), so that retaking a step
  /// in finer sub-steps does not push overlaps out faster. *max_depth (when given) gets the
  /// deepest overlap of any contact (m, ≥ 0; speculative gaps count as 0). *joined (when
  /// given) gets every body pair a contact joint ties, sorted, while some body is disabled
  /// (empty otherwise: no sleeper to wake): ODE enables a disabled body that a joint ties to
  /// an enabled one. With SimOptions::sleep a speculative contact to a
  /// disabled body whose gap the bodies' speed does not close within h ties the other body
  /// to the world instead.
  int collide(std::vector<std::pair<int, int>>* pairs, double h, double h_soft = 0.0,
              double* max_depth = nullptr, std::vector<std::pair<int, int>>* joined = nullptr);
  /// dWorldQuickStep over h (Δt_r or a sub-step of it; ODE's constraint-order RNG seeded
  /// from `seed`), then empties the contact group. Damping rates are kept per second.
  void quickstep(unsigned long seed, double h);
  /// Drops contact joints created by collide() but not yet stepped (after a failed step).
  void discard_contacts();
  /// True after ODE failed inside quickstep(): its world is left half-stepped and must not
  /// be stepped again; the owner replaces the bridge. (ODE's shared stepping state is left
  /// unfinished too, so dCloseODE, which would assert on it, is skipped from then on.)
  bool broken() const;
  /// Declares the world unusable (ODE failed inside a call other than quickstep()).
  void mark_broken();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace magsim::engine
