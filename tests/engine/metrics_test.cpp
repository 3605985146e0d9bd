// tests/engine/metrics_test.cpp — energy, momentum, extent, attachment (attached, held,
// escaped).
#include "engine/simulation.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

using namespace magsim;
using namespace magsim::test;

TEST_CASE("metrics: kinetic energy, momentum, speed and radius of free bodies", "[metrics]") {
  SceneDesc s;
  s.options.gravity = Vec3::Zero();
  s.options.ground = false;
  BodyDesc a = iron_ball("a", Vec3(-0.03, 0, 0));
  a.moments.clear();
  a.velocity = Vec3(1, 2, 0);
  a.angular_velocity = Vec3(0, 0, 3);
  BodyDesc b = a;
  b.name = "b";
  b.position = Vec3(0.03, 0, 0);
  b.velocity = Vec3(0, 0, 0);
  b.angular_velocity = Vec3::Zero();
  s.bodies = {a, b};
  engine::Simulation sim(s);
  const double m = 7870.0 * sphere_volume(kR);
  const double I = 0.4 * m * kR * kR;
  const engine::Metrics x = sim.metrics();
  CHECK(x.dynamic_bodies == 2);
  CHECK(x.kinetic_energy == Approx(0.5 * m * 5.0 + 0.5 * I * 9.0));
  CHECK(x.rotational_energy == Approx(0.5 * I * 9.0));
  CHECK((x.momentum - m * Vec3(1, 2, 0)).norm() < 1e-15);
  CHECK(x.max_speed == Approx(std::sqrt(5.0)));
  CHECK(x.bounding_radius == Approx(0.03));
  CHECK(x.magnet_radius == 0.0);
  CHECK(x.attached == 0);
  sim.run(10);  // free flight: energy and momentum stay
  CHECK(sim.metrics().kinetic_energy == Approx(x.kinetic_energy).epsilon(1e-9));
}

TEST_CASE("metrics: a chain magnet–ball–ball counts two attached balls", "[metrics]") {
  SceneDesc s;
  s.options.threads = 1;
  s.options.gravity = Vec3::Zero();
  s.options.ground = false;
  s.bodies.push_back(cube_magnet(Vec3(0, 0, 0), Vec3(0, 0, 1.0)));
  s.bodies.push_back(iron_ball("near", Vec3(0, 0, -0.0102)));
  s.bodies.push_back(iron_ball("far", Vec3(0, 0, -0.0204)));
  s.bodies.push_back(iron_ball("away", Vec3(0.2, 0, 0)));  // too far to be pulled in 0.2 s
  engine::Simulation sim(s);
  sim.run(200);
  const engine::Metrics x = sim.metrics();
  CHECK(x.attached == 2);
  CHECK(x.held == 2);  // no ground: every attached ball is held
  CHECK(x.magnet_radius == Approx(0.2).margin(1e-3));
  CHECK(x.iterations >= 1);
  CHECK(x.contacts >= 2);
}

namespace {

// magnet (static, body 0) at (0, 0, 0.1) and six balls, bodies 1–6, placed by hand
SceneDesc magnet_and_six_balls() {
  SceneDesc s;
  s.bodies.push_back(cube_magnet(Vec3(0, 0, 0.1), Vec3(0, 0, 1.0)));
  for (int i = 1; i <= 6; ++i) s.bodies.push_back(iron_ball("ball_" + std::to_string(i), Vec3(0.02 * i, 0, 0.2)));
  return s;
}

}  // namespace

TEST_CASE("metrics: held leaves out balls that touch the ground and what hangs on them", "[metrics]") {
  const engine::Model m = engine::compile_model(magnet_and_six_balls());
  engine::State s = engine::initial_state(m);
  // magnet–1–2–3–4 chain where 3 also lies on the ground; 5 lies on the ground alone;
  // 6 touches 1 and the ground
  s.contact_pairs = {{0, 1}, {1, 2}, {2, 3}, {-1, 3}, {3, 4}, {-1, 5}, {1, 6}, {-1, 6}};
  const engine::Metrics x = engine::compute_metrics(m, s, {});
  CHECK(x.attached == 5);  // 1, 2, 3, 4, 6: the floor does not stop the walk
  CHECK(x.held == 2);      // 1, 2: 3 and 6 touch the ground, 4 hangs only on 3

  // the same chain without the ground contacts: all five are held
  s.contact_pairs = {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {1, 6}};
  const engine::Metrics y = engine::compute_metrics(m, s, {});
  CHECK(y.attached == 5);
  CHECK(y.held == 5);

  // a ball touching the magnet and the ground is neither held nor a bridge
  s.contact_pairs = {{0, 1}, {-1, 1}, {1, 2}};
  CHECK(engine::compute_metrics(m, s, {}).held == 0);
  CHECK(engine::compute_metrics(m, s, {}).attached == 2);
  s.contact_pairs.clear();
  CHECK(engine::compute_metrics(m, s, {}).held == 0);
}

TEST_CASE("metrics: escaped counts bodies beyond the escape radius, horizontally under gravity", "[metrics]") {
  SceneDesc d = magnet_and_six_balls();
  d.escape_radius = 0.1;
  const std::vector<Vec3> at = {
      Vec3(0, 0, 0.09),       // 1: next to the magnet
      Vec3(0.05, 0, 0),       // 2: 0.05 sideways (3-D 0.112)
      Vec3(0.12, 0, 0),       // 3: 0.12 sideways: escaped
      Vec3(0, 0.09, 0.5),     // 4: 0.09 sideways, 0.4 above (3-D 0.41)
      Vec3(0.3, 0.3, 0),      // 5: far: escaped
      Vec3(-0.08, -0.08, 0),  // 6: 0.113 sideways: escaped
  };
  SECTION("gravity: horizontal distance") {
    const engine::Model m = engine::compile_model(d);
    engine::State s = engine::initial_state(m);
    for (int i = 1; i <= 6; ++i) s.pos[i] = at[i - 1];
    CHECK(engine::compute_metrics(m, s, {}).escaped == 3);
  }
  SECTION("zero gravity: 3-D distance") {
    d.options.gravity = Vec3::Zero();
    const engine::Model m = engine::compile_model(d);
    engine::State s = engine::initial_state(m);
    for (int i = 1; i <= 6; ++i) s.pos[i] = at[i - 1];
    CHECK(engine::compute_metrics(m, s, {}).escaped == 5);  // all but ball 1
  }
  SECTION("radius 0: not measured") {
    d.escape_radius = 0.0;
    const engine::Model m = engine::compile_model(d);
    engine::State s = engine::initial_state(m);
    for (int i = 1; i <= 6; ++i) s.pos[i] = at[i - 1];
    CHECK(engine::compute_metrics(m, s, {}).escaped == 0);
  }
  SECTION("several magnets: distance to their centroid, not to the nearest") {
    d.bodies[0].position = Vec3(-0.2, 0, 0.1);
    d.bodies.push_back(cube_magnet(Vec3(0.2, 0, 0.1), Vec3(0, 0, 1.0)));
    d.bodies.back().name = "magnet_2";
    const engine::Model m = engine::compile_model(d);
    engine::State s = engine::initial_state(m);
    for (int i = 1; i <= 6; ++i) s.pos[i] = Vec3(0, 0.01 * i, 0);  // 0.2 from either magnet
    s.pos[6] = Vec3(0.19, 0, 0.1);                                   // next to magnet_2
    CHECK(engine::compute_metrics(m, s, {}).escaped == 1);          // ball 6 only
  }
}
