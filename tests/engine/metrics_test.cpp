// tests/engine/metrics_test.cpp — energy, momentum, extent and attachment.
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
  CHECK(x.magnet_radius == Approx(0.2).margin(1e-3));
  CHECK(x.iterations >= 1);
  CHECK(x.contacts >= 2);
}
