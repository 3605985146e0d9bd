// scenes/options_json.cpp — SimOptions <-> JSON (scenes/options_json.hpp). The reader checks
// each value's kind and range and names the JSON path of the first bad one; the writer
// writes every field, so the two are each other's inverse (tests/engine/options_json_test.cpp).
#include "scenes/options_json.hpp"

#include "engine/limits.hpp"
#include "scenes/option_ranges.hpp"
#include "magnetics/magnetization.hpp"

namespace magsim::scenes {

using engine::SimOptions;
using json = nlohmann::json;

json to_json(const mag::DynamicsOptions& d) {
  return json{{"dt", d.dt},
              {"beta", d.beta},
              {"alpha", d.alpha},
              {"gamma_c_max", d.gamma_c_max},
              {"adaptive_gamma_bound", d.adaptive_gamma_bound},
              {"adaptive_gamma_cap", d.adaptive_gamma_cap},
              {"tol", d.tol},
              {"criterion", mag::kCriterionNames.name(d.criterion)},
              {"max_iter", d.max_iter},
              {"min_pair_angle", d.min_pair_angle},
              {"theta_integrator", mag::kThetaIntegratorNames.name(d.theta_integrator)},
              {"anderson_depth", d.anderson_depth},
              {"anderson_damping", d.anderson_damping},
              {"anderson_restart_growth", d.anderson_restart_growth},
              {"softening", d.field.softening},
              {"bounded_pairs", d.field.bounded_pairs}};
}

json to_json(const SimOptions& o) {
  const mag::FieldOptions& f = o.magnetics.field;
  return json{{"method", mag::method_name(o.magnetics.method)},
              {"dt", o.dt},
              {"gravity", vec3_json(o.gravity)},
              {"ground", o.ground},
              {"friction", o.friction},
              {"restitution", o.restitution},
              {"erp", o.erp},
              {"cfm", o.cfm},
              {"quickstep_iterations", o.quickstep_iterations},
              {"quickstep_w", o.quickstep_w},
              {"max_contacts", o.max_contacts},
              {"space", engine::space_name(o.space)},
              {"auto_disable", o.auto_disable},
              {"linear_damping", o.linear_damping},
              {"angular_damping", o.angular_damping},
              {"surface_layer", o.surface_layer},
              {"max_correcting_velocity", o.max_correcting_velocity},
              {"contact_margin", o.contact_margin},
              {"threads", o.threads},
              {"reaction_symmetric_forces", o.reaction_symmetric_forces},
              {"balance_magnetic_torque", o.balance_magnetic_torque},
              {"force_model", mag::kForceModelNames.name(o.force_model)},
              {"energy_guard", o.energy_guard},
              {"energy_guard_tolerance", o.energy_guard_tolerance},
              {"energy_guard_floor", o.energy_guard_floor},
              {"energy_guard_max_substeps", o.energy_guard_max_substeps},
              {"max_substeps", o.max_substeps},
              {"substep_reach", o.substep_reach},
              {"substep_load", o.substep_load},
              {"rolling_friction", o.rolling_friction},
              {"rolling_friction_bodies", o.rolling_friction_bodies},
              {"eddy_conductivity", o.eddy_conductivity},
              {"max_body_speed", o.max_body_speed},
              {"field_solver", mag::field_solver_name(f.solver)},
              {"bh_theta", f.bh_theta},
              {"bh_threshold", f.auto_threshold},
              {"bh_leaf_size", f.bh_leaf_size},
              {"bh_group_size", f.bh_group_size},
              {"bh_order", f.bh_order},
              {"bh_near_float", f.bh_near_float},
              {"bh_far_float", f.bh_far_float},
              {"near_field", mag::kNearFieldNames.name(f.near_field.model)},
              {"near_field_mu_r", f.near_field.mu_r},
              {"magnetics", to_json(o.magnetics)}};
}

void from_json(const JsonReader& r, const json& j, const std::string& path, mag::DynamicsOptions* d) {
  r.keys(j, path, {"dt", "beta", "alpha", "gamma_c_max", "adaptive_gamma_bound", "adaptive_gamma_cap",
                   "tol", "criterion", "max_iter", "min_pair_angle", "theta_integrator", "softening",
                   "bounded_pairs", "anderson_depth", "anderson_damping", "anderson_restart_growth"});
  if_present(j, "dt", path, [&](const json& v, const std::string& p) { d->dt = r.option(v, p, option_range("magnetics.dt")); });
  if_present(j, "beta", path, [&](const json& v, const std::string& p) { d->beta = r.positive(v, p); });
  if_present(j, "alpha", path, [&](const json& v, const std::string& p) { d->alpha = r.in_range(v, p, 1e-12, 1.0); });
  if_present(j, "gamma_c_max", path, [&](const json& v, const std::string& p) { d->gamma_c_max = r.in_range(v, p, 1.0 / 3.0, 1e12); });
  if_present(j, "adaptive_gamma_bound", path, [&](const json& v, const std::string& p) { d->adaptive_gamma_bound = r.boolean(v, p); });
  if_present(j, "adaptive_gamma_cap", path, [&](const json& v, const std::string& p) { d->adaptive_gamma_cap = r.positive(v, p); });
  if_present(j, "tol", path, [&](const json& v, const std::string& p) { d->tol = r.option(v, p, option_range("magnetics.tol")); });
  if_present(j, "max_iter", path, [&](const json& v, const std::string& p) { d->max_iter = static_cast<int>(r.option(v, p, option_range("magnetics.max_iter"))); });
  if_present(j, "min_pair_angle", path, [&](const json& v, const std::string& p) { d->min_pair_angle = r.in_range(v, p, 1e-300, 0.0099999); });
  if_present(j, "theta_integrator", path, [&](const json& v, const std::string& p) {
    d->theta_integrator = r.named(v, p, mag::kThetaIntegratorNames, "theta integrator");
  });
  if_present(j, "criterion", path, [&](const json& v, const std::string& p) {
    d->criterion = r.named(v, p, mag::kCriterionNames, "criterion");
  });
  if_present(j, "softening", path, [&](const json& v, const std::string& p) { d->field.softening = r.option(v, p, option_range("magnetics.softening")); });
  if_present(j, "bounded_pairs", path, [&](const json& v, const std::string& p) { d->field.bounded_pairs = r.boolean(v, p); });
  if_present(j, "anderson_depth", path, [&](const json& v, const std::string& p) { d->anderson_depth = r.integer(v, p, 0, 50); });
  if_present(j, "anderson_damping", path, [&](const json& v, const std::string& p) { d->anderson_damping = r.in_range(v, p, 1e-300, 1.0); });
  if_present(j, "anderson_restart_growth", path, [&](const json& v, const std::string& p) { d->anderson_restart_growth = r.positive(v, p); });
  const std::string e = mag::validate(*d);
  if (!e.empty()) r.fail(path, e);
}

void from_json(const JsonReader& r, const json& j, const std::string& path, SimOptions* o) {
  r.keys(j, path, {"method", "dt", "gravity", "ground", "friction", "restitution", "erp", "cfm",
                   "quickstep_iterations", "max_contacts", "space", "auto_disable", "linear_damping",
                   "angular_damping", "surface_layer", "max_correcting_velocity", "contact_margin",
                   "threads", "reaction_symmetric_forces", "balance_magnetic_torque", "field_solver",
                   "bh_theta", "bh_threshold", "magnetics", "force_model", "max_substeps", "substep_reach",
                   "substep_load", "rolling_friction", "rolling_friction_bodies", "eddy_conductivity",
                   "quickstep_w", "max_body_speed", "bh_leaf_size", "bh_group_size", "bh_order",
                   "bh_near_float", "bh_far_float", "near_field", "near_field_mu_r", "energy_guard", "energy_guard_tolerance",
                   "energy_guard_floor", "energy_guard_max_substeps"});
  if_present(j, "method", path, [&](const json& v, const std::string& p) { o->magnetics.method = r.named(v, p, mag::kMethodNames, "method"); });
  if_present(j, "dt", path, [&](const json& v, const std::string& p) {
    o->dt = r.option(v, p, option_range("dt"));
  });
  if_present(j, "gravity", path, [&](const json& v, const std::string& p) { o->gravity = r.bounded(v, p, engine::limits::kMaxGravity, "m/s^2"); });
  if_present(j, "ground", path, [&](const json& v, const std::string& p) { o->ground = r.boolean(v, p); });
  if_present(j, "friction", path, [&](const json& v, const std::string& p) { o->friction = r.non_negative(v, p); });
  if_present(j, "restitution", path, [&](const json& v, const std::string& p) { o->restitution = r.in_range(v, p, 0, 1); });
  if_present(j, "erp", path, [&](const json& v, const std::string& p) { o->erp = r.in_range(v, p, 0, 1); });
  if_present(j, "cfm", path, [&](const json& v, const std::string& p) { o->cfm = r.non_negative(v, p); });
  if_present(j, "quickstep_iterations", path, [&](const json& v, const std::string& p) { o->quickstep_iterations = static_cast<int>(r.option(v, p, option_range("quickstep_iterations"))); });
  if_present(j, "max_contacts", path, [&](const json& v, const std::string& p) { o->max_contacts = r.integer(v, p, 1, 64); });
  if_present(j, "space", path, [&](const json& v, const std::string& p) { o->space = r.named(v, p, engine::kSpaceNames, "space"); });
  if_present(j, "auto_disable", path, [&](const json& v, const std::string& p) { o->auto_disable = r.boolean(v, p); });
  if_present(j, "linear_damping", path, [&](const json& v, const std::string& p) { o->linear_damping = r.non_negative(v, p); });
  if_present(j, "angular_damping", path, [&](const json& v, const std::string& p) { o->angular_damping = r.non_negative(v, p); });
  if_present(j, "surface_layer", path, [&](const json& v, const std::string& p) { o->surface_layer = r.non_negative(v, p); });
  if_present(j, "max_correcting_velocity", path, [&](const json& v, const std::string& p) { o->max_correcting_velocity = r.non_negative(v, p); });
  if_present(j, "contact_margin", path, [&](const json& v, const std::string& p) { o->contact_margin = r.number(v, p); });
  if_present(j, "threads", path, [&](const json& v, const std::string& p) { o->threads = static_cast<int>(r.option(v, p, option_range("threads"))); });
  if_present(j, "force_model", path, [&](const json& v, const std::string& p) {
    o->force_model = r.named(v, p, mag::kForceModelNames, "force model");
  });
  if_present(j, "energy_guard", path, [&](const json& v, const std::string& p) { o->energy_guard = r.boolean(v, p); });
  if_present(j, "energy_guard_tolerance", path, [&](const json& v, const std::string& p) { o->energy_guard_tolerance = r.option(v, p, option_range("energy_guard_tolerance")); });
  if_present(j, "energy_guard_floor", path, [&](const json& v, const std::string& p) { o->energy_guard_floor = r.option(v, p, option_range("energy_guard_floor")); });
  if_present(j, "energy_guard_max_substeps", path, [&](const json& v, const std::string& p) { o->energy_guard_max_substeps = static_cast<int>(r.option(v, p, option_range("energy_guard_max_substeps"))); });
  if_present(j, "max_substeps", path, [&](const json& v, const std::string& p) { o->max_substeps = static_cast<int>(r.option(v, p, option_range("max_substeps"))); });
  if_present(j, "substep_reach", path, [&](const json& v, const std::string& p) { o->substep_reach = r.option(v, p, option_range("substep_reach")); });
  if_present(j, "substep_load", path, [&](const json& v, const std::string& p) { o->substep_load = r.boolean(v, p); });
  if_present(j, "rolling_friction", path, [&](const json& v, const std::string& p) { o->rolling_friction = r.option(v, p, option_range("rolling_friction")); });
  if_present(j, "rolling_friction_bodies", path,
             [&](const json& v, const std::string& p) { o->rolling_friction_bodies = r.option(v, p, option_range("rolling_friction_bodies")); });
  if_present(j, "eddy_conductivity", path,
             [&](const json& v, const std::string& p) { o->eddy_conductivity = r.option(v, p, option_range("eddy_conductivity")); });
  if_present(j, "quickstep_w", path, [&](const json& v, const std::string& p) {
    o->quickstep_w = r.option(v, p, option_range("quickstep_w"));
  });
  if_present(j, "reaction_symmetric_forces", path, [&](const json& v, const std::string& p) { o->reaction_symmetric_forces = r.boolean(v, p); });
  if_present(j, "balance_magnetic_torque", path, [&](const json& v, const std::string& p) { o->balance_magnetic_torque = r.boolean(v, p); });
  mag::FieldOptions& f = o->magnetics.field;
  if_present(j, "field_solver", path, [&](const json& v, const std::string& p) {
    f.solver = r.named(v, p, mag::kFieldSolverNames, "field solver");
  });
  if_present(j, "bh_theta", path, [&](const json& v, const std::string& p) {
    f.bh_theta = r.option(v, p, option_range("bh_theta"));
  });
  if_present(j, "bh_threshold", path, [&](const json& v, const std::string& p) { f.auto_threshold = static_cast<int>(r.option(v, p, option_range("bh_threshold"))); });
  if_present(j, "bh_leaf_size", path, [&](const json& v, const std::string& p) { f.bh_leaf_size = r.integer(v, p, 1, 1000000); });
  if_present(j, "bh_group_size", path, [&](const json& v, const std::string& p) { f.bh_group_size = r.integer(v, p, 1, 1000000); });
  if_present(j, "bh_order", path, [&](const json& v, const std::string& p) { f.bh_order = r.integer(v, p, 1, 2); });
  if_present(j, "bh_near_float", path, [&](const json& v, const std::string& p) { f.bh_near_float = r.boolean(v, p); });
  if_present(j, "bh_far_float", path, [&](const json& v, const std::string& p) { f.bh_far_float = r.boolean(v, p); });
  if_present(j, "near_field", path, [&](const json& v, const std::string& p) {
    f.near_field.model = r.named(v, p, mag::kNearFieldNames, "near-field model");
  });
  if_present(j, "near_field_mu_r", path, [&](const json& v, const std::string& p) { f.near_field.mu_r = r.in_range(v, p, 10.0, 10000.0); });
  if_present(j, "max_body_speed", path, [&](const json& v, const std::string& p) { o->max_body_speed = r.non_negative(v, p); });
  if_present(j, "magnetics", path, [&](const json& v, const std::string& p) { from_json(r, v, p, &o->magnetics); });
}

}  // namespace magsim::scenes
