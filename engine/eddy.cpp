// engine/eddy.cpp — stage 3b of a step: the eddy-current loss of conducting induced bodies
// (SimOptions::eddy_conductivity). Not in the paper: a stated physical loss that
// acts only where there is a field to move through, so a scene without
// magnetism keeps its mechanics.
//
// Moment j (volume V_j, the sphere it stands for has radius a_j = (3 V_j / 4π)^{1/3}) carries
// the flux density of a uniformly magnetized sphere in its applied field H_j:
//   B_j = μ0 (H_j + ⅔ M_j).
// Where B_j changes in the body's own frame at the rate Ḃ_j (the body moving through the
// field's gradient, spinning against the field, the sources moving or re-magnetizing),
// currents circulate in it, E = −½ Ḃ_j × s (s from the centre, Ḃ uniform over the sphere),
// and dissipate
//   P_j = σ ∫ |E|² dV = c_j |Ḃ_j|²,   c_j = σ a_j² V_j / 10
// (∫ |Ḃ × s|² dV = |Ḃ|² · ⅖ a² V; low-frequency limit, skin depth ≫ a_j: it overstates the
// loss of fast spins, whose currents crowd to the surface).
// The loss acts on the body's velocities q_b = (v_b, ω_b) through the Rayleigh function
// R = ½ Σ_j c_j |Ḃ_j|²:  Q_b = −∂R/∂q_b = −Σ_j c_j D_jᵀ Ḃ_j, with
//   D_j = ∂Ḃ_j/∂q_b = [ G_j | [B_j]× − G_j [r_j]× ],   G_j = ∂B_j/∂p_j = μ0 (1 + ⅔ A_j) J_j,
// r_j = p_j − x_b, A_j = ∂M/∂H (the curve), J_j = ∂H/∂p (the force stage's Jacobian); the
// body frame sees Ḃ_world − ω × B, and a moment moves at v_b + ω_b × r_j.
// Ḃ_j is measured, not modelled: the change of R_bᵀ B_j over the last ODE step (the sources'
// motion and the magnetizations' change included), expressed in the world frame. ODE moved
// the body over that step with the velocities it has now (semi-implicit Euler), so
// Ḃ_j(q') ≈ Ḃ_j + D_j (q' − q). Spin damping rates c|B|²/I reach 10³/s for a 5 mm iron ball
// at 2 T, so the loss is taken implicitly (backward Euler over the step h):
//   (M_b + h Σ_j c_j D_jᵀ D_j) Δq = −h Σ_j c_j D_jᵀ Ḃ_j,   Q_b = M_b Δq / h,
// M_b = diag(m_b 1, I_world): Q_b is the loss's force at the velocities it leaves, stable at
// any σ, and ODE applies it with the other forces (its contacts see it). Q_b drags a body
// toward the motion of the field it sits in; the reaction on the sources is not applied (the
// field's sources are not split per pair), so momentum is not conserved by this force.
// The first ODE step of a run has no previous B and takes no loss. The previous B is
// State::eddy, so a restored state, or a step retaken after a rollback, measures Ḃ as the
// uninterrupted run does.
#include "engine/stages.hpp"
#include "magnetics/det_math.hpp"

#include "magnetics/curves.hpp"
#include "magnetics/types.hpp"

#include <Eigen/Cholesky>
#include <cmath>

namespace magsim::engine {

namespace {

Mat3 cross_matrix(const Vec3& u) {
  Mat3 c;
  c << 0.0, -u.z(), u.y(), u.z(), 0.0, -u.x(), -u.y(), u.x(), 0.0;
  return c;
}

}  // namespace

double eddy_coefficient(double conductivity, double volume) {
  const double a = mag::dmath::cbrt(3.0 * volume / (4.0 * mag::kPi));
  return conductivity * a * a * volume / 10.0;
}

Vec3 eddy_flux_density(const Vec3& H, const Vec3& M) { return mag::kMu0 * (H + (2.0 / 3.0) * M); }

Mat3 eddy_flux_gradient(mag::Curve curve, const Vec3& H, double Ms, const Mat3& J) {
  return mag::kMu0 * (Mat3::Identity() + (2.0 / 3.0) * mag::curve_dMdH(curve, H, Ms)) * J;
}

void apply_eddy_losses(const Model& m, const mag::MomentDesc& set,
                       const mag::Magnetization& mz, const State& s, double h,
                       EddyMemory* memory, Workspace* ws, OdeBridge* ode) {
  const double sigma = m.options.eddy_conductivity;
  if (!(sigma > 0.0)) {  // off: empty vectors tell the energy audit there is no such force
    ws->eddy_force.clear();
    ws->eddy_torque.clear();
    return;
  }
  ws->eddy_force.assign(m.nbody, Vec3::Zero());
  ws->eddy_torque.assign(m.nbody, Vec3::Zero());
  const mag::Curve curve = m.resolved.curve;
  const std::vector<Vec3>& H = ws->mag.H;
  const std::vector<Mat3>& J = ws->mag.J;
  const bool have_prev = memory->h > 0.0 && memory->B.size() == set.size();
  memory->B.resize(set.size());
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  for (int b : m.dynamic_bodies) {
    const int adr = m.body_moment_adr[b], num = m.body_moment_num[b];
    if (num == 0) continue;
    const Mat3 R = s.quat[b].toRotationMatrix();
    Mat6 K = Mat6::Zero();  // Σ c Dᵀ D
    Vec6 g = Vec6::Zero();  // Σ c Dᵀ Ḃ
    bool any = false;
    for (int j = adr; j < adr + num; ++j) {
      if (m.moment_permanent[j]) continue;
      const Vec3 B = eddy_flux_density(H[j], mz.M[j]);
      const Vec3 Bbody = R.transpose() * B;
      if (have_prev && ode->enabled(b)) {
        const Vec3 Bdot = R * (Bbody - memory->B[j]) / memory->h;
        const Mat3 G = eddy_flux_gradient(curve, H[j], set.Ms[j], J[j]);
        Eigen::Matrix<double, 3, 6> D;
        D.leftCols<3>() = G;
        D.rightCols<3>() = cross_matrix(B) - G * cross_matrix(set.position[j] - s.pos[b]);
        const double c = eddy_coefficient(sigma, set.volume[j]);
        K += c * D.transpose() * D;
        g += c * D.transpose() * Bdot;
        any = true;
      }
      memory->B[j] = Bbody;
    }
    if (!any) continue;
    Mat6 Mb = Mat6::Zero();
    Mb.topLeftCorner<3, 3>() = m.body_mass[b] * Mat3::Identity();
    Mb.bottomRightCorner<3, 3>() = R * m.body_inertia[b] * R.transpose();
    const Vec6 dq = (Mb + h * K).ldlt().solve(-h * g);
    const Vec6 Q = Mb * dq / h;
    ws->eddy_force[b] = Q.head<3>();
    ws->eddy_torque[b] = Q.tail<3>();
    ode->add_force_at(b, ws->eddy_force[b], s.pos[b]);
    ode->add_torque(b, ws->eddy_torque[b]);
  }
  memory->h = h;
}

}  // namespace magsim::engine
