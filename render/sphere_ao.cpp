// render/sphere_ao.cpp — neighbour-based ambient occlusion for spheres.
//
// Spheres are binned in a uniform grid (cell = 2.5 × the 90th-percentile radius; much
// larger spheres are left out), each sphere looks at its 27 surrounding cells. A
// neighbour j at unit direction u and gap g = |c_j − c_i| − r_i − r_j occludes with
//   w = (1 − smoothstep(0, 0.3 r_i, g)) · min(r_j / r_i, 1) · (0.15 + 0.85 max(u_z, 0)),
// i.e. fully when touching and above, little when beside or below; the factor is
//   ao = clamp(1 / (1 + 0.25 Σ w), 0.3, 1).
#include "render/sphere_ao.hpp"

#include <algorithm>
#include <cmath>

namespace magsim::render {

namespace {

constexpr std::uint32_t kHashSize = 1u << 16;

std::uint32_t hash_cell(int x, int y, int z) {
  return (std::uint32_t(x) * 73856093u ^ std::uint32_t(y) * 19349663u ^
          std::uint32_t(z) * 83492791u) &
         (kHashSize - 1);
}

}  // namespace

void SphereAmbientOcclusion::run(float* spheres, std::size_t stride, std::size_t n,
                                 std::size_t ao_offset, const std::uint8_t* wanted) {
  if (n == 0) return;
  // typical radius: the 90th percentile (a few big spheres must not blow up the cells)
  std::vector<float> radii(n);
  for (std::size_t i = 0; i < n; ++i) radii[i] = spheres[i * stride + 3];
  const std::size_t p90 = std::min(n - 1, n * 9 / 10);
  std::nth_element(radii.begin(), radii.begin() + std::ptrdiff_t(p90), radii.end());
  const float r_typ = std::max(radii[p90], 1e-6f);
  const float r_max = 2.0f * r_typ;  // bigger spheres neither get nor give occlusion
  const float h = 2.5f * r_typ;
  const float inv_h = 1.0f / h;

  // counting sort of the spheres by hashed cell
  cell_of_.assign(n, kHashSize);
  cell_start_.assign(kHashSize + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const float* s = spheres + i * stride;
    if (!wanted || wanted[i]) spheres[i * stride + ao_offset] = 1.0f;
    if (s[3] > r_max) continue;
    const std::uint32_t c = hash_cell(int(std::floor(s[0] * inv_h)), int(std::floor(s[1] * inv_h)),
                                      int(std::floor(s[2] * inv_h)));
    cell_of_[i] = c;
    ++cell_start_[c + 1];
  }
  for (std::uint32_t c = 0; c < kHashSize; ++c) cell_start_[c + 1] += cell_start_[c];
  // {x, y, z, r} copied in bucket order, so a bucket's spheres are contiguous
  packed_.resize(4 * std::size_t(cell_start_[kHashSize]));
  {
    std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
      if (cell_of_[i] == kHashSize) continue;
      const std::uint32_t slot = fill[cell_of_[i]]++;
      std::copy(spheres + i * stride, spheres + i * stride + 4, &packed_[4 * std::size_t(slot)]);
    }
  }

  for (std::size_t i = 0; i < n; ++i) {
    if (cell_of_[i] == kHashSize || (wanted && !wanted[i])) continue;
    const float* s = spheres + i * stride;
    const float ri = s[3];
    const int cx = int(std::floor(s[0] * inv_h)), cy = int(std::floor(s[1] * inv_h)),
              cz = int(std::floor(s[2] * inv_h));
    float occl = 0.0f;
    std::uint32_t seen[27];
    int n_seen = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const std::uint32_t c = hash_cell(cx + dx, cy + dy, cz + dz);
          // two neighbour cells may share a bucket: visit each bucket once
          if (std::find(seen, seen + n_seen, c) != seen + n_seen) continue;
          seen[n_seen++] = c;
          for (std::uint32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
            const float* t = &packed_[4 * std::size_t(k)];
            const float ex = t[0] - s[0], ey = t[1] - s[1], ez = t[2] - s[2];
            const float d2 = ex * ex + ey * ey + ez * ez;
            const float reach = 0.3f * ri;
            const float far = ri + t[3] + reach;
            // too far (hash collisions land here too), or the sphere itself
            if (d2 >= far * far || d2 <= 0.0f) continue;
            const float dist = std::sqrt(d2);
            const float gap = dist - ri - t[3];
            const float g = std::max(gap, 0.0f) / reach;
            const float contact = 1.0f - g * g * (3.0f - 2.0f * g);
            const float above = 0.15f + 0.85f * std::max(ez / dist, 0.0f);
            occl += contact * std::min(t[3] / ri, 1.0f) * above;
          }
        }
    spheres[i * stride + ao_offset] = std::clamp(1.0f / (1.0f + 0.25f * occl), 0.3f, 1.0f);
  }
}

}  // namespace magsim::render
