// engine/energy.hpp — the energy audit: where the kinetic energy of bodies that scatter comes
// from, step by step, split into the work of the magnetic forces, of gravity and of the
// contacts, and the total E = K + U_g + U* that a conservative force can only lose.
//
// Per ODE step of length h, with v, ω the velocities of a dynamic body before (−) and after
// (+) the step:
//   W_mag = Σ_b [F_b · ½(v⁻ + v⁺) + τ_b · ½(ω⁻ + ω⁺)] h     F_b, τ_b the net magnetic force
//                                                          and torque about the COM
//   W_g   = Σ_b m_b g · ½(v⁻ + v⁺) h                       the work of gravity
//   W_e   = the same sum for the eddy-current loss (eddy.cpp; 0 unless a scene sets σ)
//   W_c   = ΔK − W_mag − W_g − W_e                         the contacts: the residual
// ODE changes a body's momentum by the impulses h F of every force in the step
// (m(v⁺ − v⁻) = h ΣF), so ΔK_lin = Σ h F · ½(v⁻ + v⁺) holds exactly, term by term: with the
// trapezoid of the velocities each force's share of ΔK is exact, and the residual W_c is
// what the contact joints did — impulses, ERP push-out of overlaps, friction — and nothing
// of the integrator. What else lands in W_c (all zero in the scenes today): linear and
// angular damping (SimOptions::linear_damping, angular_damping; default 0), the velocities
// auto-disable zeroes, kinematic bodies' pushes, and the rotational integrator's error on
// anisotropic bodies (I_world turns during the step; ODE's implicit gyroscopic term).
//
// The potential U_g = −Σ m g·x is reported as well, but it is not what W_g is checked
// against: ODE moves x by h v⁺ (semi-implicit Euler), so −ΔU_g = Σ m g·v⁺ h and
//   D = −ΔU_g − W_g = Σ ½ m h g·(v⁺ − v⁻)          (= ½ m h² |g|² per free-falling body)
// is the integrator's energy drift under gravity, kept apart (`gravity_drift`) so that
//   ΔK + ΔU_g = W_mag + W_e + W_c − D     exactly.
// With it, K + U_g + Σ D stays constant in free fall; K + U_g alone loses ½ m h² |g|² per
// step (4 g ball, 1 ms: 2·10⁻⁷ J per step).
//
// Magnetic energy: U*, the co-energy of the moments (magnetics/coenergy.hpp). The classic
// force with converged magnetizations is exactly −∇U*, so for it (and for zeeman-total, whose
// potential E_sys replaces U*) the total E = K + U_g + U* can only fall, through the contacts,
// the eddy loss and the integrator; a rise is energy the step created. eq. 4's Zeeman force
// is not the gradient of any energy (it breaks action = reaction, see forces.hpp): there U* is
// still the moments' co-energy, and E measures what eq. 4 adds beyond it.
//
// Per rigid step (the frame, all of its sub-steps), E_start = K + U_g + U* at its start and
// E_end at its end (U* from the field the next step's forces use: the end state's converged
// magnetization), ΔE = E_end − E_start:
//   created    = Σ_steps max(0, ΔE)        dissipated = Σ_steps max(0, −ΔE).
//
// Cost: O(bodies) per step (two kinetic energies and a few dot products per body), no
// allocation; the magnetic energy reuses the field the force stage evaluated (O(moments),
// no field sum).
#pragma once

#include "engine/state.hpp"
#include "magnetics/moments.hpp"

#include <vector>

namespace magsim::engine {

/// What the steps did to the dynamic bodies' energy (J): increments of one rigid step, or
/// sums over a run.
struct EnergyFlow {
  double kinetic_change = 0.0;        ///< ΔK (J)
  double gravitational_change = 0.0;  ///< ΔU_g, U_g = −Σ m g·x (J)
  double magnetic_work = 0.0;         ///< W_mag: magnetic forces and torques (J)
  double gravity_work = 0.0;          ///< W_g = Σ m g·½(v⁻ + v⁺) h (J)
  /// W_e: the eddy-current loss's forces and torques (SimOptions::eddy_conductivity) (J); ≤ 0
  /// for a body in a still field up to second order (Ḃ is measured over the step before)
  double eddy_work = 0.0;
  double contact_work = 0.0;          ///< W_c = ΔK − W_mag − W_g − W_e: contacts, the residual (J)
  double gravity_drift = 0.0;         ///< D = −ΔU_g − W_g: semi-implicit Euler's drift (J)
  /// Σ over bodies and ODE steps of max(0, W_c,b): what the contacts gave the bodies they
  /// sped up (J, ≥ 0). Includes transfers (a ball hitting a resting one), so it bounds the
  /// contacts' injection from above; contact_work_in − contact_work = what they took.
  double contact_work_in = 0.0;
  /// Σ over rigid steps of max(0, ΔE), ΔE the step's change of E = K + U_g + U* (J, ≥ 0)
  double energy_created = 0.0;
  /// Σ over rigid steps of max(0, −ΔE) (J, ≥ 0)
  double energy_dissipated = 0.0;
};

/// The audit of a run: state functions now, and the work done since t = 0.
struct EnergyAudit {
  double kinetic = 0.0;                ///< K = Σ ½ m v² + ½ ωᵀ I_world ω, dynamic bodies (J)
  double gravitational = 0.0;          ///< U_g = −Σ m g·x over dynamic bodies (J)
  double initial_kinetic = 0.0;        ///< K at the start of the audit (J)
  double initial_gravitational = 0.0;  ///< U_g at the start of the audit (J)
  /// U* (J), the co-energy of the moments at the state (magnetics/coenergy.hpp), from the
  /// field of its converged magnetization; 0 before the first step. With the zeeman-total
  /// force model it is that force's potential E_sys (mag::zeeman_total_energy).
  double magnetic_energy = 0.0;
  /// E = K + U_g + U* at the start of the audit's first step (J)
  double initial_total = 0.0;
  /// retakes of rigid steps by the energy guard (SimOptions::energy_guard), and the steps it
  /// accepted at its sub-step cap with E still rising by more than its tolerance
  long guard_retakes = 0;
  long guard_unresolved = 0;
  EnergyFlow total;  ///< sums since the start of the audit
  EnergyFlow last;   ///< the last rigid step (the sum over its ODE sub-steps)
  long substeps = 0;  ///< ODE steps audited
  /// (nbody) per body since the start: magnetic work and contact work (J); 0 for bodies
  /// that are not dynamic. Where the energy of the bodies that flew off came from.
  std::vector<double> body_magnetic_work, body_contact_work;
  /// (nbody) the same summed over the steps where it was positive (J, ≥ 0): how much each
  /// channel ever gave the body, whatever it took back at other steps
  std::vector<double> body_magnetic_work_in, body_contact_work_in;
};

/// An audit starting at state s: K and U_g of s, nothing done yet.
EnergyAudit start_energy_audit(const Model& model, const State& s);

/// *next = a with `last` emptied, totals kept: the next rigid step audits into *next and
/// commits it with the state (a failed step leaves the audit alone). Reuses next's storage.
void begin_audit_step(const EnergyAudit& a, EnergyAudit* next);

/// Adds one ODE step of length h from `before` to `after` to acc->total and acc->last and
/// sets acc->kinetic and acc->gravitational to those of `after`. body_force and body_torque
/// (nbody) are the net magnetic force (N) and torque about the COM (N·m) that were applied
/// during the step; a body asleep before and after the step got none. eddy_force and
/// eddy_torque (nbody, or empty = none) the same for the eddy-current loss. Call it once per ODE
/// step: today once per rigid step with h = Δt_r; with ODE sub-steps, once per sub-step.
void audit_substep(const Model& model, const State& before, const State& after,
                   const std::vector<Vec3>& body_force, const std::vector<Vec3>& body_torque,
                   const std::vector<Vec3>& eddy_force, const std::vector<Vec3>& eddy_torque,
                   double h, EnergyAudit* acc);

/// E = K + U_g + U* of an audit's state (J).
inline double total_energy(const EnergyAudit& a) {
  return a.kinetic + a.gravitational + a.magnetic_energy;
}

}  // namespace magsim::engine
