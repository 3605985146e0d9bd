// tests/render/renderer_test.cpp — the offscreen renderer, PNG I/O and output helpers.
//
// Pixel checks project world points with the renderer's own camera matrices (which a
// separate check ties to the frame's camera) and compare colours by dominant channel
// and luminance, so they survive shading tweaks but fail if a shape, its shadow or the
// image orientation goes missing.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "render/camera.hpp"
#include "render/frame_writer.hpp"
#include "render/png_io.hpp"
#include "render/renderer.hpp"

namespace {

namespace fs = std::filesystem;
using namespace magsim::render;

struct Rgb {
  int r = 0, g = 0, b = 0;
  double luminance() const { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }
};

Rgb pixel_at(const Renderer& renderer, float px, float py) {
  const int x = int(std::floor(px)), y = int(std::floor(py));
  REQUIRE(x >= 0);
  REQUIRE(y >= 0);
  REQUIRE(x < renderer.width());
  REQUIRE(y < renderer.height());
  const std::uint8_t* p =
      renderer.pixels().data() + (std::size_t(y) * std::size_t(renderer.width()) + x) * 3;
  return {p[0], p[1], p[2]};
}

// colour of the pixel a world point projects to
Rgb pixel_of(const Renderer& renderer, const Eigen::Vector3f& world) {
  float px = 0, py = 0;
  REQUIRE(project_to_pixel(renderer.last_view(), renderer.width(), renderer.height(), world, &px,
                           &py));
  return pixel_at(renderer, px, py);
}

Rgb srgb(const Color& c) {
  return {Renderer::to_srgb8(c.r), Renderer::to_srgb8(c.g), Renderer::to_srgb8(c.b)};
}

bool near_colour(const Rgb& a, const Rgb& b, int tol) {
  return std::abs(a.r - b.r) <= tol && std::abs(a.g - b.g) <= tol && std::abs(a.b - b.b) <= tol;
}

// a scratch folder, removed at the end of the test
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() /
           ("magsim_render_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter()++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  static int& counter() {
    static int n = 0;
    return n;
  }
};

// One red ball of radius 0.1 m at height 0.3 m over the ground, lit from straight above.
Frame red_ball_frame() {
  Frame f;
  Shape s;
  s.type = ShapeType::Sphere;
  s.position = Eigen::Vector3f(0.0f, 0.0f, 0.3f);
  s.size = Eigen::Vector3f(0.1f, 0.1f, 0.1f);
  s.color = Color{0.8f, 0.05f, 0.04f};
  f.shapes.push_back(s);
  f.camera.eye = Eigen::Vector3f(0.9f, -0.9f, 0.7f);
  f.camera.target = Eigen::Vector3f(0.0f, 0.0f, 0.15f);
  f.camera.fov_y_deg = 40.0f;
  f.light_dir = Eigen::Vector3f(0.0f, 0.0f, 1.0f);
  return f;
}

}  // namespace

TEST_CASE("camera: the target projects to the image centre and up is up", "[render]") {
  Frame f = red_ball_frame();
  const ViewSetup v = view_setup(f, 320.0f / 240.0f);
  float px = 0, py = 0;
  REQUIRE(project_to_pixel(v, 320, 240, f.camera.target, &px, &py));
  CHECK(px == Approx(160.0f).margin(0.01));
  CHECK(py == Approx(120.0f).margin(0.01));
  // a point above the target is higher in the image (smaller row index)
  REQUIRE(project_to_pixel(v, 320, 240, f.camera.target + Eigen::Vector3f(0, 0, 0.1f), &px, &py));
  CHECK(py < 110.0f);
  // near and far were chosen from the scene: both positive, the ball between them
  const float d = (f.camera.eye - f.shapes[0].position).norm();
  CHECK(v.z_near > 0.0f);
  CHECK(v.z_near < d - 0.1f);
  CHECK(v.z_far > d + 0.1f);
  // behind the camera: not projected
  CHECK_FALSE(project_to_pixel(v, 320, 240, f.camera.eye + (f.camera.eye - f.camera.target),
                               &px, &py));
}

TEST_CASE("renderer: a red ball over the ground casts a shadow under a clear sky", "[render]") {
  Renderer renderer(320, 240);
  const Frame f = red_ball_frame();
  renderer.draw(f);
  REQUIRE(renderer.pixels().size() == 320u * 240u * 3u);

  // top corners look above the horizon: the background colour exactly (sRGB-encoded)
  const Rgb sky = srgb(f.background);
  CHECK(near_colour(pixel_at(renderer, 0.5f, 0.5f), sky, 1));
  CHECK(near_colour(pixel_at(renderer, 319.5f, 0.5f), sky, 1));

  // the ball's projected centre is red
  const Rgb ball = pixel_of(renderer, f.shapes[0].position);
  INFO("ball pixel " << ball.r << " " << ball.g << " " << ball.b);
  CHECK(ball.r > 80);
  CHECK(ball.r > 2 * ball.g);
  CHECK(ball.r > 2 * ball.b);

  // the ground right under the ball (the light is straight above) is in its shadow; points
  // are cell centres of the 2 cm grid so that no grid line falls on them
  const Rgb shadow = pixel_of(renderer, Eigen::Vector3f(0.01f, 0.01f, 0.0f));
  const Rgb lit_far = pixel_of(renderer, Eigen::Vector3f(0.31f, -0.29f, 0.0f));
  const Rgb lit_near = pixel_of(renderer, Eigen::Vector3f(0.17f, 0.01f, 0.0f));
  INFO("shadow " << shadow.luminance() << ", lit far " << lit_far.luminance() << ", lit near "
                 << lit_near.luminance());
  CHECK(shadow.luminance() < 0.7 * lit_far.luminance());
  CHECK(shadow.luminance() < 0.7 * lit_near.luminance());
  // lit ground is light and grey, not black or tinted
  CHECK(lit_far.luminance() > 150.0);
  CHECK(std::abs(lit_far.r - lit_far.b) < 30);

  // with shadows off the same ground pixel is lit
  Frame no_shadow = f;
  no_shadow.shadows = false;
  renderer.draw(no_shadow);
  const Rgb unshadowed = pixel_of(renderer, Eigen::Vector3f(0.01f, 0.01f, 0.0f));
  CHECK(unshadowed.luminance() > 0.9 * lit_far.luminance());
}

TEST_CASE("renderer: the ball moves in the image when it moves in the world", "[render]") {
  Renderer renderer(320, 240);
  Frame f = red_ball_frame();
  f.shapes[0].position = Eigen::Vector3f(0.3f, 0.3f, 0.3f);
  renderer.draw(f);
  const Rgb moved = pixel_of(renderer, f.shapes[0].position);
  const Rgb old_place = pixel_of(renderer, Eigen::Vector3f(0.0f, 0.0f, 0.3f));
  CHECK(moved.r > 2 * moved.g);
  CHECK_FALSE(old_place.r > 2 * old_place.g);  // nothing red left there
}

TEST_CASE("renderer: boxes capsules cylinders and arrows all draw", "[render]") {
  Frame f;
  f.ground = false;
  f.camera.eye = Eigen::Vector3f(0.0f, -1.2f, 0.6f);
  f.camera.target = Eigen::Vector3f(0.0f, 0.0f, 0.1f);
  f.light_dir = Eigen::Vector3f(0.2f, -0.5f, 1.0f);

  Shape box;
  box.type = ShapeType::Box;
  box.position = Eigen::Vector3f(-0.35f, 0.0f, 0.1f);
  box.orientation = Eigen::AngleAxisf(0.4f, Eigen::Vector3f::UnitZ());
  box.size = Eigen::Vector3f(0.08f, 0.05f, 0.06f);
  box.color = Color{0.05f, 0.1f, 0.8f};  // blue
  Shape capsule;
  capsule.type = ShapeType::Capsule;
  capsule.position = Eigen::Vector3f(0.0f, 0.0f, 0.1f);
  capsule.orientation = Eigen::AngleAxisf(1.5708f, Eigen::Vector3f::UnitY());  // along x
  capsule.size = Eigen::Vector3f(0.04f, 0.08f, 0.0f);
  capsule.color = Color{0.05f, 0.7f, 0.05f};  // green
  Shape cylinder;
  cylinder.type = ShapeType::Cylinder;
  cylinder.position = Eigen::Vector3f(0.35f, 0.0f, 0.1f);
  cylinder.size = Eigen::Vector3f(0.05f, 0.07f, 0.0f);
  cylinder.color = Color{0.8f, 0.05f, 0.05f};  // red
  f.shapes = {box, capsule, cylinder};
  Arrow arrow;
  arrow.origin = Eigen::Vector3f(-0.3f, 0.0f, 0.35f);
  arrow.vec = Eigen::Vector3f(0.6f, 0.0f, 0.0f);
  arrow.color = Color{0.9f, 0.8f, 0.05f};  // yellow
  f.arrows = {arrow};

  Renderer renderer(320, 240);
  renderer.draw(f);
  const Rgb bg = srgb(f.background);

  auto dominant = [](const Rgb& c, int channel) {
    const int v[3] = {c.r, c.g, c.b};
    return v[channel] > 60 && v[channel] > 2 * v[(channel + 1) % 3] &&
           v[channel] > 2 * v[(channel + 2) % 3];
  };
  const Rgb b = pixel_of(renderer, box.position);
  INFO("box " << b.r << " " << b.g << " " << b.b);
  CHECK(dominant(b, 2));
  const Rgb c = pixel_of(renderer, capsule.position);
  INFO("capsule " << c.r << " " << c.g << " " << c.b);
  CHECK(dominant(c, 1));
  // the capsule's round caps (impostors) reach beyond the cylinder body
  const Rgb cap = pixel_of(renderer, capsule.position + Eigen::Vector3f(0.105f, 0.0f, 0.0f));
  INFO("cap " << cap.r << " " << cap.g << " " << cap.b);
  CHECK(dominant(cap, 1));
  const Rgb y = pixel_of(renderer, cylinder.position);
  INFO("cylinder " << y.r << " " << y.g << " " << y.b);
  CHECK(dominant(y, 0));
  // arrow shaft and head: yellow (red and green high, blue low)
  for (float t : {0.3f, 0.92f}) {
    const Rgb a = pixel_of(renderer, arrow.origin + t * arrow.vec);
    INFO("arrow at " << t << ": " << a.r << " " << a.g << " " << a.b);
    CHECK_FALSE(near_colour(a, bg, 10));
    CHECK(a.r > 2 * a.b);
    CHECK(a.g > 2 * a.b);
  }
  // empty space between the shapes is background (no ground)
  CHECK(near_colour(pixel_of(renderer, Eigen::Vector3f(-0.17f, 0.0f, 0.1f)), bg, 1));
}

TEST_CASE("renderer: an empty frame is sky above ground and bad sizes throw", "[render]") {
  Frame f;  // no shapes; a low camera, so the top rows look above the horizon
  f.camera.eye = Eigen::Vector3f(0.5f, -0.5f, 0.15f);
  f.camera.target = Eigen::Vector3f(0.0f, 0.0f, 0.05f);
  Renderer renderer(64, 48);
  renderer.draw(f);
  const Rgb sky = srgb(f.background);
  CHECK(near_colour(pixel_at(renderer, 0.5f, 0.5f), sky, 1));
  // the ground at the target: light grey, and not the background
  const Rgb ground = pixel_of(renderer, f.camera.target);
  CHECK_FALSE(near_colour(ground, sky, 4));
  CHECK(ground.luminance() > 120.0);
  CHECK(std::abs(ground.r - ground.b) < 30);

  f.ground = false;
  renderer.draw(f);
  for (std::size_t i = 0; i < renderer.pixels().size(); i += 3)
    REQUIRE(near_colour({renderer.pixels()[i], renderer.pixels()[i + 1], renderer.pixels()[i + 2]},
                        sky, 0));

  CHECK_THROWS_AS(Renderer(0, 10), std::runtime_error);
}

TEST_CASE("renderer: 2x2 supersampling gives the same picture", "[render]") {
  const Frame f = red_ball_frame();
  Renderer plain(160, 120, 1), supersampled(160, 120, 4);
  CHECK(plain.samples() == 1);
  CHECK(supersampled.samples() == 4);
  plain.draw(f);
  supersampled.draw(f);
  REQUIRE(plain.pixels().size() == supersampled.pixels().size());
  double diff = 0.0;
  for (std::size_t i = 0; i < plain.pixels().size(); ++i)
    diff += std::abs(int(plain.pixels()[i]) - int(supersampled.pixels()[i]));
  diff /= double(plain.pixels().size());
  CHECK(diff < 3.0);  // mean absolute difference per channel (0–255)
  const Rgb ball = pixel_of(supersampled, f.shapes[0].position);
  CHECK(ball.r > 2 * ball.g);
}

TEST_CASE("png: round trip keeps size and every pixel", "[render]") {
  TempDir dir;
  const int w = 37, h = 23;  // odd sizes catch stride mistakes
  std::vector<std::uint8_t> rgb(std::size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = &rgb[(std::size_t(y) * w + x) * 3];
      p[0] = std::uint8_t(x * 7);
      p[1] = std::uint8_t(y * 11);
      p[2] = std::uint8_t((x * y) ^ 0x5a);
    }
  const std::string path = (dir.path / "pattern.png").string();
  std::string err;
  REQUIRE(write_png(path, w, h, rgb.data(), &err));
  int rw = 0, rh = 0;
  std::vector<std::uint8_t> back;
  REQUIRE(read_png(path, &rw, &rh, &back, &err));
  CHECK(rw == w);
  CHECK(rh == h);
  REQUIRE(back.size() == rgb.size());
  CHECK(back == rgb);

  // errors come back as messages, not crashes
  CHECK_FALSE(read_png((dir.path / "missing.png").string(), &rw, &rh, &back, &err));
  CHECK_FALSE(err.empty());
  {
    std::ofstream(dir.path / "junk.png") << "not a png";
  }
  err.clear();
  CHECK_FALSE(read_png((dir.path / "junk.png").string(), &rw, &rh, &back, &err));
  CHECK_FALSE(err.empty());
  err.clear();
  CHECK_FALSE(write_png((dir.path / "no" / "such" / "dir.png").string(), w, h, rgb.data(), &err));
  CHECK_FALSE(err.empty());
}

TEST_CASE("output: check_output_dir creates folders and refuses files", "[render]") {
  TempDir dir;
  std::string err;
  const fs::path nested = dir.path / "a" / "b" / "frames";
  CHECK(check_output_dir(nested.string(), &err));
  CHECK(fs::is_directory(nested));
  CHECK(fs::is_empty(nested));  // the probe file is gone
  CHECK(check_output_dir(nested.string(), &err));  // existing folder: fine

  const fs::path file = dir.path / "a_file";
  {
    std::ofstream(file) << "x";
  }
  err.clear();
  CHECK_FALSE(check_output_dir(file.string(), &err));
  CHECK(err.find("not a directory") != std::string::npos);
  // a folder below a file cannot be created either
  err.clear();
  CHECK_FALSE(check_output_dir((file / "sub").string(), &err));
  CHECK_FALSE(err.empty());

  CHECK(frame_path("out/x", 42) == "out/x/frame_000042.png");
  CHECK(frame_path("out/x/", 0) == "out/x/frame_000000.png");
}

TEST_CASE("output: FrameWriter writes every frame and reports errors", "[render]") {
  TempDir dir;
  const int w = 8, h = 4;
  {
    FrameWriter writer(2);
    for (int i = 0; i < 5; ++i)
      writer.push(frame_path(dir.path.string(), i), w, h,
                  std::vector<std::uint8_t>(std::size_t(w) * h * 3, std::uint8_t(40 * i)));
    writer.finish();
    CHECK(writer.written() == 5);
  }
  for (int i = 0; i < 5; ++i) {
    int rw = 0, rh = 0;
    std::vector<std::uint8_t> rgb;
    std::string err;
    REQUIRE(read_png(frame_path(dir.path.string(), i), &rw, &rh, &rgb, &err));
    CHECK(rw == w);
    CHECK(rgb[0] == std::uint8_t(40 * i));
  }

  FrameWriter failing(2);
  failing.push((dir.path / "missing_dir" / "f.png").string(), w, h,
               std::vector<std::uint8_t>(std::size_t(w) * h * 3, 0));
  CHECK_THROWS_AS(failing.finish(), std::runtime_error);
}

TEST_CASE("renderer: the floor's grid and fade do not change when a body flies far away", "[render]") {
  // the same camera, once with a second sphere 20 m off: the scene's extent grows 100×, the
  // floor in front of the camera must look the same (it used to take its grid cell from the
  // extent: a ball thrown off made the floor jump from 5 cm to 5 m cells mid-video)
  Renderer a(320, 240), b(320, 240);
  Frame f = red_ball_frame();
  a.draw(f);
  Shape far = f.shapes[0];
  far.position = Eigen::Vector3f(20.0f, 20.0f, 0.1f);
  f.shapes.push_back(far);
  b.draw(f);
  // the bottom 60 rows: ground between the camera and the ball, away from its shadow
  int differ = 0, lines = 0;
  for (int y = 180; y < 240; ++y)
    for (int x = 0; x < 320; ++x) {
      const Rgb pa = pixel_at(a, x + 0.5f, y + 0.5f), pb = pixel_at(b, x + 0.5f, y + 0.5f);
      differ += !near_colour(pa, pb, 3);
      lines += pa.luminance() < pixel_at(a, 0.5f, 239.5f).luminance() - 8.0;
    }
  INFO(differ << " of 19200 pixels differ; " << lines << " darker (grid lines, checker)");
  CHECK(differ == 0);
  CHECK(lines > 100);  // the grid is drawn there: the comparison sees it
}
