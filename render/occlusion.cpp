// render/occlusion.cpp — coarse occlusion culling of spheres.
//
// Distances are Euclidean from the eye. A sphere S (centre distance d, radius
// r) whose centre projects to pixel c covers, for certain, the pixels within f·asin(r/d)
// of c (f: focal length in pixels; the perspective map stretches angles by at least f),
// and every ray through that disc meets S at a distance ≤ d. A sphere T is hidden when
// every cell touched by the screen box of its impostor quad holds a distance < d_T − r_T,
// the nearest T can be.
#include "render/occlusion.hpp"

#include <algorithm>
#include <cmath>

namespace magsim::render {

void SphereOcclusion::reset(int width, int height, int cell, std::size_t n,
                            std::vector<std::uint8_t>* visible) {
  visible->assign(n, 1);
  hidden_ = 0;
  cell_ = std::max(cell, 1);
  gw_ = (width + cell_ - 1) / cell_;
  gh_ = (height + cell_ - 1) / cell_;
  grid_.assign(std::size_t(gw_) * std::size_t(gh_), INFINITY);
}

bool SphereOcclusion::box_hidden(float x0, float y0, float x1, float y1, float nearest) const {
  const float inv = 1.0f / float(cell_);
  const int gx0 = std::max(0, int(std::floor(x0 * inv)));
  const int gy0 = std::max(0, int(std::floor(y0 * inv)));
  const int gx1 = std::min(gw_ - 1, int(std::floor(x1 * inv)));
  const int gy1 = std::min(gh_ - 1, int(std::floor(y1 * inv)));
  if (gx0 > gx1 || gy0 > gy1) return true;  // entirely outside the target
  for (int gy = gy0; gy <= gy1; ++gy) {
    const float* row = &grid_[std::size_t(gy) * std::size_t(gw_)];
    for (int gx = gx0; gx <= gx1; ++gx)
      if (!(row[gx] < nearest)) return false;
  }
  return true;
}

void SphereOcclusion::occlude_disc(float cx, float cy, float rho, float dist) {
  // cells whose four corners lie inside the disc
  const float inv = 1.0f / float(cell_);
  const float rho2 = rho * rho;
  const int ix0 = std::max(0, int(std::ceil((cx - rho) * inv)));
  const int ix1 = std::min(gw_, int(std::floor((cx + rho) * inv)));  // exclusive
  const int iy0 = std::max(0, int(std::ceil((cy - rho) * inv)));
  const int iy1 = std::min(gh_, int(std::floor((cy + rho) * inv)));
  for (int gy = iy0; gy < iy1; ++gy) {
    const float ya = float(gy * cell_) - cy, yb = float((gy + 1) * cell_) - cy;
    const float dy2 = std::max(ya * ya, yb * yb);
    float* row = &grid_[std::size_t(gy) * std::size_t(gw_)];
    for (int gx = ix0; gx < ix1; ++gx) {
      const float xa = float(gx * cell_) - cx, xb = float((gx + 1) * cell_) - cx;
      if (std::max(xa * xa, xb * xb) + dy2 <= rho2) row[gx] = std::min(row[gx], dist);
    }
  }
}

void SphereOcclusion::run_perspective(const float* spheres, std::size_t stride,
                                      const std::vector<std::uint32_t>& order,
                                      const Eigen::Vector3f& eye, const ViewSetup& view,
                                      float fov_y_deg, int width, int height, int cell,
                                      std::vector<std::uint8_t>* visible) {
  reset(width, height, cell, order.size(), visible);
  const float tan_half = std::tan(0.5f * fov_y_deg * 3.14159265f / 180.0f);
  const float focal = 0.5f * float(height) / tan_half;  // pixels per unit of tan(angle)
  const Eigen::Matrix4f& vp = view.view_proj;

  // window pixel of a world point (bottom-up, like GL); false when not in front
  auto project = [&](const Eigen::Vector3f& p, float* x, float* y) {
    const Eigen::Vector4f c = vp * p.homogeneous();
    if (c.w() <= 1e-6f) return false;
    *x = (0.5f * c.x() / c.w() + 0.5f) * float(width);
    *y = (0.5f * c.y() / c.w() + 0.5f) * float(height);
    return true;
  };

  for (const std::uint32_t i : order) {
    const float* s = spheres + std::size_t(i) * stride;
    const Eigen::Vector3f c(s[0], s[1], s[2]);
    const float r = s[3];
    const Eigen::Vector3f dvec = c - eye;
    const float d = dvec.norm();
    if (d <= 1.5f * r) continue;  // too close to reason about: keep, do not occlude
    float cx = 0.0f, cy = 0.0f;
    if (!project(c, &cx, &cy)) continue;

    // the impostor quad's screen box, built as the vertex shader builds it (plus a pixel)
    const Eigen::Vector3f f = dvec / d;
    const Eigen::Vector3f up =
        std::abs(f.z()) < 0.99f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
    const Eigen::Vector3f right = f.cross(up).normalized();
    const Eigen::Vector3f u = right.cross(f);
    const float t = d - r;
    const float half = t * (r / std::sqrt(d * d - r * r) + 2.0f * tan_half / float(height));
    float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
    bool in_front = true;
    for (int q = 0; q < 4 && in_front; ++q) {
      const Eigen::Vector3f p =
          eye + f * t + (right * ((q & 1) ? half : -half) + u * ((q & 2) ? half : -half));
      float px = 0.0f, py = 0.0f;
      in_front = project(p, &px, &py);
      x0 = std::min(x0, px), x1 = std::max(x1, px);
      y0 = std::min(y0, py), y1 = std::max(y1, py);
    }
    if (!in_front) continue;
    if (box_hidden(x0 - 1.0f, y0 - 1.0f, x1 + 1.0f, y1 + 1.0f, d - r)) {
      (*visible)[i] = 0;
      ++hidden_;
      continue;
    }
    occlude_disc(cx, cy, focal * std::asin(std::min(r / d, 1.0f)), d);
  }
}

}  // namespace magsim::render
