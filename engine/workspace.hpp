// engine/workspace.hpp — per-step scratch: fields, forces, the next state.
// Sized once; a warm step allocates nothing.
#pragma once

#include "engine/energy.hpp"
#include "engine/state.hpp"
#include "magnetics/magnetization.hpp"

#include <vector>

namespace magsim::engine {

struct Workspace {
  mag::MagWorkspace mag;          ///< fields, Jacobians, packed sources (magnetics core)
  std::vector<mag::Vec3> F;       ///< (nmoment) magnetic force on each moment (N)
  std::vector<mag::Vec3> tau;     ///< (nmoment) magnetic torque on each moment (N·m)
  std::vector<Vec3> body_force;   ///< (nbody) net magnetic force on each body this step (N)
  /// (nbody) net magnetic torque on each body about its COM this step (N·m): the lever arms
  /// of its moments' forces and the torques of its permanent moments (energy audit)
  std::vector<Vec3> body_torque;
  /// (nbody) net magnetic force when the body was last awake (auto-disable wake-up)
  std::vector<Vec3> body_force_awake;
  /// (nbody) SimOptions::balance_magnetic_torque: the correction per body (N; empty when
  /// not applied this step), and its scratch (positions, weights)
  std::vector<Vec3> balance_force;
  std::vector<Vec3> balance_x;
  std::vector<double> balance_w;
  /// SimOptions::eddy_conductivity (eddy.cpp): the loss's force and torque per body this ODE
  /// step (N, N·m; empty when the loss is off). Its memory of the last step is State::eddy.
  std::vector<Vec3> eddy_force;
  std::vector<Vec3> eddy_torque;
  /// F, tau and mag.H/J hold the forces of the committed state's poses and magnetization
  /// (computed at the end of the step that made it): the next step's first sub-step uses
  /// them. Cleared by a rollback or a restore.
  bool forces_ready = false;
  double coenergy_start = 0.0;    ///< U* (J) at the start of the step being taken
  State sub_prev;                 ///< the state after the last sub-step (energy audit)
  State next;                     ///< the state being computed; swapped in when it checks out
  EnergyAudit audit;              ///< the energy audit being computed, committed with next
  /// bodies that fell asleep at the attempt's end state (sleep.cpp: settle → finish_sleep)
  std::vector<int> fell_asleep;
  /// the body pairs the last collisions tied by contact joints (sleep: who touches a sleeper)
  std::vector<std::pair<int, int>> joined;
};

}  // namespace magsim::engine
