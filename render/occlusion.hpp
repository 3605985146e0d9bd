// render/occlusion.hpp — a conservative software occlusion test for sphere impostors.
//
// In a pile most balls are hidden behind others, yet every impostor quad costs fragment
// work on llvmpipe. This rasterizes each sphere's inner disc into a coarse grid of
// "distance within which every ray through this cell meets a surface" and drops spheres
// whose whole impostor lies behind already-seen surfaces. It never drops a sphere that
// could show, so images are unchanged (bit for bit).
#pragma once

#include <cstdint>
#include <vector>

#include "render/camera.hpp"

namespace magsim::render {

class SphereOcclusion {
 public:
  /// Perspective camera at `eye` (the view of `view`, field of view `fov_y_deg`) on a
  /// `width` × `height` pixel target. `spheres`: packed records of `stride` floats
  /// starting {x, y, z, r}; `order`: their indices from front to back (an approximate
  /// order only costs culling, never correctness). Sets `visible[i]` to 0 for spheres
  /// certainly hidden, 1 for the others. `cell`: grid cell size in pixels.
  void run_perspective(const float* spheres, std::size_t stride,
                       const std::vector<std::uint32_t>& order, const Eigen::Vector3f& eye,
                       const ViewSetup& view, float fov_y_deg, int width, int height, int cell,
                       std::vector<std::uint8_t>* visible);

  std::size_t hidden() const { return hidden_; }

 private:
  void reset(int width, int height, int cell, std::size_t n, std::vector<std::uint8_t>* visible);
  // true if the pixel box [x0, x1] × [y0, y1] only sees surfaces nearer than `nearest`
  bool box_hidden(float x0, float y0, float x1, float y1, float nearest) const;
  // cells inside the disc of radius rho around (cx, cy) see a surface within `dist`
  void occlude_disc(float cx, float cy, float rho, float dist);

  std::vector<float> grid_;  // per cell, a distance (m)
  int gw_ = 0, gh_ = 0, cell_ = 1;
  std::size_t hidden_ = 0;
};

}  // namespace magsim::render
