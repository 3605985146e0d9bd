// engine/stages.hpp — the stages of one rigid step (paper Algorithm 1), one file each:
//   place_moments.cpp  (1) moments take their world poses from their bodies
//   magnetize.cpp      (2) magnetization dynamics until converged or capped
//   apply_forces.cpp   (3) magnetic forces and torques onto the ODE bodies
//   ode_bridge.cpp     (4) collide + QuickStep
//   safety.cpp         non-finite checks between the stages
// step.cpp calls them in order.
#pragma once

#include "engine/ode_bridge.hpp"
#include "engine/profile.hpp"
#include "engine/workspace.hpp"
#include "magnetics/moments.hpp"

namespace magsim::engine {

// (1) place_moments.cpp
/// The moment description of a model for the magnetics solvers: moment j of the model, group
/// id = its body index, H0 set; positions and permanent moments come from place_moments.
mag::MomentDesc make_moment_desc(const Model& model);
/// World positions p_j = x_b + R_b o_j and permanent moments m_j = R_b m_j^body at the poses
/// of s; with mz, also the permanent moments' magnetizations M_j = m_j / V_j.
void place_moments(const Model& model, const State& s, mag::MomentDesc* set,
                   mag::Magnetization* mz);

// (1b) substeps.cpp
/// The number of rigid sub-steps for the frame starting at s (SimOptions::max_substeps).
int choose_substeps(const Model& model, const State& s);

// (2) magnetize.cpp
/// Relaxes the induced magnetizations *mz (warm-started from their values) with the model's
/// method, or solves them exactly for Method::Exact. Fills iterations/converged/cap_hit.
void magnetize(const Model& model, const mag::MomentDesc& set, mag::Magnetization* mz,
               Workspace* ws, StepProfile* prof);

// (3) apply_forces.cpp
/// Forces and torques on every moment (ws->F, ws->tau) with the method's force model.
void compute_magnetic_forces(const Model& model, const mag::MomentDesc& set,
                             const mag::Magnetization& mz, Workspace* ws);
/// Adds them to the dynamic bodies: F at each moment's world position, τ of permanent
/// moments as a body torque. Wakes a sleeping body whose magnetic load changed.
void apply_magnetic_forces(const Model& model, const mag::MomentDesc& set,
                           const mag::Magnetization& mz, Workspace* ws, OdeBridge* ode);
/// SimOptions::balance_magnetic_torque: cancels the net torque the reaction-symmetric
/// Zeeman forces leave (ws->balance_force, added to ws->body_force; apply_forces.cpp).
void balance_magnetic_torque(const Model& model, const mag::MomentDesc& set,
                             const mag::Magnetization& mz, Workspace* ws, const OdeBridge* ode);
/// The least correction δF_b (Σ_b |δF_b|²/w_b minimal) with Σ δF_b = 0 and
/// Σ_b x_b × δF_b = −L; bodies with w_b = 0 take none. The part of L along a line through
/// every weighted body cannot be cancelled by forces and stays.
void torque_balance_forces(const std::vector<Vec3>& x, const std::vector<double>& w, const Vec3& L,
                           std::vector<Vec3>* dF);

// (3b) eddy.cpp
/// SimOptions::eddy_conductivity: the eddy-current loss of the induced moments' bodies,
/// taken implicitly over the ODE step h starting at the poses of s with the magnetization mz,
/// added to ODE as a force and torque per body (ws->eddy_force, ws->eddy_torque: empty when
/// σ = 0, zero while *memory holds no previous step). Reads the last ODE step's flux
/// densities from *memory and leaves this step's there. Needs the fields and Jacobians of
/// the force stage (ws->mag.H, ws->mag.J).
void apply_eddy_losses(const Model& model, const mag::MomentDesc& set,
                       const mag::Magnetization& mz, const State& s, double h,
                       EddyMemory* memory, Workspace* ws, OdeBridge* ode);
/// c = σ a² V / 10 (a = the radius of a sphere of volume V): P = c |Ḃ|² (W).
double eddy_coefficient(double conductivity, double volume);
/// B = μ0 (H + ⅔ M), the flux density inside a uniformly magnetized sphere in the field H (T).
Vec3 eddy_flux_density(const Vec3& H, const Vec3& M);
/// ∂B/∂p = μ0 (1 + ⅔ ∂M/∂H) ∂H/∂p for M = f(H) of the curve (T/m).
Mat3 eddy_flux_gradient(mag::Curve curve, const Vec3& H, double Ms, const Mat3& J);

}  // namespace magsim::engine
