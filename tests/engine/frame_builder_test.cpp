// tests/engine/frame_builder_test.cpp — the plain Frame handed to the renderer.
#include "engine/simulation.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

using namespace magsim;
using namespace magsim::test;

TEST_CASE("frame: visible shapes with colours and poses, camera, arrows on request", "[frame]") {
  SceneDesc s = pile_under_magnet(2);
  s.camera.eye = Eigen::Vector3f(1, 2, 3);
  BodyDesc hidden = cube_magnet(Vec3(0.1, 0, 0.1), Vec3(0, 0, 1));
  hidden.name = "hidden";
  hidden.visible = false;
  s.bodies.push_back(hidden);
  engine::Simulation sim(s);
  sim.run(3);

  render::Frame f = sim.frame();
  REQUIRE(f.shapes.size() == 9);  // magnet + 8 balls; the hidden one is not drawn
  CHECK(f.arrows.empty());
  CHECK(f.camera.eye.isApprox(Eigen::Vector3f(1, 2, 3)));
  CHECK(f.ground);
  CHECK(f.shapes[0].type == render::ShapeType::Box);
  CHECK(f.shapes[0].color.r == Approx(0.8f));
  CHECK(f.shapes[1].type == render::ShapeType::Sphere);
  CHECK((f.shapes[1].position.cast<double>() - sim.body_position(1)).norm() < 1e-6);
  CHECK(f.shapes[1].size.x() == Approx(kR));

  engine::FrameOptions opt;
  opt.magnetization_arrows = true;
  opt.arrow_scale = 0.5;
  f = sim.frame(opt);
  REQUIRE(f.arrows.size() == 16);  // M1 and M2 of 8 induced moments
  CHECK(f.arrows[0].color.r > 0.5f);  // M1 red
  CHECK(f.arrows[1].color.b > 0.5f);  // M2 blue
  CHECK(f.arrows[0].vec.norm() == Approx(0.5 * kR).epsilon(1e-5));
  CHECK((f.arrows[0].origin.cast<double>() - sim.moments().position[1]).norm() < 1e-6);
}
