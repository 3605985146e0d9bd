// tests/engine/options_json_test.cpp — the run options as JSON (scenes/options_json.cpp):
// every field written and read back equal, the scene file reads the same spelling, and the
// names of every enum round-trip through its one table.
#include "engine/simulation.hpp"
#include "scenes/options_json.hpp"
#include "scenes/registry.hpp"
#include "scenes/scene_file.hpp"

#include <catch2/catch.hpp>

#include <set>
#include <string>
#include <vector>

using namespace magsim;
using engine::SimOptions;
using engine::Vec3;

namespace {

// Every field away from its default (and from the registry scenes' values).
SimOptions all_changed() {
  SimOptions o;
  mag::DynamicsOptions& d = o.magnetics;
  d.method = mag::Method::Kim2018;
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
  f.near_field.model = mag::NearField::Pair;
  f.near_field.mu_r = 300.0;
  o.reaction_symmetric_forces = true;
  o.balance_magnetic_torque = true;
  o.force_model = mag::ForceModel::Classic;
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
  CHECK(da.method == db.method);  // the options' top-level "method"
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
  CHECK(fa.near_field.model == fb.near_field.model);
  CHECK(fa.near_field.mu_r == fb.near_field.mu_r);
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
static_assert(sizeof(mag::FieldOptions) == 64, "FieldOptions changed: extend scenes/options_json.cpp");
static_assert(sizeof(mag::DynamicsOptions) == 168, "DynamicsOptions changed: extend scenes/options_json.cpp");
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

// One enum's table: every value 0..N-1 has one name, which parses back to it; an unknown name
// is refused (the value left alone) with a message that lists the valid names.
template <class E, std::size_t N>
void check_names(const mag::NameTable<E, N>& t, const std::string& what) {
  INFO(what);
  std::set<std::string> seen;
  for (std::size_t i = 0; i < N; ++i) {
    const E v = static_cast<E>(i);
    const std::string n = t.name(v);
    CHECK(n != "?");
    CHECK(seen.insert(n).second);
    E back = static_cast<E>(N);
    REQUIRE(t.parse(n, &back));
    CHECK(back == v);
    CHECK(std::string(t.name(back)) == n);
  }
  CHECK(std::string(t.name(static_cast<E>(N))) == "?");
  const std::vector<std::string> names = t.names();
  CHECK(std::set<std::string>(names.begin(), names.end()) == seen);
  E kept = static_cast<E>(0);
  CHECK_FALSE(t.parse("no-such-name", &kept));
  CHECK(kept == static_cast<E>(0));
  CHECK(t.unknown(what.c_str(), "no-such-name") == "unknown " + what + " 'no-such-name' (" + t.list() + ")");
}

TEST_CASE("names: every enum's values round-trip through its one table", "[options_json]") {
  check_names(mag::kMethodNames, "method");
  check_names(mag::kCurveNames, "curve");
  check_names(mag::kForceModelNames, "force model");
  check_names(mag::kFieldSolverNames, "field solver");
  check_names(mag::kThetaIntegratorNames, "theta integrator");
  check_names(mag::kCriterionNames, "criterion");
  check_names(engine::kSpaceNames, "space");
  check_names(engine::kShapeKindNames, "shape kind");
  check_names(engine::kBodyTypeNames, "body type");
  CHECK(mag::kMethodNames.list() == "ours, ours-realigned, kim2018, damping-llg, exact, anderson");
  CHECK(mag::kForceModelNames.list() == "method, zeeman, classic, zeeman-total");
}

TEST_CASE("names: the scene file refuses an unknown name with the path and the valid names", "[options_json]") {
  struct Case {
    const char* json;
    const char* says;
  };
  const Case cases[] = {
      {R"({"options": {"method": "x"}, "bodies": []})",
       "options.method: unknown method 'x' (ours, ours-realigned, kim2018, damping-llg, exact, anderson)"},
      {R"({"options": {"force_model": "x"}, "bodies": []})",
       "options.force_model: unknown force model 'x' (method, zeeman, classic, zeeman-total)"},
      {R"({"options": {"space": "x"}, "bodies": []})", "options.space: unknown space 'x' (hash, sap, simple)"},
      {R"({"options": {"field_solver": "x"}, "bodies": []})",
       "options.field_solver: unknown field solver 'x' (direct, barnes-hut, auto)"},
      {R"({"options": {"magnetics": {"criterion": "x"}}, "bodies": []})",
       "options.magnetics.criterion: unknown criterion 'x' (residual, change)"},
      {R"({"options": {"magnetics": {"theta_integrator": "x"}}, "bodies": []})",
       "options.magnetics.theta_integrator: unknown theta integrator 'x' (exact, euler)"},
      {R"({"bodies": [{"type": "x"}]})", "bodies[0].type: unknown body type 'x' (dynamic, kinematic, static)"},
      {R"({"bodies": [{"shapes": [{"kind": "x"}]}]})",
       "bodies[0].shapes[0].kind: unknown shape kind 'x' (sphere, box, capsule, cylinder)"},
  };
  for (const Case& c : cases) {
    INFO(c.json);
    CHECK_THROWS_WITH(scenes::parse_scene_json(c.json, "x.json"), Catch::Matchers::Contains(c.says));
  }
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
