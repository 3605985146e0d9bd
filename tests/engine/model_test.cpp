// tests/engine/model_test.cpp — SceneDesc → Model: validation messages, mass properties.
#include "engine/model.hpp"
#include "engine/simulation.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace magsim;
using namespace magsim::test;
using Catch::Matchers::Contains;

namespace {

SceneDesc two_balls() {
  SceneDesc s;
  s.bodies.push_back(iron_ball("ball_0", Vec3(0, 0, 0.01)));
  s.bodies.push_back(iron_ball("ball_1", Vec3(0.02, 0, 0.01)));
  s.bodies.push_back(iron_ball("ball_2", Vec3(0.04, 0, 0.01)));
  return s;
}

std::string compile_error(const SceneDesc& s) {
  try {
    engine::compile_model(s);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("model: a negative radius is rejected, naming the body and the field", "[model]") {
  SceneDesc s = two_balls();
  s.bodies[2].shapes[0].size = Vec3(-0.01, 0, 0);
  const std::string e = compile_error(s);
  CHECK_THAT(e, Contains("body 2 'ball_2'"));
  CHECK_THAT(e, Contains("shapes[0].size"));
  CHECK_THAT(e, Contains("radius"));
}

TEST_CASE("model: a non-finite position is rejected, naming the body", "[model]") {
  SceneDesc s = two_balls();
  s.bodies[1].position.y() = std::numeric_limits<double>::quiet_NaN();
  const std::string e = compile_error(s);
  CHECK_THAT(e, Contains("body 1 'ball_1'"));
  CHECK_THAT(e, Contains("position is not finite"));
}

TEST_CASE("model: other invalid inputs are rejected with the field named", "[model]") {
  SceneDesc s = two_balls();
  SECTION("empty dynamic body") {
    s.bodies[0].shapes.clear();
    CHECK_THAT(compile_error(s), Contains("body 0 'ball_0'") && Contains("shapes"));
  }
  SECTION("non-positive moment volume") {
    s.bodies[1].moments[0].volume = 0;
    CHECK_THAT(compile_error(s), Contains("body 1 'ball_1'") && Contains("moments[0].volume"));
  }
  SECTION("non-finite permanent moment") {
    s.bodies.push_back(cube_magnet(Vec3(0, 0, 0.05), Vec3(0, 0, std::nan(""))));
    CHECK_THAT(compile_error(s), Contains("body 3 'magnet'") && Contains("moments[0].moment"));
  }
  SECTION("negative mass") {
    s.bodies[0].mass = -1;
    CHECK_THAT(compile_error(s), Contains("body 0 'ball_0'") && Contains("mass"));
  }
  SECTION("negative or non-finite escape radius") {
    s.escape_radius = -0.1;
    CHECK_THAT(compile_error(s), Contains("escape_radius: must be >= 0 and finite (got -0.1)"));
    s.escape_radius = std::numeric_limits<double>::infinity();
    CHECK_THAT(compile_error(s), Contains("escape_radius"));
    s.escape_radius = 0.2;
    CHECK(compile_error(s).empty());
  }
  SECTION("dt outside (0, 0.1]") {
    s.options.dt = 0.5;
    CHECK_THAT(compile_error(s), Contains("options.dt"));
    s.options.dt = 0;
    CHECK_THAT(compile_error(s), Contains("options.dt"));
  }
  SECTION("torque balance without reaction-symmetric forces") {
    s.options.balance_magnetic_torque = true;
    CHECK_THAT(compile_error(s), Contains("options.balance_magnetic_torque: needs reaction_symmetric_forces"));
    s.options.reaction_symmetric_forces = true;
    CHECK(compile_error(s).empty());
  }
  SECTION("magnetics options") {
    s.options.magnetics.dt = 1e-3;
    CHECK_THAT(compile_error(s), Contains("options.magnetics") && Contains("dt"));
  }
  SECTION("unnamed bodies get a default name in messages") {
    s.bodies[1].name.clear();
    s.bodies[1].density = -3;
    CHECK_THAT(compile_error(s), Contains("body 1 'body_1'") && Contains("density"));
  }
}

TEST_CASE("model: moments are laid out by body, group id = body index", "[model]") {
  SceneDesc s = two_balls();
  s.bodies.push_back(cube_magnet(Vec3(0, 0, 0.05), Vec3(0, 0, 1)));
  engine::Simulation sim(s);
  const auto& set = sim.moments();
  REQUIRE(set.size() == 4);
  for (int j = 0; j < 4; ++j) CHECK(set.group[j] == j);
  CHECK(set.kind[3] == mag::MomentKind::Permanent);
  CHECK((set.position[1] - Vec3(0.02, 0, 0.01)).norm() < 1e-15);
  CHECK(sim.model().induced_count == 3);
}

// Three boxes, one rotated 90° about z: mass, COM and inertia against the analytic sum
// (box of edge lengths a, b, c: I_xx = m (b² + c²)/12; parallel axes: + m (|d|² 𝟙 − d dᵀ)).
TEST_CASE("model: a composite body of three boxes gets its mass and inertia right", "[model]") {
  const double rho = 7870.0;
  BodyDesc b;
  b.name = "letter";
  b.density = rho;
  b.position = Vec3(0.1, -0.2, 0.3);
  const Quat rz90(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()));
  b.shapes.push_back({ShapeKind::Box, Vec3(0, 0, 0), Quat::Identity(), Vec3(0.02, 0.005, 0.005)});
  // stored as half extents (0.015, 0.005, 0.005) turned by 90° about z: (0.005, 0.015, 0.005)
  b.shapes.push_back({ShapeKind::Box, Vec3(0.03, 0.01, 0), rz90, Vec3(0.015, 0.005, 0.005)});
  b.shapes.push_back({ShapeKind::Box, Vec3(-0.02, 0, 0.015), Quat::Identity(), Vec3(0.005, 0.005, 0.01)});
  SceneDesc s;
  s.bodies.push_back(b);

  // expected, with the rotated box written axis-aligned
  const Vec3 edges[3] = {Vec3(0.04, 0.01, 0.01), Vec3(0.01, 0.03, 0.01), Vec3(0.01, 0.01, 0.02)};
  const Vec3 offs[3] = {Vec3(0, 0, 0), Vec3(0.03, 0.01, 0), Vec3(-0.02, 0, 0.015)};
  double M = 0;
  Vec3 c = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const double mk = rho * edges[k].prod();
    M += mk;
    c += mk * offs[k];
  }
  c /= M;
  engine::Mat3 I = engine::Mat3::Zero();
  for (int k = 0; k < 3; ++k) {
    const double mk = rho * edges[k].prod();
    const Vec3 e2 = edges[k].cwiseProduct(edges[k]);
    I.diagonal() += mk / 12.0 * Vec3(e2.y() + e2.z(), e2.x() + e2.z(), e2.x() + e2.y());
    const Vec3 d = offs[k] - c;
    I += mk * (d.squaredNorm() * engine::Mat3::Identity() - d * d.transpose());
  }

  const engine::Model m = engine::compile_model(s);
  CHECK(m.body_mass[0] == Approx(M).epsilon(1e-12));
  CHECK((m.body_com[0] - c).norm() < 1e-15);
  CHECK((m.body_inertia[0] - I).norm() < 1e-12 * I.norm());
  // body frame = COM frame: the body sits at x + R c, shapes are offset by −c
  CHECK((m.body_pos0[0] - (b.position + c)).norm() < 1e-15);
  CHECK((m.shape_offset[1] - (offs[1] - c)).norm() < 1e-15);

  // the Simulation reports the description's origin and draws the shapes where they were put
  engine::Simulation sim(s);
  CHECK((sim.body_origin(0) - b.position).norm() < 1e-15);
  const render::Frame f = sim.frame();
  REQUIRE(f.shapes.size() == 3);
  for (int k = 0; k < 3; ++k)
    CHECK((f.shapes[k].position.cast<double>() - (b.position + offs[k])).norm() < 1e-7);

  // a stated mass rescales the inertia
  s.bodies[0].mass = 2.0;
  const engine::Model m2 = engine::compile_model(s);
  CHECK(m2.body_mass[0] == 2.0);
  CHECK((m2.body_inertia[0] - I * (2.0 / M)).norm() < 1e-12 * I.norm() * 2.0 / M);
}

TEST_CASE("model: shape volumes and inertias of the primitives", "[model]") {
  engine::Mat3 I;
  // capsule r = 1, half length 1: cylinder 2π + sphere 4π/3
  const double V = engine::shape_volume_inertia(ShapeKind::Capsule, Vec3(1, 1, 0), &I);
  CHECK(V == Approx(2 * kPi + 4 * kPi / 3));
  // I_zz = Vc r²/2 + 2/5 Vs r²
  CHECK(I(2, 2) == Approx(2 * kPi / 2 + 0.4 * 4 * kPi / 3));
  // I_xx = Vc (r²/4 + h²/3) + Vs (2/5 r² + h² + 3/4 h r)
  CHECK(I(0, 0) == Approx(2 * kPi * (0.25 + 1.0 / 3) + 4 * kPi / 3 * (0.4 + 1 + 0.75)));
  const double Vs = engine::shape_volume_inertia(ShapeKind::Sphere, Vec3(2, 0, 0), &I);
  CHECK(Vs == Approx(4 * kPi / 3 * 8));
  CHECK(I(1, 1) == Approx(0.4 * Vs * 4));
}
