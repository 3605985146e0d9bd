// engine/state.hpp — everything that changes during a run: body poses and
// velocities, sub-magnetizations, the step counter. Plain data: copy it to save, assign it
// back to restore, hash it to compare runs bit for bit.
#pragma once

#include "engine/model.hpp"
#include "magnetics/moments.hpp"

#include <cstdint>
#include <utility>
#include <vector>

namespace magsim::engine {

/// What the eddy-current loss remembers of the last ODE step (eddy.cpp).
struct EddyMemory {
  /// (nmoment) each induced moment's flux density in its body's frame at the start of the
  /// last ODE step (T); empty = none yet
  std::vector<Vec3> B;
  double h = 0.0;  ///< that step's length (s); 0 = none yet
};

struct State {
  long step = 0;  ///< rigid steps taken; time = step · Δt_r

  // bodies; poses and velocities are those of the centre of mass (the Model's body frame)
  std::vector<Vec3> pos;               ///< (nbody) m
  std::vector<Quat> quat;              ///< (nbody) body → world
  std::vector<Vec3> vel;               ///< (nbody) m/s
  std::vector<Vec3> angvel;            ///< (nbody) rad/s, world frame
  std::vector<std::uint8_t> enabled;   ///< (nbody) 0 = put to sleep by ODE's auto-disable

  /// (nmoment, Model order) the moments' magnetizations: sub-magnetizations M1, M2 and
  /// M = (M1 + M2)/2 (A/m), whether the sub-pair axis has been chosen. The only copy: the
  /// magnetics solvers work on the State being computed (Simulation::step).
  mag::Magnetization mag;

  /// Body pairs (a < b) in contact during the last step, −1 = the ground plane. Derived
  /// data kept for metrics (attachment graph); not part of the hash.
  std::vector<std::pair<int, int>> contact_pairs;
  /// (nbody) m/s: each body's velocity change over the last step, which sets the next
  /// step's number of rigid sub-steps (SimOptions::max_substeps). Derived data kept so that
  /// a restored state continues as the original; not part of the hash. Empty = zero.
  std::vector<Vec3> dvel;
  /// (nbody) m/s²: |F|/m of each body's magnetic force in the last step, the load term of
  /// the next step's sub-steps (SimOptions::substep_load). Derived data as dvel: kept so that
  /// a restored state continues as the original; not part of the hash. Empty = zero.
  std::vector<double> mag_accel;
  /// (m) the deepest overlap of any contact over the last step's collisions (each
  /// sub-step's, at its start): how far bodies sank into contacts the solver left unbalanced.
  /// Derived data kept for metrics; not part of the hash.
  double contact_depth = 0.0;
  /// SimOptions::eddy_conductivity (eddy.cpp): the loss measures Ḃ as the change of each
  /// moment's flux density in its body's frame over the last ODE step. Derived data as dvel:
  /// kept so that a restored state continues as the original; not part of the hash.
  EddyMemory eddy;
  /// SimOptions::sleep (engine/sleep.cpp), derived data as dvel: kept so that a restored state
  /// continues as the original; not part of the hash. Empty = nothing asleep, nobody still.
  ///   still_time  (nbody) s each awake body has been still for;
  ///   still_vel, still_angvel (nbody) its mean velocities (sleep.cpp);
  ///   sleep_island (nbody) −1 = awake, else the island it sleeps in (its lowest body index);
  ///   H_sleep     (nmoment) A/m, the field at a sleeping moment when its island fell asleep.
  std::vector<double> still_time;
  std::vector<Vec3> still_vel;
  std::vector<Vec3> still_angvel;
  std::vector<int> sleep_island;
  std::vector<Vec3> H_sleep;
  /// mag.M is the converged magnetization at these poses (every state a step produced): the
  /// next step's first forces need no solve. false at t = 0 (unmagnetized). Not hashed.
  bool magnetized = false;
};

/// The state at t = 0: the scene's poses and velocities, unmagnetized induced moments.
State initial_state(const Model& model);

/// 64-bit FNV-1a over the exact bytes of poses, velocities and magnetizations (pos, quat,
/// vel, angvel, mag.M1, mag.M2, mag.M, in that order). Equal hashes ⇔ bit-identical states
/// (up to hash collisions).
std::uint64_t state_hash(const State& s);

/// Throws std::invalid_argument when `s` does not fit `model` (array sizes).
void check_state_shape(const Model& model, const State& s);

}  // namespace magsim::engine
