// render/meshes.cpp — unit box, cylinder and cone.
#include "render/meshes.hpp"

#include <cmath>

namespace magsim::render {

namespace {

constexpr float kTwoPi = 6.28318530717958647f;

std::uint32_t add_vertex(Mesh& m, float x, float y, float z, float nx, float ny, float nz) {
  const auto index = std::uint32_t(m.vertex_count());
  m.vertices.insert(m.vertices.end(), {x, y, z, nx, ny, nz});
  return index;
}

void add_triangle(Mesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  m.indices.insert(m.indices.end(), {a, b, c});
}

// a flat disk at height z facing +z (up = true) or −z
void add_disk(Mesh& m, int segments, float z, bool up) {
  const float nz = up ? 1.0f : -1.0f;
  const std::uint32_t centre = add_vertex(m, 0.0f, 0.0f, z, 0.0f, 0.0f, nz);
  const std::uint32_t first = centre + 1;
  for (int i = 0; i < segments; ++i) {
    const float a = kTwoPi * float(i) / float(segments);
    add_vertex(m, std::cos(a), std::sin(a), z, 0.0f, 0.0f, nz);
  }
  for (int i = 0; i < segments; ++i) {
    const std::uint32_t a = first + std::uint32_t(i);
    const std::uint32_t b = first + std::uint32_t((i + 1) % segments);
    if (up) add_triangle(m, centre, a, b);
    else add_triangle(m, centre, b, a);
  }
}

}  // namespace

Mesh unit_box() {
  Mesh m;
  // one quad per face: normal axis k, sign s; u, v span the face counter-clockwise
  for (int k = 0; k < 3; ++k) {
    for (int s = -1; s <= 1; s += 2) {
      float n[3] = {0, 0, 0};
      n[k] = float(s);
      const int ku = (k + 1) % 3, kv = (k + 2) % 3;
      std::uint32_t idx[4];
      const float us[4] = {-1, 1, 1, -1}, vs[4] = {-1, -1, 1, 1};
      for (int c = 0; c < 4; ++c) {
        float p[3];
        p[k] = float(s);
        p[ku] = us[c];
        p[kv] = vs[c] * float(s);  // mirror v on the negative face to keep the winding
        idx[c] = add_vertex(m, p[0], p[1], p[2], n[0], n[1], n[2]);
      }
      add_triangle(m, idx[0], idx[1], idx[2]);
      add_triangle(m, idx[0], idx[2], idx[3]);
    }
  }
  return m;
}

Mesh unit_cylinder(int segments) {
  Mesh m;
  const auto first = std::uint32_t(m.vertex_count());
  for (int i = 0; i <= segments; ++i) {
    const float a = kTwoPi * float(i) / float(segments);
    const float c = std::cos(a), s = std::sin(a);
    add_vertex(m, c, s, -1.0f, c, s, 0.0f);
    add_vertex(m, c, s, 1.0f, c, s, 0.0f);
  }
  for (int i = 0; i < segments; ++i) {
    const std::uint32_t b0 = first + 2 * std::uint32_t(i), t0 = b0 + 1, b1 = b0 + 2, t1 = b0 + 3;
    add_triangle(m, b0, b1, t1);
    add_triangle(m, b0, t1, t0);
  }
  add_disk(m, segments, 1.0f, true);
  add_disk(m, segments, -1.0f, false);
  return m;
}

Mesh unit_cone(int segments) {
  Mesh m;
  // side normal of a cone with base radius 1 and height 1: (cos a, sin a, 1)/√2;
  // the tip gets one vertex per segment, with the normal of the segment's middle
  const float k = 1.0f / std::sqrt(2.0f);
  const auto first = std::uint32_t(m.vertex_count());
  for (int i = 0; i < segments; ++i) {
    const float a0 = kTwoPi * float(i) / float(segments);
    const float a1 = kTwoPi * float(i + 1) / float(segments);
    const float am = 0.5f * (a0 + a1);
    add_vertex(m, std::cos(a0), std::sin(a0), 0.0f, k * std::cos(a0), k * std::sin(a0), k);
    add_vertex(m, std::cos(a1), std::sin(a1), 0.0f, k * std::cos(a1), k * std::sin(a1), k);
    add_vertex(m, 0.0f, 0.0f, 1.0f, k * std::cos(am), k * std::sin(am), k);
    const std::uint32_t b = first + 3 * std::uint32_t(i);
    add_triangle(m, b, b + 1, b + 2);
  }
  add_disk(m, segments, 0.0f, false);
  return m;
}

}  // namespace magsim::render
