// tests/engine/options_json_test.cpp — the run options as JSON (scenes/options_json.cpp):
// every field written and read back equal, the scene file reads the same spelling, and the
// method list is the method table's.
#include "engine/simulation.hpp"
#include "scenes/options_json.hpp"
#include "scenes/registry.hpp"
#include "scenes/scene_file.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace magsim;
using engine::SimOptions;
using engine::Vec3;

namespace {

// Every field away from its default (and from the registry scenes' values).
SimOptions all_changed() {
  SimOptions o;
  o.method = mag::Method::Anderson;
  mag::DynamicsOptions& d = o.magnetics;
  d.method = o.method;
  d.dt = 7.3e-8;
  d.beta = 4.25;
  d.alpha = 0.23;
  d.gamma_c_max = 1.7;
  d.adaptive_gamma_bound = false;
  d.adaptive_gamma_cap = 2.1;
  d.tol = 3.3e-5;
  d.criterion = mag::DynamicsOptions::Criterion::Change;
  d.max_iter = 77;
  d.min_pair_angle = 2e-6;
  d.theta_integrator = mag::ThetaIntegrator::Euler;
  d.anderson_depth = 7;
  d.anderson_damping = 0.6;
  d.anderson_restart_growth = 3.5;
  mag::FieldOptions& f = d.field;
  f.softening = 1.5e-3;
  f.bounded_pairs = true;
  f.solver = mag::FieldSolver::BarnesHut;
  f.bh_theta = 0.45;
  f.auto_threshold = 1234;
  f.bh_leaf_size = 17;
  f.bh_group_size = 9;
  f.bh_order = 1;
  f.bh_near_float = false;
  f.bh_far_float = false;
  o.reaction_symmetric_forces = true;
  o.balance_magnetic_torque = true;
  o.force_model = engine::ForceChoice::Classic;
  o.dt = 5e-4;
  o.max_substeps = 6;
  o.substep_reach = 0.4;
  o.substep_load = false;
  o.gravity = Vec3(0.1, -0.2, -3.7);
  o.ground = false;
  o.friction = 0.31;
  o.rolling_friction = 1e-3;
  o.rolling_friction_bodies = 4e-4;
  o.eddy_conductivity = 6.5e6;
  o.energy_guard = false;
  o.energy_guard_tolerance = 2.5e-4;
  o.energy_guard_floor = 3e-8;
  o.energy_guard_max_substeps = 17;
  o.restitution = 0.2;
  o.erp = 0.35;
  o.cfm = 2e-8;
  o.quickstep_iterations = 33;
  o.quickstep_w = 1.1;
  o.max_contacts = 6;
  o.space = engine::SpaceKind::Hash;
  o.auto_disable = true;
  o.linear_damping = 0.01;
  o.angular_damping = 0.02;
  o.surface_layer = 1e-4;
  o.max_correcting_velocity = 0.5;
  o.contact_margin = 2e-4;
  o.threads = 3;
  o.max_body_speed = 321.0;
  return o;
}

// field by field: a field missing from to_json or from_json keeps its default and fails here
void check_equal(const SimOptions& a, const SimOptions& b) {
  const mag::DynamicsOptions &da = a.magnetics, &db = b.magnetics;
  const mag::FieldOptions &fa = da.field, &fb = db.field;
  CHECK(a.method == b.method);  // magnetics.method is not an option: the engine sets it from this
  CHECK(da.dt == db.dt);
  CHECK(da.beta == db.beta);
  CHECK(da.alpha == db.alpha);
  CHECK(da.gamma_c_max == db.gamma_c_max);
  CHECK(da.adaptive_gamma_bound == db.adaptive_gamma_bound);
  CHECK(da.adaptive_gamma_cap == db.adaptive_gamma_cap);
  CHECK(da.tol == db.tol);
  CHECK(da.criterion == db.criterion);
  CHECK(da.max_iter == db.max_iter);
  CHECK(da.min_pair_angle == db.min_pair_angle);
  CHECK(da.theta_integrator == db.theta_integrator);
  CHECK(da.anderson_depth == db.anderson_depth);
  CHECK(da.anderson_damping == db.anderson_damping);
  CHECK(da.anderson_restart_growth == db.anderson_restart_growth);
  CHECK(fa.softening == fb.softening);
  CHECK(fa.bounded_pairs == fb.bounded_pairs);
  CHECK(fa.solver == fb.solver);
  CHECK(fa.bh_theta == fb.bh_theta);
  CHECK(fa.auto_threshold == fb.auto_threshold);
  CHECK(fa.bh_leaf_size == fb.bh_leaf_size);
  CHECK(fa.bh_group_size == fb.bh_group_size);
  CHECK(fa.bh_order == fb.bh_order);
  CHECK(fa.bh_near_float == fb.bh_near_float);
  CHECK(fa.bh_far_float == fb.bh_far_float);
  CHECK(a.reaction_symmetric_forces == b.reaction_symmetric_forces);
  CHECK(a.balance_magnetic_torque == b.balance_magnetic_torque);
  CHECK(a.force_model == b.force_model);
  CHECK(a.dt == b.dt);
  CHECK(a.max_substeps == b.max_substeps);
  CHECK(a.substep_reach == b.substep_reach);
  CHECK(a.substep_load == b.substep_load);
  CHECK(a.gravity == b.gravity);
  CHECK(a.ground == b.ground);
  CHECK(a.friction == b.friction);
  CHECK(a.rolling_friction == b.rolling_friction);
  CHECK(a.rolling_friction_bodies == b.rolling_friction_bodies);
  CHECK(a.eddy_conductivity == b.eddy_conductivity);
  CHECK(a.energy_guard == b.energy_guard);
  CHECK(a.energy_guard_tolerance == b.energy_guard_tolerance);
  CHECK(a.energy_guard_floor == b.energy_guard_floor);
  CHECK(a.energy_guard_max_substeps == b.energy_guard_max_substeps);
  CHECK(a.restitution == b.restitution);
  CHECK(a.erp == b.erp);
  CHECK(a.cfm == b.cfm);
  CHECK(a.quickstep_iterations == b.quickstep_iterations);
  CHECK(a.quickstep_w == b.quickstep_w);
  CHECK(a.max_contacts == b.max_contacts);
  CHECK(a.space == b.space);
  CHECK(a.auto_disable == b.auto_disable);
  CHECK(a.linear_damping == b.linear_damping);
  CHECK(a.angular_damping == b.angular_damping);
  CHECK(a.surface_layer == b.surface_layer);
  CHECK(a.max_correcting_velocity == b.max_correcting_velocity);
  CHECK(a.contact_margin == b.contact_margin);
  CHECK(a.threads == b.threads);
  CHECK(a.max_body_speed == b.max_body_speed);
}

SimOptions read_back(const nlohmann::json& j) {
  SimOptions o;
  scenes::from_json(scenes::JsonReader("test"), j, "options", &o);
  return o;
}

}  // namespace

// A new field in one of the three structs changes its size: add it to to_json, from_json,
// all_changed and check_equal above (and SCENE_FILE.md), then update the size here.
static_assert(sizeof(mag::FieldOptions) == 48, "FieldOptions changed: extend scenes/options_json.cpp");
static_assert(sizeof(mag::DynamicsOptions) == 152, "DynamicsOptions changed: extend scenes/options_json.cpp");
static_assert(sizeof(SimOptions) == 408, "SimOptions changed: extend scenes/options_json.cpp");

TEST_CASE("options_json: every field, away from its default, survives to_json and from_json", "[options_json]") {
  const SimOptions o = all_changed();
  const nlohmann::json j = scenes::to_json(o);
  check_equal(read_back(j), o);
  // and through text, as in a file
  check_equal(read_back(nlohmann::json::parse(j.dump())), o);
  // the defaults too
  check_equal(read_back(scenes::to_json(SimOptions{})), SimOptions{});
}

TEST_CASE("options_json: a scene file's options object is the same spelling", "[options_json]") {
  const SimOptions o = all_changed();
  nlohmann::json scene = {{"options", scenes::to_json(o)}, {"bodies", nlohmann::json::array()}};
  const engine::SceneDesc s = scenes::parse_scene_json(scene.dump(), "replay.json");
  check_equal(s.options, o);
}

TEST_CASE("options_json: a bad value names its JSON path", "[options_json]") {
  nlohmann::json j = scenes::to_json(SimOptions{});
  j["magnetics"]["anderson_depth"] = 99;
  CHECK_THROWS_WITH(read_back(j), Catch::Matchers::Contains("options.magnetics.anderson_depth: must be in [0, 50]"));
  j = scenes::to_json(SimOptions{});
  j["dt_m"] = 1e-7;  // the old summary.json spelling is not an option name
  CHECK_THROWS_WITH(read_back(j), Catch::Matchers::Contains("options.dt_m: unknown key"));
}

TEST_CASE("options_json: the method list is every name mag::parse_method accepts", "[options_json]") {
  const std::vector<std::string>& names = scenes::method_names();
  CHECK(names.size() == 6);
  for (const std::string& n : names) {
    mag::Method m;
    REQUIRE(mag::parse_method(n, &m));
    CHECK(mag::method_name(m) == n);
  }
  CHECK(scenes::method_list() == "ours, ours-realigned, kim2018, damping-llg, exact, anderson");
}

TEST_CASE("scene_to_json: a registry scene written and read back runs to the same state hash", "[options_json]") {
  for (const char* name : {"balls_up", "alphabets", "sakura_tree"}) {
    scenes::SceneParams p;
    p.count = 20;
    engine::SceneDesc d = scenes::find_scene(name)->build(p);
    d.options.threads = 1;
    const engine::SceneDesc back = scenes::parse_scene_json(scenes::scene_to_json(d).dump(), "written.json");
    INFO(name);
    check_equal(back.options, d.options);
    CHECK(back.bodies.size() == d.bodies.size());
    engine::Simulation a(d), b(back);
    a.run(30);
    b.run(30);
    CHECK(a.state_hash() == b.state_hash());
  }
}
