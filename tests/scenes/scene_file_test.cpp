// tests/scenes/scene_file_test.cpp — JSON scene files (scenes/scene_file.cpp): the
// example loads and runs; bad files fail with the file and the JSON path in the message.
#include "engine/simulation.hpp"
#include "scenes/scene_file.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace magsim;
using Catch::Matchers::Contains;

namespace {

const std::string kExample = std::string(MAGSIM_SOURCE_DIR) + "/scenes/examples/two_balls.json";

std::string error_of_origin(const std::string& text, const std::string& origin) {
  try {
    scenes::parse_scene_json(text, origin);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

std::string error_of(const std::string& text) {
  try {
    scenes::parse_scene_json(text, "scene.json");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

const char* kGood = R"({
  "bodies": [
    {"name": "m", "type": "static", "shapes": [{"kind": "box", "size": [0.01, 0.01, 0.01]}]},
    {"name": "b", "position": [0, 0, 0.1], "shapes": [{"kind": "sphere", "size": 0.005}],
     "moments": [{"volume": 5e-7}]}
  ]
})";

}  // namespace

TEST_CASE("scene_file: the example loads and its balls rise to the magnet", "[scene_file]") {
  const engine::SceneDesc s = scenes::load_scene_file(kExample);
  CHECK(s.name == "two_balls");
  REQUIRE(s.bodies.size() == 3);
  CHECK(s.bodies[0].type == engine::BodyType::Static);
  CHECK(s.bodies[0].magnet);
  CHECK(s.bodies[0].moments[0].permanent);
  CHECK(s.bodies[1].shapes[0].size.x() == 0.005);
  CHECK(s.options.magnetics.method == mag::Method::OursRealigned);
  engine::SceneDesc s1 = s;
  s1.options.threads = 1;
  engine::Simulation sim(s1);
  sim.run(500);
  CHECK(sim.body_position(1).z() > 0.015);
  CHECK(sim.metrics().attached == 2);
}

TEST_CASE("scene_file: a minimal file takes the SceneDesc defaults", "[scene_file]") {
  const engine::SceneDesc s = scenes::parse_scene_json(kGood, "dir/minimal.json");
  CHECK(s.name == "minimal");
  CHECK(s.escape_radius == 0.0);  // not measured unless the file says
  CHECK(s.options.dt == 1e-3);
  CHECK(s.bodies[1].moments[0].Ms == 1.6e6);
  CHECK(s.bodies[1].type == engine::BodyType::Dynamic);
}

TEST_CASE("scene_file: every options key is read", "[scene_file]") {
  const engine::SceneDesc s = scenes::parse_scene_json(R"({
    "options": {"method": "kim2018", "dt": 5e-4, "gravity": [0, 0, -1], "ground": false,
                "friction": 0.1, "restitution": 0.2, "erp": 0.3, "cfm": 1e-8,
                "quickstep_iterations": 30, "max_contacts": 8, "space": "sap",
                "auto_disable": true, "linear_damping": 0.5, "angular_damping": 0.25,
                "surface_layer": 1e-5, "max_correcting_velocity": 2, "contact_margin": 0,
                "threads": 1,
                "magnetics": {"dt": 5e-8, "beta": 4, "alpha": 0.25, "gamma_c_max": 1.5,
                              "adaptive_gamma_bound": false, "adaptive_gamma_cap": 2,
                              "tol": 1e-5, "max_iter": 50, "min_pair_angle": 1e-5,
                              "theta_integrator": "euler", "softening": 1e-3}},
    "H0": [1, 2, 3], "default_seconds": 0.5, "escape_radius": 0.25,
    "camera": {"eye": [1, 1, 1], "target": [0, 0, 0.1], "up": [0, 0, 1], "fov_y_deg": 30},
    "bodies": []})", "x.json");
  const engine::SimOptions& o = s.options;
  CHECK(o.magnetics.method == mag::Method::Kim2018);
  CHECK(o.dt == 5e-4);
  CHECK(!o.ground);
  CHECK(o.space == engine::SpaceKind::SweepAndPrune);
  CHECK(o.auto_disable);
  CHECK(o.max_correcting_velocity == 2);
  CHECK(o.contact_margin == 0);
  CHECK(o.threads == 1);
  CHECK(o.magnetics.max_iter == 50);
  CHECK(o.magnetics.theta_integrator == mag::ThetaIntegrator::Euler);
  CHECK(o.magnetics.field.softening == 1e-3);
  CHECK(!o.magnetics.adaptive_gamma_bound);
  CHECK(s.H0 == engine::Vec3(1, 2, 3));
  CHECK(s.default_seconds == 0.5);
  CHECK(s.escape_radius == 0.25);
  CHECK(s.camera.fov_y_deg == 30.0f);
}

TEST_CASE("scene_file: bad files fail with the file and the JSON path", "[scene_file]") {
  CHECK_THAT(error_of("{\"bodies\": [ {\"name\": \"x\" ]}"),
             Contains("scene.json: malformed JSON") && Contains("line 1"));
  CHECK_THAT(error_of(R"({"bodies": [{"type": "static"}, {"shapes": [{"kind": "sphere", "size": 0.01, "colour": 1}]}]})"),
             Contains("scene.json: bodies[1].shapes[0].colour: unknown key"));
  CHECK_THAT(error_of(R"({"bodies": [{"shapes": [{"kind": "sphere", "size": -0.01}]}]})"),
             Contains("scene.json: bodies[0].shapes[0].size: must be a positive radius"));
  CHECK_THAT(error_of(R"({"bodies": [{"shapes": [{"kind": "box", "size": [0.01, 0.01]}]}]})"),
             Contains("bodies[0].shapes[0].size: must be 3 positive numbers"));
  CHECK_THAT(error_of(R"({"bodies": [{"position": "up", "shapes": [{"size": 0.01}]}]})"),
             Contains("bodies[0].position: must be 3 numbers"));
  CHECK_THAT(error_of(R"({"options": {"method": "magic"}, "bodies": []})"),
             Contains("options.method: unknown method 'magic'"));
  CHECK_THAT(error_of(R"({"options": {"magnetics": {"tol": "small"}}, "bodies": []})"),
             Contains("options.magnetics.tol: must be a number"));
  CHECK_THAT(error_of(R"({"options": {"friction": -1}, "bodies": []})"),
             Contains("options.friction: must be >= 0"));
  CHECK_THAT(error_of(R"({"options": {"rolling_friction_bodies": -1e-3}, "bodies": []})"),
             Contains("options.rolling_friction_bodies: must be >= 0"));
  CHECK_THAT(error_of(R"({"bodies": [{"moments": [{"volume": 1e-6, "permanent": true, "Ms": 3}], "type": "static"}]})"),
             Contains("bodies[0].moments[0].Ms: only for induced moments"));
  CHECK_THAT(error_of(R"({"bodies": [{"moments": [{"Ms": 3}], "type": "static"}]})"),
             Contains("bodies[0].moments[0].volume: required"));
  CHECK_THAT(error_of(R"({"bodies": [{"type": "floating"}]})"), Contains("bodies[0].type: unknown body type"));
  CHECK_THAT(error_of(R"({"bodies": [{"orientation": [0, 0, 0, 0], "type": "static"}]})"),
             Contains("bodies[0].orientation"));
  CHECK_THAT(error_of(R"({"bodies": [{"shapes": []}]})"), Contains("bodies[0].shapes: a dynamic body needs"));
  CHECK_THAT(error_of(R"({"name": "x"})"), Contains("scene.json: bodies: required"));
  CHECK_THAT(error_of(R"({"bodies": [], "extra": 1})"), Contains("scene.json: extra: unknown key"));
  CHECK_THAT(error_of(R"({"bodies": [], "escape_radius": -0.5})"),
             Contains("scene.json: escape_radius: must be >= 0 (got -0.5)"));
  CHECK_THAT(error_of(R"({"bodies": [], "escape_radius": "far"})"),
             Contains("scene.json: escape_radius: must be a number"));
  CHECK_THAT(error_of(R"({"bodies": [], "H0": [0, 0, 1e999]})"), Contains("scene.json: malformed JSON"));
  try {
    scenes::load_scene_file("/nonexistent/scene.json");
    FAIL("no error");
  } catch (const std::runtime_error& e) {
    CHECK_THAT(e.what(), Contains("/nonexistent/scene.json: cannot open"));
  }
}

TEST_CASE("scene_file: the field solver options are read and checked", "[scene_file]") {
  const engine::SceneDesc s = scenes::parse_scene_json(
      R"({"options": {"field_solver": "direct", "bh_theta": 0.5, "bh_threshold": 1000}, "bodies": []})", "x.json");
  const mag::FieldOptions& f = s.options.magnetics.field;
  CHECK(f.solver == mag::FieldSolver::Direct);
  CHECK(f.bh_theta == 0.5);
  CHECK(f.auto_threshold == 1000);
  CHECK(scenes::parse_scene_json(kGood, "x.json").options.magnetics.field.solver == mag::FieldSolver::Auto);  // the default
  CHECK(scenes::parse_scene_json(R"({"options": {"field_solver": "barnes-hut"}, "bodies": []})", "x.json")
            .options.magnetics.field.solver == mag::FieldSolver::BarnesHut);
  CHECK_THAT(error_of(R"({"options": {"field_solver": "octree"}, "bodies": []})"),
             Contains("scene.json: options.field_solver: unknown field solver 'octree'"));
  CHECK_THAT(error_of(R"({"options": {"field_solver": 1}, "bodies": []})"),
             Contains("options.field_solver: must be a string"));
  CHECK_THAT(error_of(R"({"options": {"bh_theta": 0}, "bodies": []})"), Contains("options.bh_theta: must be in (0, 1]"));
  CHECK_THAT(error_of(R"({"options": {"bh_theta": 1.5}, "bodies": []})"), Contains("options.bh_theta: must be in (0, 1]"));
  CHECK_THAT(error_of(R"({"options": {"bh_threshold": -1}, "bodies": []})"), Contains("options.bh_threshold: must be in"));
  CHECK_THAT(error_of(R"({"options": {"bh_threshold": 2.5}, "bodies": []})"), Contains("options.bh_threshold: must be an integer"));
}

TEST_CASE("scene_file: a key given twice is an error naming the key and its path", "[scene_file][reliability]") {
  CHECK_THAT(error_of(R"({"bodies": [{"name": "b", "shapes": [{"kind": "sphere", "size": 0.005, "size": 0.01}]}]})"),
             Contains("scene.json: bodies[0].shapes[0].size: duplicate key"));
  CHECK_THAT(error_of(R"({"bodies": [], "bodies": []})"), Contains("scene.json: bodies: duplicate key"));
  CHECK_THAT(error_of(R"({"options": {"dt": 1e-3, "magnetics": {"tol": 1e-4, "tol": 1e-5}}, "bodies": []})"),
             Contains("options.magnetics.tol: duplicate key"));
  // the same key in two sibling objects is fine
  CHECK(error_of(R"({"bodies": [{"name": "a", "type": "static"}, {"name": "b", "type": "static"}]})").empty());
}

TEST_CASE("scene_file: a permanent moment needs \"moment\"", "[scene_file][reliability]") {
  CHECK_THAT(error_of(R"({"bodies": [{"type": "static", "moments": [{"permanent": true, "volume": 1e-6}]}]})"),
             Contains("bodies[0].moments[0].moment: required for a permanent moment"));
}

TEST_CASE("scene_file: a scene name that is not a plain folder name is refused", "[scene_file][reliability]") {
  for (const char* name : {R"("a/b")", R"("..")", R"("../up")", R"("tab\there")", R"("nl\n")", R"("")"})
    CHECK_THAT(error_of(std::string("{\"name\": ") + name + ", \"bodies\": []}"), Contains("scene.json: name: the scene name"));
  // invalid UTF-8 in the text: the JSON parser refuses it
  CHECK_THAT(error_of("{\"name\": \"bad\xff\", \"bodies\": []}"), Contains("scene.json"));
  // ... and in the file name a default name comes from
  CHECK_THAT(error_of_origin("{\"bodies\": []}", "dir/bad\xc3.json"), Contains("the scene name must be valid UTF-8"));
  CHECK(error_of(R"({"name": "Kugeln über dem Magnet", "bodies": []})").empty());
}
