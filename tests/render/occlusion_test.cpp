// tests/render/occlusion_test.cpp — CPU occlusion culling of spheres (render/occlusion.cpp)
// and the neighbour ambient-occlusion factor (render/sphere_ao.cpp).
#include <catch2/catch.hpp>

#include <vector>

#include "render/camera.hpp"
#include "render/occlusion.hpp"
#include "render/sphere_ao.hpp"

using namespace magsim::render;

TEST_CASE("occlusion: hides only spheres entirely behind others", "[render]") {
  Frame f;
  f.camera.eye = Eigen::Vector3f(0.0f, 0.0f, 0.0f);
  f.camera.target = Eigen::Vector3f(1.0f, 0.0f, 0.0f);
  f.camera.fov_y_deg = 60.0f;
  // {x, y, z, r}, listed front to back
  const std::vector<float> s = {
      0.5f, 0.0f,  0.0f, 0.05f,  // 0: in front of the big one
      1.0f, 0.0f,  0.0f, 0.3f,   // 1: big occluder, angular radius asin(0.3) = 17.5°
      2.0f, 0.0f,  0.0f, 0.05f,  // 2: right behind it -> hidden
      2.0f, 0.15f, 0.1f, 0.05f,  // 3: behind it, off centre but inside its disc -> hidden
      2.0f, 0.62f, 0.0f, 0.1f,   // 4: centre behind the rim, edge peeking out -> visible
      2.0f, 0.8f,  0.0f, 0.05f,  // 5: beside it (21.8°) -> visible
      -1.0f, 0.0f, 0.0f, 0.05f,  // 6: behind the camera -> not culled (not reasoned about)
      0.5f, 3.0f,  0.0f, 0.05f,  // 7: far outside the field of view -> culled
  };
  const std::vector<std::uint32_t> order = {0, 1, 2, 3, 4, 5, 6, 7};
  const int w = 400, h = 300;
  const ViewSetup view = view_setup(f, float(w) / float(h));
  SphereOcclusion occ;
  std::vector<std::uint8_t> visible;
  occ.run_perspective(s.data(), 4, order, f.camera.eye, view, f.camera.fov_y_deg, w, h, 4,
                      &visible);
  REQUIRE(visible.size() == 8);
  CHECK(visible[0] == 1);
  CHECK(visible[1] == 1);
  CHECK(visible[2] == 0);
  CHECK(visible[3] == 0);
  CHECK(visible[4] == 1);
  CHECK(visible[5] == 1);
  CHECK(visible[6] == 1);
  CHECK(visible[7] == 0);
  CHECK(occ.hidden() == 3);

  // the same spheres processed back to front: nothing is known yet when the hidden ones
  // come, so they are kept (order only costs culling, never correctness)
  const std::vector<std::uint32_t> reversed = {7, 6, 5, 4, 3, 2, 1, 0};
  occ.run_perspective(s.data(), 4, reversed, f.camera.eye, view, f.camera.fov_y_deg, w, h, 4,
                      &visible);
  CHECK(visible[2] == 1);
  CHECK(visible[3] == 1);
  CHECK(visible[7] == 0);  // off screen is off screen in any order
}

TEST_CASE("sphere ambient occlusion: buried and capped spheres get less sky", "[render]") {
  const float r = 0.01f;
  // records {x, y, z, r, ao}
  auto run = [&](std::vector<float> s) {
    SphereAmbientOcclusion ao;
    ao.run(s.data(), 5, s.size() / 5, 4);
    return s;
  };
  // alone: open sky
  CHECK(run({0, 0, 0, r, 0})[4] == Approx(1.0f));
  // a touching sphere above shades more than one below or beside
  const float above = run({0, 0, 0, r, 0, 0, 0, 2 * r, r, 0})[4];
  const float below = run({0, 0, 0, r, 0, 0, 0, -2 * r, r, 0})[4];
  const float beside = run({0, 0, 0, r, 0, 2 * r, 0, 0, r, 0})[4];
  CHECK(above < beside);
  CHECK(beside < below + 1e-6f);
  CHECK(below < 1.0f);
  // far neighbours do not count
  CHECK(run({0, 0, 0, r, 0, 10 * r, 0, 0, r, 0})[4] == Approx(1.0f));
  // the middle of a simple cubic block of 27 (six contacts) is darker than a top corner
  std::vector<float> block;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) block.insert(block.end(), {2 * r * x, 2 * r * y, 2 * r * z, r, 0});
  const std::vector<float> out = run(block);
  const float centre = out[13 * 5 + 4], top_corner = out[26 * 5 + 4];
  CHECK(centre < top_corner);
  CHECK(centre >= 0.3f);
  CHECK(centre < 0.75f);
  CHECK(top_corner > 0.85f);
  // `wanted` restricts which spheres get a factor (the others are left alone)
  std::vector<float> two = {0, 0, 0, r, -1, 0, 0, 2 * r, r, -1};
  const std::uint8_t wanted[2] = {1, 0};
  SphereAmbientOcclusion ao;
  ao.run(two.data(), 5, 2, 4, wanted);
  CHECK(two[4] < 1.0f);
  CHECK(two[9] == -1.0f);
}
