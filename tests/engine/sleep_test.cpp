// tests/engine/sleep_test.cpp — sleeping islands (SimOptions::sleep, engine/sleep.cpp):
// falling asleep, waking by a touch and by a moving magnet's field, never by the island's own
// field, the energy books across both, and the same hash on a repeat and after a restore.
#include "engine/simulation.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace magsim;
using namespace magsim::test;

namespace {

/// An empty scene on one thread with the default method (anderson), sleeping after 0.1 s still.
SceneDesc sleeping_scene(const std::string& name) {
  SceneDesc s;
  s.name = name;
  s.options.threads = 1;
  s.options.magnetics.method = mag::Method::Anderson;
  s.options.sleep = true;
  s.options.sleep_time = 0.1;
  return s;
}

/// Four balls in a 2×2 layer just above a static magnet standing on the ground, with the
/// sleeping_scene's options; `drop_height` > 0 adds one more ball that far above
/// the layer, falling onto it.
SceneDesc heap_on_magnet(double drop_height) {
  SceneDesc s = sleeping_scene("sleep_heap");
  s.options.sleep_speed = 0.01;
  s.options.rolling_friction = 0.0005;  // a ball knocked onto the ground stops rolling
  s.options.rolling_friction_bodies = 0.0005;
  s.bodies.push_back(cube_magnet(Vec3(0, 0, 0.005), Vec3(0, 0, 0.05)));
  const double z = 0.01 + kR + 0.0005;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      s.bodies.push_back(iron_ball("ball_" + std::to_string(2 * i + j),
                                   Vec3((i - 0.5) * 2.02 * kR, (j - 0.5) * 2.02 * kR, z)));
  if (drop_height > 0) s.bodies.push_back(iron_ball("dropped", Vec3(0, 0, z + drop_height)));
  return s;
}

int asleep(const engine::Simulation& sim) {
  return static_cast<int>(std::count_if(sim.state().sleep_island.begin(), sim.state().sleep_island.end(),
                                        [](int i) { return i >= 0; }));
}

/// The audit's books: E now = E at the start + Σ created − Σ dissipated (J).
double book_gap(const engine::Simulation& sim) {
  const engine::EnergyAudit& a = sim.energy();
  return engine::total_energy(a) - (a.initial_total + a.total.energy_created - a.total.energy_dissipated);
}

}  // namespace

TEST_CASE("sleep: a heap on a magnet falls asleep, a dropped ball wakes it, and it sleeps again",
          "[sleep]") {
  engine::Simulation sim(heap_on_magnet(0.3));  // the drop lands at about 0.25 s
  const int heap = 4, dropped = sim.find_body("dropped");
  REQUIRE(dropped == 5);
  double first_all_asleep = -1.0, woken_at = -1.0;
  int least_asleep_after_wake = heap;
  while (sim.time() < 1.5 - 1e-9) {
    sim.step();
    const int n = asleep(sim) - (sim.state().sleep_island[dropped] >= 0 ? 1 : 0);
    if (first_all_asleep < 0 && n == heap) first_all_asleep = sim.time();
    if (first_all_asleep > 0 && woken_at < 0 && n < heap) woken_at = sim.time();
    if (woken_at > 0) least_asleep_after_wake = std::min(least_asleep_after_wake, n);
    REQUIRE(std::abs(book_gap(sim)) <= 1e-9 * std::max(1e-3, std::abs(engine::total_energy(sim.energy()))));
  }
  INFO("heap asleep at " << first_all_asleep << " s, woken at " << woken_at << " s");
  CHECK(first_all_asleep > 0.0);
  CHECK(first_all_asleep < 0.2);  // before the dropped ball arrives
  CHECK(woken_at > first_all_asleep);
  CHECK(least_asleep_after_wake < heap);
  // the dropped ball lies on the heap, and everything sleeps again
  CHECK(sim.body_position(dropped).z() < 0.01 + 4 * kR + 0.002);
  for (int b = 1; b <= heap + 1; ++b)
    UNSCOPED_INFO("body " << b << " v " << sim.body_velocity(b).norm() << " w " << sim.body_angular_velocity(b).norm() << " still " << sim.state().still_time[b] << " z " << sim.body_position(b).z());
  CHECK(asleep(sim) == heap + 1);
  CHECK(sim.last_profile().asleep == heap + 1);
}

TEST_CASE("sleep: a sleeping ball wakes when a magnet moves toward it from 0.5 m, before it pulls",
          "[sleep]") {
  SceneDesc s = sleeping_scene("sleep_approach");
  s.bodies.push_back(iron_ball("ball", Vec3(0, 0, kR)));
  BodyDesc magnet = cube_magnet(Vec3(-0.5, 0, 0.02), Vec3(1.0, 0, 0));
  magnet.type = BodyType::Kinematic;
  magnet.velocity = Vec3(0.5, 0, 0);  // reaches the ball in about 1 s
  s.bodies.push_back(magnet);
  engine::Simulation sim(s);
  double asleep_at = -1.0, woken_at = -1.0, gap_at_wake = 0.0;
  while (sim.time() < 1.1 - 1e-9) {
    sim.step();
    const bool a = sim.state().sleep_island[0] >= 0;
    if (a && asleep_at < 0) asleep_at = sim.time();
    if (!a && asleep_at > 0 && woken_at < 0) {
      woken_at = sim.time();
      gap_at_wake = (sim.body_position(1) - sim.body_position(0)).norm();
    }
  }
  INFO("asleep at " << asleep_at << " s, woken at " << woken_at << " s, magnet " << gap_at_wake << " m away");
  REQUIRE(asleep_at > 0.0);
  CHECK(asleep_at < 0.3);
  REQUIRE(woken_at > asleep_at);
  // woken while the magnet's pull is still far below the ball's weight (at 5 cm: ~1e-3 of it)
  CHECK(gap_at_wake > 0.05);
  // and, awake, the ball is pulled off its place by the magnet
  CHECK(std::abs(sim.body_position(0).x()) > 0.001);
}

TEST_CASE("sleep: a sleeping island is never woken by its own frozen field, while another body moves",
          "[sleep]") {
  SceneDesc s = heap_on_magnet(0.0);
  s.options.rolling_friction = 0.0;
  // a ball rolling away 1 m off keeps the world awake, so the magnetics run every step
  BodyDesc roller = iron_ball("roller", Vec3(1.0, 0, kR));
  roller.velocity = Vec3(0.2, 0, 0);
  roller.angular_velocity = Vec3(0, 0.2 / kR, 0);
  s.bodies.push_back(roller);
  engine::Simulation sim(s);
  while (sim.time() < 0.6 - 1e-9) sim.step();
  REQUIRE(asleep(sim) == 4);
  const engine::State at_sleep = sim.save_state();
  while (sim.time() < 1.6 - 1e-9) {
    sim.step();
    REQUIRE(asleep(sim) == 4);
    REQUIRE(sim.last_profile().iterations > 0);  // the magnetics did run
  }
  CHECK(sim.body_position(5).x() > 1.15);  // the roller rolled on
  for (int b = 1; b <= 4; ++b) {
    CHECK(sim.state().pos[b] == at_sleep.pos[b]);
    CHECK(sim.state().mag.M[b] == at_sleep.mag.M[b]);
  }
}

TEST_CASE("sleep: with every body asleep a step costs no solve, and the run repeats and restores bit for bit",
          "[sleep]") {
  auto run = [](engine::Simulation* sim, double t) {
    while (sim->time() < t - 1e-9) sim->step();
  };
  engine::Simulation a(heap_on_magnet(0.3));
  run(&a, 0.2);
  REQUIRE(asleep(a) == 4);  // the heap, with the dropped ball in flight
  const engine::State mid = a.save_state();
  run(&a, 1.2);
  const std::uint64_t h = a.state_hash();

  engine::Simulation b(heap_on_magnet(0.3));
  run(&b, 1.2);
  CHECK(b.state_hash() == h);

  engine::Simulation c(heap_on_magnet(0.3));
  c.restore_state(mid);
  run(&c, 1.2);
  CHECK(c.state_hash() == h);

  // all asleep: the clock advances, nothing is solved
  engine::Simulation d(heap_on_magnet(0.0));
  run(&d, 0.6);
  REQUIRE(asleep(d) == 4);
  const std::uint64_t rest = d.state_hash();
  d.step();
  CHECK(d.last_profile().iterations == 0);
  CHECK(d.state_hash() == rest);
  // woken by the user: the next step solves and steps the heap again
  d.wake_all();
  d.step();
  CHECK(d.last_profile().iterations > 0);
}

TEST_CASE("sleep: a body at rest in the air, pulled slowly, does not sleep: only an island touching the world does",
          "[sleep]") {
  SceneDesc s = heap_on_magnet(0.0);
  s.options.gravity = Vec3::Zero();
  s.options.ground = false;
  // a ball 3 cm beside the magnet, starting from rest: pulled weakly, it is slower than
  // sleep_speed for its first 0.1 s
  s.bodies.push_back(iron_ball("slow", Vec3(0.03, 0, 0.005)));
  engine::Simulation sim(s);
  const int slow = sim.find_body("slow");
  bool slept = false;
  while (sim.time() < 0.3 - 1e-9) {
    sim.step();
    slept = slept || sim.state().sleep_island[slow] >= 0;
  }
  CHECK_FALSE(slept);
  INFO("x " << sim.body_position(slow).x() << " m, v " << sim.body_velocity(slow).norm() << " m/s");
  CHECK(sim.body_position(slow).x() < 0.03 - 2e-5);  // it was pulled toward the magnet
}

TEST_CASE("sleep: options are checked", "[sleep]") {
  SceneDesc s = heap_on_magnet(0.0);
  s.options.auto_disable = true;  // ODE's own auto-disable, asked for, puts sleep off
  CHECK_FALSE(engine::Simulation(s).model().options.sleep);
  s.options.auto_disable = false;
  s.options.magnetics.method = mag::Method::Exact;
  CHECK_THROWS_WITH(engine::Simulation(s), Catch::Contains("relaxation method"));
  s.options.magnetics.method = mag::Method::Anderson;
  s.options.sleep_speed = -1;
  CHECK_THROWS_WITH(engine::Simulation(s), Catch::Contains("sleep_speed"));
}
