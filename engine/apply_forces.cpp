// engine/apply_forces.cpp — stage 3 of a step (Algorithm 1, "compute F using eq. 4"): one
// field + Jacobian evaluation at the converged magnetizations gives the force on every
// moment (the force model compile_model resolved, Model::resolved: classic eqs. 13–14 by
// default and for Kim 2018, Zeeman eq. 4 for the paper's θ dynamics) and the torque on
// permanent moments (τ = μ0 m × H); they act on the dynamic bodies.
#include "engine/stages.hpp"

#include "magnetics/forces.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

namespace magsim::engine {

void compute_magnetic_forces(const Model& m, const mag::MomentDesc& set,
                             const mag::Magnetization& mz, Workspace* ws) {
  mag::compute_forces(set, mz, m.resolved.force, m.resolved.curve,
                      m.options.magnetics.field, &ws->mag, &ws->F, &ws->tau, nullptr,
                      m.options.reaction_symmetric_forces);
}

void apply_magnetic_forces(const Model& m, const mag::MomentDesc& set,
                           const mag::Magnetization& mz, Workspace* ws, OdeBridge* ode) {
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

  if (m.options.balance_magnetic_torque) balance_magnetic_torque(m, set, mz, ws, ode);

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
  // the torque balance's forces act at the centres of mass (no torque about them)
  if (!ws->balance_force.empty())
    for (int b : m.dynamic_bodies)
      if (ode->enabled(b) && ws->balance_force[b] != Vec3::Zero())
        ode->add_force_at(b, ws->balance_force[b], ode->position(b));
}

// The least correction that cancels a net torque L (SimOptions::balance_magnetic_torque):
//   minimise Σ_b |δF_b|² / w_b   subject to   Σ_b δF_b = 0,   Σ_b (x_b − c) × δF_b = −L.
// Stationarity gives δF_b = w_b (λ + α × (x_b − c)); with c the w-weighted centroid,
// Σ δF = 0 gives λ = 0, and the torque condition I_w α = −L with
//   I_w = Σ_b w_b (|r_b|² 1 − r_b r_bᵀ),  r_b = x_b − c
// (the inertia tensor of point "masses" w_b). Where the bodies with weight lie on a line,
// I_w is singular and the part of L along the line cannot be cancelled by forces: it stays
// (pseudo-inverse, eigenvalues below 1e-12 of the largest dropped).
void torque_balance_forces(const std::vector<Vec3>& x, const std::vector<double>& w, const Vec3& L,
                           std::vector<Vec3>* dF) {
  dF->assign(x.size(), Vec3::Zero());
  double W = 0.0;
  Vec3 c = Vec3::Zero();
  for (std::size_t b = 0; b < x.size(); ++b) {
    W += w[b];
    c += w[b] * x[b];
  }
  if (!(W > 0.0)) return;
  c /= W;
  Mat3 I = Mat3::Zero();
  for (std::size_t b = 0; b < x.size(); ++b) {
    if (w[b] == 0.0) continue;
    const Vec3 r = x[b] - c;
    I += w[b] * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(I);
  const Vec3 lam = eig.eigenvalues();
  const double floor = 1e-12 * lam.cwiseAbs().maxCoeff();
  Vec3 a = Vec3::Zero();  // α = I_w⁺ (−L)
  for (int k = 0; k < 3; ++k) {
    if (!(lam[k] > floor)) continue;
    const Vec3 v = eig.eigenvectors().col(k);
    a -= (v.dot(L) / lam[k]) * v;
  }
  for (std::size_t b = 0; b < x.size(); ++b)
    if (w[b] != 0.0) (*dF)[b] = w[b] * a.cross(x[b] - c);
}

// The reaction-symmetric Zeeman forces (mag::compute_forces) sum to zero, but their torques
// about any point do not: Σ_j (p_j × F_j + τ_j) = −Σ_{j induced} ℓ_j with
//   ℓ_j = ½ μ0 (m̃_j × H_j + m_j × H̃_j),
// the torque of the pair energy behind those forces on the induced moment j, which Algorithm
// 1 does not apply (M is re-induced, it does not turn with its ball); H̃ is the field of the
// effective moments m̃ (tests/magnetics/forces_test.cpp; m̃_j ∥ H_j once M_j ∥ H_j). ℓ_j
// vanishes when every source's effective moment is the same multiple of its moment; it does
// not where iron (m̃ ≈ 2(χ+1) m in the linear range) meets a permanent magnet (m̃ = m) or
// saturated iron. Summed over falling_magnet it is about 0.2 N·m at ×1 and 1 N·m at ×3: at
// ×3 with 40 QuickStep iterations the magnet and its heap rolled off across the
// floor (0.65 m in 2 s) while the magnetic work kept growing. The correction takes the least
// forces that cancel L = −Σ ℓ_j, weighted by each body's share w_b = |Σ_{j∈b} ℓ_j| so that it
// lands where the torque arises (mass weights over every body did worse: at ×3, 1.2 s, KE
// 4.6 J and a ball at 12.8 m/s; they load the farthest balls most, whose lever arms are the
// longest). Applied to the awake dynamic bodies; a sleeping body takes no share.
void balance_magnetic_torque(const Model& m, const mag::MomentDesc& set,
                             const mag::Magnetization& mz, Workspace* ws, const OdeBridge* ode) {
  ws->balance_force.clear();
  const std::vector<Vec3>& Ht = ws->mag.H_eff_src;  // set by the reaction-symmetric forces
  if (Ht.size() != set.size()) return;             // classic or zeeman-total: no such torque
  const std::vector<Vec3>& H = ws->mag.H;
  const mag::MomentSet& eff = ws->mag.effective;    // m̃_j of the induced moments
  ws->balance_x.assign(m.nbody, Vec3::Zero());
  ws->balance_w.assign(m.nbody, 0.0);
  Vec3 L = Vec3::Zero();
  for (int b : m.dynamic_bodies) {
    if (!ode->enabled(b)) continue;
    Vec3 share = Vec3::Zero();
    const int adr = m.body_moment_adr[b], num = m.body_moment_num[b];
    for (int j = adr; j < adr + num; ++j)
      if (!m.moment_permanent[j])
        share += 0.5 * mag::kMu0 *
                 (eff.moment(j).cross(H[j]) + mag::moment(set, mz, j).cross(Ht[j]));
    L -= share;
    ws->balance_x[b] = ode->position(b);
    ws->balance_w[b] = share.norm();
  }
  torque_balance_forces(ws->balance_x, ws->balance_w, L, &ws->balance_force);
  for (int b : m.dynamic_bodies) ws->body_force[b] += ws->balance_force[b];
}

}  // namespace magsim::engine
