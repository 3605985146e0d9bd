// tests/engine/safety_test.cpp — non-finite values raise SimulationError and roll back.
#include "engine/simulation.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <limits>

using namespace magsim;
using namespace magsim::test;
using Catch::Matchers::Contains;

// When ODE fails mid-step it keeps one job record (80 bytes) that only dCloseODE frees,
// and dCloseODE is skipped after such a failure (see OdeBridge::broken()). Tell
// LeakSanitizer (sanitizer builds) that this one is expected.
extern "C" const char* __lsan_default_suppressions() { return "leak:PreallocateJobInfos\n"; }

namespace {

// three iron balls apart from each other under a magnet, one resting on the ground
SceneDesc three_balls() {
  SceneDesc s;
  s.options.threads = 1;
  s.bodies.push_back(cube_magnet(Vec3(0, 0, 0.1), Vec3(0, 0, 1)));
  s.bodies.push_back(iron_ball("ball_0", Vec3(-0.05, 0, kR)));
  s.bodies.push_back(iron_ball("ball_1", Vec3(0.0, 0.05, 0.03)));
  s.bodies.push_back(iron_ball("ball_2", Vec3(0.05, 0, 0.05)));
  return s;
}

}  // namespace

// Injects a NaN velocity into `name` before step 11's rigid step: the step must fail with
// the body and quantity named, leave the last good state, and step on exactly as a fresh
// simulation restored to that state.
void check_nan_velocity(const std::string& name, int index) {
  const SceneDesc scene = three_balls();
  engine::Simulation sim(scene);
  sim.run(10);
  const std::uint64_t good = sim.state_hash();
  const engine::State before = sim.save_state();
  REQUIRE(sim.find_body(name) == index);
  sim.inject_velocity_for_testing(index, Vec3(0, std::numeric_limits<double>::quiet_NaN(), 0));
  try {
    sim.step();
    FAIL("no SimulationError");
  } catch (const engine::SimulationError& e) {
    CHECK_THAT(e.what(), Contains("step 11: body " + std::to_string(index) + " '" + name +
                                  "': velocity is not finite (nan)"));
    CHECK(e.step() == 11);
    CHECK(e.body() == index);
    CHECK(e.quantity() == "velocity");
  }
  CHECK(sim.steps() == 10);
  CHECK(sim.state_hash() == good);
  engine::Simulation twin(scene);
  twin.restore_state(before);
  sim.run(20);
  twin.run(20);
  CHECK(sim.state_hash() == twin.state_hash());
}

TEST_CASE("safety: a NaN velocity names step, body and quantity, and rolls back", "[safety]") {
  SECTION("a body in free flight: caught after the rigid step") { check_nan_velocity("ball_2", 3); }
  SECTION("a body on the ground: ODE fails inside the step, the world is rebuilt") {
    check_nan_velocity("ball_0", 1);
  }
}

TEST_CASE("safety: coincident moments make the magnetics non-finite: caught, rolled back", "[safety]") {
  SceneDesc s;
  s.options.threads = 1;
  s.options.gravity = Vec3::Zero();
  s.options.ground = false;
  // an invisible static moment (no shapes) exactly at the centre of an iron ball
  BodyDesc src;
  src.name = "source";
  src.type = BodyType::Static;
  src.position = Vec3(0, 0, 0.05);
  MomentDesc md;
  md.permanent = true;
  md.volume = 1e-6;
  md.moment = Vec3(0, 0, 1);
  src.moments.push_back(md);
  s.bodies.push_back(src);
  s.bodies.push_back(iron_ball("victim", Vec3(0, 0, 0.05)));
  {
    // with bounded pairs the pair is evaluated at the ball's radius: finite
    SceneDesc b = s;
    b.options.magnetics.field.bounded_pairs = true;
    engine::Simulation bounded(b);
    CHECK_NOTHROW(bounded.step());
  }
  // point dipoles: r = 0 is singular
  s.options.magnetics.field.bounded_pairs = false;
  engine::Simulation sim(s);
  const std::uint64_t h0 = sim.state_hash();
  try {
    sim.step();
    FAIL("no SimulationError");
  } catch (const engine::SimulationError& e) {
    // which value goes first depends on the field kernel (r = 0: H = ±inf or NaN)
    CHECK_THAT(e.what(), Contains("step 1: body "));
    CHECK_THAT(e.what(), Contains("is not finite"));
    CHECK((e.quantity() == "magnetization" || e.quantity() == "magnetic force" ||
           e.quantity() == "magnetic torque"));
    CHECK((e.body() == 0 || e.body() == 1));
  }
  CHECK(sim.steps() == 0);
  CHECK(sim.state_hash() == h0);
  CHECK(sim.state().mag.M[1].allFinite());
}
