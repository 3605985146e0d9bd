// engine/apply_forces.cpp — stage 3 of a step (Algorithm 1, "compute F using eq. 4"): one
// field + Jacobian evaluation at the converged magnetizations gives the force on every
// moment (the method's force model: Zeeman eq. 4 for ours, classic eqs. 13–14 for Kim 2018)
// and the torque on permanent moments (τ = μ0 m × H); they act on the dynamic bodies.
#include "engine/stages.hpp"

#include "magnetics/forces.hpp"

#include <algorithm>

namespace magsim::engine {

void compute_magnetic_forces(const Model& m, const mag::MomentSet& set, Workspace* ws) {
  const mag::Method method = m.options.method;
  const ForceChoice fc = m.options.force_model;
  const mag::ForceModel model = fc == ForceChoice::Zeeman        ? mag::ForceModel::Zeeman
                                : fc == ForceChoice::Classic     ? mag::ForceModel::Classic
                                : fc == ForceChoice::ZeemanTotal ? mag::ForceModel::ZeemanTotal
                                                                 : mag::force_model_of(method);
  mag::compute_forces(set, model, mag::curve_of(method),
                      m.options.magnetics.field, &ws->mag, &ws->F, &ws->tau, nullptr,
                      m.options.reaction_symmetric_forces);
}

void apply_magnetic_forces(const Model& m, const mag::MomentSet& set, Workspace* ws,
                           OdeBridge* ode) {
  // net magnetic force per body, and the torque about its COM x_b that ODE will make of the
  // forces at the moments' positions and the permanent moments' torques:
  //   F_b = Σ_j F_j,  τ_b = Σ_j (p_j − x_b) × F_j + τ_j (τ_j of permanent moments only)
  // (the energy audit's W_mag needs both; ODE gets the same loads below, unchanged)
  std::fill(ws->body_force.begin(), ws->body_force.end(), Vec3::Zero());
  std::fill(ws->body_torque.begin(), ws->body_torque.end(), Vec3::Zero());
  for (int b : m.dynamic_bodies) {
    const int adr = m.body_moment_adr[b], num = m.body_moment_num[b];
    if (num == 0) continue;
    const Vec3 x = ode->position(b);
    for (int j = adr; j < adr + num; ++j) {
      ws->body_force[b] += ws->F[j];
      ws->body_torque[b] += (set.position[j] - x).cross(ws->F[j]);
      if (m.moment_permanent[j]) ws->body_torque[b] += ws->tau[j];
    }
  }

  // auto-disable: ODE sleeps on small velocities only, so wake a sleeping body whose
  // magnetic load changed by more than 5 % of its weight (|g| taken ≥ 1 m/s²) since it
  // was last awake, e.g. because a magnet moved
  if (m.options.auto_disable) {
    const double g = std::max(m.options.gravity.norm(), 1.0);
    for (int b : m.dynamic_bodies) {
      if (m.body_moment_num[b] == 0) continue;
      if (ode->enabled(b)) {
        ws->body_force_awake[b] = ws->body_force[b];
      } else if ((ws->body_force[b] - ws->body_force_awake[b]).norm() > 0.05 * m.body_mass[b] * g) {
        ode->enable(b);
        ws->body_force_awake[b] = ws->body_force[b];
      }
    }
  }

  // F at the moment's world position (torque about the COM follows); τ of permanent moments.
  // Sleeping bodies get nothing: ODE would keep accumulating until they wake.
  for (int j = 0; j < m.nmoment; ++j) {
    const int b = m.moment_body[j];
    if (m.body_type[b] != BodyType::Dynamic || !ode->enabled(b)) continue;
    ode->add_force_at(b, ws->F[j], set.position[j]);
    if (m.moment_permanent[j]) ode->add_torque(b, ws->tau[j]);
  }
}

}  // namespace magsim::engine
