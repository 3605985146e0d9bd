// tests/scenes/options_json_test.cpp — the run options as JSON (scenes/options_json.cpp): the
// scene file reads the spelling summary.json and --write-scene write, a bad value names its
// path, and the names of every enum round-trip through its one table. Each option's own round
// trip: options_table_test.cpp.
#include "engine/simulation.hpp"
#include "scenes/options_json.hpp"
#include "scenes/registry.hpp"
#include "scenes/scene_file.hpp"
#include "tests/engine/option_probes.hpp"

#include <catch2/catch.hpp>

#include <set>
#include <string>
#include <vector>

using namespace magsim;
using engine::SimOptions;

namespace {

SimOptions read_back(const nlohmann::json& j) {
  SimOptions o;
  scenes::from_json(scenes::JsonReader("test"), j, "options", &o);
  return o;
}

}  // namespace

TEST_CASE("options_json: a scene file's options object is the same spelling", "[options_json]") {
  const SimOptions o = test::all_changed();
  nlohmann::json scene = {{"options", scenes::to_json(o)}, {"bodies", nlohmann::json::array()}};
  const engine::SceneDesc s = scenes::parse_scene_json(scene.dump(), "replay.json");
  test::check_equal(s.options, o);
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
      {R"({"options": {"space": "x"}, "bodies": []})", "options.space: unknown broad phase 'x' (hash, sap, simple)"},
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
    test::check_equal(back.options, d.options);
    CHECK(back.bodies.size() == d.bodies.size());
    engine::Simulation a(d), b(back);
    a.run(30);
    b.run(30);
    CHECK(a.state_hash() == b.state_hash());
  }
}
