// engine/energy.cpp — the energy audit: work of the magnetic forces, gravity and contacts
// per ODE step (formulas and their reasons in energy.hpp).
#include "engine/energy.hpp"

#include "engine/metrics.hpp"
#include "magnetics/types.hpp"

#include <algorithm>

namespace magsim::engine {

namespace {

// U_g = −Σ m g·x over the dynamic bodies (J)
double gravitational_energy(const Model& m, const State& s) {
  double u = 0.0;
  for (int b : m.dynamic_bodies) u -= m.body_mass[b] * m.options.gravity.dot(s.pos[b]);
  return u;
}

double total_kinetic_energy(const Model& m, const State& s) {
  double k = 0.0;
  for (int b : m.dynamic_bodies) k += kinetic_energy(m, s, b);
  return k;
}

void add(const EnergyFlow& d, EnergyFlow* to) {
  to->kinetic_change += d.kinetic_change;
  to->gravitational_change += d.gravitational_change;
  to->magnetic_work += d.magnetic_work;
  to->gravity_work += d.gravity_work;
  to->eddy_work += d.eddy_work;
  to->contact_work += d.contact_work;
  to->gravity_drift += d.gravity_drift;
  to->contact_work_in += d.contact_work_in;
  to->energy_created += d.energy_created;
  to->energy_dissipated += d.energy_dissipated;
}

}  // namespace

EnergyAudit start_energy_audit(const Model& m, const State& s) {
  EnergyAudit a;
  a.kinetic = a.initial_kinetic = total_kinetic_energy(m, s);
  a.gravitational = a.initial_gravitational = gravitational_energy(m, s);
  a.body_magnetic_work.assign(m.nbody, 0.0);
  a.body_contact_work.assign(m.nbody, 0.0);
  a.body_magnetic_work_in.assign(m.nbody, 0.0);
  a.body_contact_work_in.assign(m.nbody, 0.0);
  return a;
}

void begin_audit_step(const EnergyAudit& a, EnergyAudit* next) {
  *next = a;  // vectors: copy-assignment into the same sizes, no allocation once warm
  next->last = EnergyFlow{};
}

void audit_substep(const Model& m, const State& before, const State& after,
                   const std::vector<Vec3>& body_force, const std::vector<Vec3>& body_torque,
                   const std::vector<Vec3>& eddy_force, const std::vector<Vec3>& eddy_torque,
                   double h, EnergyAudit* acc) {
  const bool eddy = eddy_force.size() == body_force.size() && eddy_torque.size() == body_force.size();
  const Vec3& g = m.options.gravity;
  EnergyFlow d;
  double k_before = 0.0, k_after = 0.0, u_before = 0.0, u_after = 0.0;
  for (int b : m.dynamic_bodies) {
    const double mass = m.body_mass[b];
    const double kb = kinetic_energy(m, before, b), ka = kinetic_energy(m, after, b);
    k_before += kb;
    k_after += ka;
    u_before -= mass * g.dot(before.pos[b]);
    u_after -= mass * g.dot(after.pos[b]);
    double w_mag = 0.0, w_g = 0.0, w_e = 0.0;
    // a body asleep throughout the step was given no force by ODE (nor gravity)
    if (before.enabled[b] || after.enabled[b]) {
      // work of a constant force over the step: F · ½(v⁻ + v⁺) h, exact for ODE's impulse
      const Vec3 v_mid = 0.5 * (before.vel[b] + after.vel[b]);
      const Vec3 w_mid = 0.5 * (before.angvel[b] + after.angvel[b]);
      w_mag = (body_force[b].dot(v_mid) + body_torque[b].dot(w_mid)) * h;
      w_g = mass * g.dot(v_mid) * h;
      if (eddy) w_e = (eddy_force[b].dot(v_mid) + eddy_torque[b].dot(w_mid)) * h;
    }
    // the body's own books: its contact work is its residual
    const double w_c = (ka - kb) - w_mag - w_g - w_e;
    d.magnetic_work += w_mag;
    d.eddy_work += w_e;
    d.gravity_work += w_g;
    d.contact_work_in += std::max(0.0, w_c);
    acc->body_magnetic_work[b] += w_mag;
    acc->body_contact_work[b] += w_c;
    acc->body_magnetic_work_in[b] += std::max(0.0, w_mag);
    acc->body_contact_work_in[b] += std::max(0.0, w_c);
  }
  d.kinetic_change = k_after - k_before;
  d.gravitational_change = u_after - u_before;
  // the contacts (and whatever else is not a force we know, energy.hpp): the residual
  d.contact_work = d.kinetic_change - d.magnetic_work - d.gravity_work - d.eddy_work;
  // semi-implicit Euler under gravity: −ΔU_g − W_g
  d.gravity_drift = -d.gravitational_change - d.gravity_work;
  add(d, &acc->total);
  add(d, &acc->last);
  acc->kinetic = k_after;
  acc->gravitational = u_after;
  ++acc->substeps;
}

}  // namespace magsim::engine
