// tools/bench/render_demo.cpp — magsim-render-demo: draws a pile of iron balls next to a bar
// magnet, a capsule and a few field arrows, writes one PNG and prints the milliseconds per
// frame (median of 5 draws). A development tool for looking at and timing the renderer.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include "render/frame_writer.hpp"
#include "render/png_io.hpp"
#include "render/renderer.hpp"

namespace {

using magsim::render::Arrow;
using magsim::render::Color;
using magsim::render::Frame;
using magsim::render::Shape;
using magsim::render::ShapeType;

struct Options {
  std::string out = "out/render_demo";
  int balls = 2500;
  int width = 1280, height = 720, samples = 1;
  bool profile = false;
};

void usage(const char* argv0) {
  std::printf(
      "usage: %s [--out DIR] [--balls N] [--size WxH] [--samples S] [--profile]\n"
      "  Draws a pile of N iron balls (default 2500) with a bar magnet, a capsule, a cylinder\n"
      "  and field arrows at WxH (default 1280x720), writes DIR/frame_000000.png (default\n"
      "  DIR out/render_demo) and prints ms per frame (median of 5 draws).\n"
      "  --samples 4 adds 2x2 supersampling (default 1: analytic edge anti-aliasing only).\n"
      "  --profile times each stage (waits for the GL work after each one).\n"
      "  The CPU time counts all threads; LP_NUM_THREADS=1 makes llvmpipe use one core.\n",
      argv0);
}

// Hexagonal close-packed layers of balls of radius r inside a cone of slope 34°: the
// lowest n lattice sites, with a little jitter so the pile does not look machined.
std::vector<Eigen::Vector3f> pile(int n, float r) {
  const float layer_dz = r * std::sqrt(8.0f / 3.0f);
  const float tan_slope = std::tan(34.0f * 3.14159265f / 180.0f);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> jitter(-0.04f * r, 0.04f * r);
  for (float base = 4.0f * r;; base *= 1.1f) {
    std::vector<Eigen::Vector3f> sites;
    const int rows = int(base / (std::sqrt(3.0f) * r)) + 2;
    for (int layer = 0;; ++layer) {
      const float z = r + float(layer) * layer_dz;
      const float radius = base - (z - r) / tan_slope;
      if (radius < 0.0f) break;
      // layers alternate between the A and B sites of the triangular lattice
      const float ox = (layer % 2) ? r : 0.0f;
      const float oy = (layer % 2) ? r / std::sqrt(3.0f) : 0.0f;
      for (int j = -rows; j <= rows; ++j)
        for (int i = -rows - 1; i <= rows + 1; ++i) {
          const float x = ox + 2.0f * r * float(i) + ((j & 1) ? r : 0.0f);
          const float y = oy + std::sqrt(3.0f) * r * float(j);
          if (std::hypot(x, y) <= radius) sites.emplace_back(x, y, z);
        }
    }
    if (int(sites.size()) < n) continue;
    std::stable_sort(sites.begin(), sites.end(),
                     [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
                       return a.z() < b.z();
                     });
    sites.resize(std::size_t(n));
    for (Eigen::Vector3f& p : sites) p += Eigen::Vector3f(jitter(rng), jitter(rng), 0.0f);
    return sites;
  }
}

Frame demo_frame(int n_balls) {
  Frame f;
  const float r = 0.005f;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> shade(-0.04f, 0.04f);
  for (const Eigen::Vector3f& p : pile(n_balls, r)) {
    Shape s;
    s.type = ShapeType::Sphere;
    s.position = p;
    s.size = Eigen::Vector3f(r, r, r);
    const float g = 0.55f + shade(rng);
    s.color = Color{g, g * 1.01f, g * 1.03f};
    f.shapes.push_back(s);
  }
  // bar magnet lying on the ground: north half red, south half blue
  const Eigen::Vector3f magnet(0.17f, -0.02f, 0.012f);
  const Eigen::Quaternionf yaw(Eigen::AngleAxisf(0.35f, Eigen::Vector3f::UnitZ()));
  for (int k = 0; k < 2; ++k) {
    Shape b;
    b.type = ShapeType::Box;
    b.orientation = yaw;
    b.position = magnet + yaw * Eigen::Vector3f(k == 0 ? 0.02f : -0.02f, 0.0f, 0.0f);
    b.size = Eigen::Vector3f(0.02f, 0.01f, 0.012f);
    b.color = k == 0 ? Color{0.75f, 0.06f, 0.05f} : Color{0.06f, 0.16f, 0.70f};
    f.shapes.push_back(b);
  }
  // a capsule and a cylinder magnet lying on the ground
  Shape cap;
  cap.type = ShapeType::Capsule;
  cap.position = Eigen::Vector3f(-0.15f, 0.09f, 0.008f);
  cap.orientation = Eigen::Quaternionf(Eigen::AngleAxisf(0.6f, Eigen::Vector3f::UnitZ())) *
                    Eigen::Quaternionf(Eigen::AngleAxisf(1.5708f, Eigen::Vector3f::UnitY()));
  cap.size = Eigen::Vector3f(0.008f, 0.025f, 0.0f);
  cap.color = Color{0.85f, 0.55f, 0.08f};
  f.shapes.push_back(cap);
  Shape cyl;
  cyl.type = ShapeType::Cylinder;
  cyl.position = Eigen::Vector3f(-0.06f, -0.16f, 0.01f);
  cyl.size = Eigen::Vector3f(0.012f, 0.01f, 0.0f);
  cyl.color = Color{0.10f, 0.45f, 0.20f};
  f.shapes.push_back(cyl);
  // field arrows around the magnet
  for (int k = 0; k < 8; ++k) {
    const float a = 2.0f * 3.14159265f * float(k) / 8.0f;
    Arrow ar;
    ar.origin = magnet + Eigen::Vector3f(0.05f * std::cos(a), 0.05f * std::sin(a), 0.03f);
    ar.vec = 0.03f * Eigen::Vector3f(-std::sin(a), std::cos(a), 0.4f);
    ar.color = Color{0.95f, 0.75f, 0.1f};
    f.arrows.push_back(ar);
  }
  f.camera.eye = Eigen::Vector3f(0.26f, -0.40f, 0.20f);
  f.camera.target = Eigen::Vector3f(0.01f, 0.0f, 0.035f);
  f.light_dir = Eigen::Vector3f(-0.5f, -0.35f, 1.0f);
  f.camera.fov_y_deg = 40.0f;
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage(argv[0]);
      return 0;
    } else if (a == "--out") {
      opt.out = value();
    } else if (a == "--balls") {
      opt.balls = std::max(0, std::atoi(value()));
    } else if (a == "--profile") {
      opt.profile = true;
    } else if (a == "--samples") {
      opt.samples = std::atoi(value());
    } else if (a == "--size") {
      if (std::sscanf(value(), "%dx%d", &opt.width, &opt.height) != 2) {
        std::fprintf(stderr, "--size wants WxH, e.g. 1280x720\n");
        return 2;
      }
    } else {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      usage(argv[0]);
      return 2;
    }
  }

  std::string err;
  if (!magsim::render::check_output_dir(opt.out, &err)) {
    std::fprintf(stderr, "%s\n", err.c_str());
    return 1;
  }
  try {
    const Frame frame = demo_frame(opt.balls);
    magsim::render::Renderer renderer(opt.width, opt.height, opt.samples);
    renderer.set_profiling(opt.profile);
    std::vector<double> ms, cpu_ms;
    magsim::render::RenderProfile stages[5];
    renderer.draw(frame);  // warm-up: shader variants are compiled on first use
    for (int k = 0; k < 5; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      const std::clock_t c0 = std::clock();
      renderer.draw(frame);
      cpu_ms.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
      ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
              .count());
      stages[k] = renderer.profile();
    }
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    const int median = int(std::find(ms.begin(), ms.end(), sorted[2]) - ms.begin());
    const magsim::render::RenderProfile& p = stages[median];
    const std::string path = magsim::render::frame_path(opt.out, 0);
    if (!magsim::render::write_png(path, opt.width, opt.height, renderer.pixels().data(),
                                   &err)) {
      std::fprintf(stderr, "%s\n", err.c_str());
      return 1;
    }
    std::sort(cpu_ms.begin(), cpu_ms.end());
    std::printf("%d balls, %dx%d, %d sample(s) per pixel: %.1f ms per frame (median of 5), "
                "CPU time %.1f ms (all threads) -> %s\n",
                opt.balls, opt.width, opt.height, renderer.samples(), sorted[2], cpu_ms[2],
                path.c_str());
    if (opt.profile)
      std::printf("  stages (ms): prepare %.1f, shadow %.1f, meshes %.1f, sphere depth %.1f, "
                  "ground %.1f, spheres %.1f, read-back %.1f; spheres drawn %zu of %zu\n",
                  p.prepare, p.shadow, p.meshes, p.sphere_depth, p.ground, p.spheres,
                  p.readback, p.spheres_camera, p.spheres_total);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "magsim-render-demo: %s\n", e.what());
    return 1;
  }
  return 0;
}
