// tools/gltf/gltf_meshes.cpp — the shapes as triangle meshes (gltf_meshes.hpp).
#include "tools/gltf/gltf_meshes.hpp"

#include <cmath>

namespace magsim::gltf {

namespace {

constexpr double kPi = 3.14159265358979323846;
// segments around the axis and rings from pole to pole: smooth at the size a ball is seen
constexpr int kSegments = 32;
constexpr int kRings = 16;

struct Builder {
  MeshData m;
  std::uint32_t add(const Vec3& p, const Vec3& n) {
    const Vec3 gp = to_gltf(p), gn = to_gltf(n.normalized());
    for (int i = 0; i < 3; ++i) {
      m.positions.push_back(static_cast<float>(gp[i]));
      m.normals.push_back(static_cast<float>(gn[i]));
    }
    return static_cast<std::uint32_t>(m.vertices() - 1);
  }
  void tri(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    m.indices.push_back(a);
    m.indices.push_back(b);
    m.indices.push_back(c);
  }
};

// Rings of kSegments vertices from the north pole to the south pole of a sphere of radius r,
// the northern half raised by h and the southern half lowered by h (h > 0: a capsule, whose
// equator is then two rings joined by the cylinder's side). Triangles run (ring i, j),
// (ring i + 1, j), (ring i + 1, j + 1): ∂/∂θ × ∂/∂φ points outwards.
void add_rounded(Builder* b, double r, double h) {
  std::vector<std::uint32_t> ring_start;
  const Vec3 north(0, 0, 1);
  const std::uint32_t top = b->add(Vec3(0, 0, r + h), north);
  auto add_ring = [&](double theta, double shift) {
    ring_start.push_back(static_cast<std::uint32_t>(b->m.vertices()));
    for (int j = 0; j < kSegments; ++j) {
      const double phi = 2 * kPi * j / kSegments;
      const Vec3 n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      b->add(r * n + Vec3(0, 0, shift), n);
    }
  };
  for (int i = 1; i < kRings; ++i) {
    const double theta = kPi * i / kRings;
    if (2 * i < kRings) {
      add_ring(theta, h);
    } else if (2 * i > kRings) {
      add_ring(theta, -h);
    } else {  // the equator: doubled for a capsule, one ring at +h and one at −h
      add_ring(theta, h);
      if (h > 0) add_ring(theta, -h);
    }
  }
  const std::uint32_t bottom = b->add(Vec3(0, 0, -r - h), -north);
  auto at = [&](std::size_t ring, int j) { return ring_start[ring] + static_cast<std::uint32_t>(j % kSegments); };
  for (int j = 0; j < kSegments; ++j) b->tri(top, at(0, j), at(0, j + 1));
  for (std::size_t i = 0; i + 1 < ring_start.size(); ++i)
    for (int j = 0; j < kSegments; ++j) {
      b->tri(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      b->tri(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  const std::size_t last = ring_start.size() - 1;
  for (int j = 0; j < kSegments; ++j) b->tri(bottom, at(last, j + 1), at(last, j));
}

// A quad with corners c ± u ± v, facing u × v.
void add_quad(Builder* b, const Vec3& c, const Vec3& u, const Vec3& v) {
  const Vec3 n = u.cross(v);
  const std::uint32_t a = b->add(c - u - v, n), p = b->add(c + u - v, n), q = b->add(c + u + v, n),
                      d = b->add(c - u + v, n);
  b->tri(a, p, q);
  b->tri(a, q, d);
}

void add_box(Builder* b, const Vec3& half) {
  for (int axis = 0; axis < 3; ++axis) {
    const int ua = (axis + 1) % 3, va = (axis + 2) % 3;  // e_ua × e_va = e_axis
    Vec3 u = Vec3::Zero(), v = Vec3::Zero(), c = Vec3::Zero();
    u[ua] = half[ua];
    v[va] = half[va];
    c[axis] = half[axis];
    add_quad(b, c, u, v);
    add_quad(b, -c, v, u);  // v × u = −e_axis
  }
}

void add_cylinder(Builder* b, double r, double h) {
  std::uint32_t top_ring = 0, bottom_ring = 0;
  for (int side = 0; side < 2; ++side) {
    const double z = side == 0 ? h : -h;
    (side == 0 ? top_ring : bottom_ring) = static_cast<std::uint32_t>(b->m.vertices());
    for (int j = 0; j < kSegments; ++j) {
      const double phi = 2 * kPi * j / kSegments;
      const Vec3 n(std::cos(phi), std::sin(phi), 0);
      b->add(r * n + Vec3(0, 0, z), n);
    }
  }
  auto ring = [](std::uint32_t start, int j) { return start + static_cast<std::uint32_t>(j % kSegments); };
  for (int j = 0; j < kSegments; ++j) {
    b->tri(ring(top_ring, j), ring(bottom_ring, j), ring(bottom_ring, j + 1));
    b->tri(ring(top_ring, j), ring(bottom_ring, j + 1), ring(top_ring, j + 1));
  }
  for (int side = 0; side < 2; ++side) {  // the caps, flat
    const Vec3 n(0, 0, side == 0 ? 1.0 : -1.0);
    const std::uint32_t centre = b->add(Vec3(0, 0, side == 0 ? h : -h), n);
    const std::uint32_t start = static_cast<std::uint32_t>(b->m.vertices());
    for (int j = 0; j < kSegments; ++j) {
      const double phi = 2 * kPi * j / kSegments;
      b->add(Vec3(r * std::cos(phi), r * std::sin(phi), side == 0 ? h : -h), n);
    }
    for (int j = 0; j < kSegments; ++j) {
      if (side == 0)
        b->tri(centre, ring(start, j), ring(start, j + 1));
      else
        b->tri(centre, ring(start, j + 1), ring(start, j));
    }
  }
}

}  // namespace

MeshData shape_mesh(ShapeKind kind, const Vec3& size) {
  Builder b;
  switch (kind) {
    case ShapeKind::Sphere: add_rounded(&b, size.x(), 0.0); break;
    case ShapeKind::Capsule: add_rounded(&b, size.x(), size.y()); break;
    case ShapeKind::Box: add_box(&b, size); break;
    case ShapeKind::Cylinder: add_cylinder(&b, size.x(), size.y()); break;
  }
  return b.m;
}

MeshData ground_mesh(double half, double height) {
  Builder b;
  add_quad(&b, Vec3(0, 0, height), Vec3(half, 0, 0), Vec3(0, half, 0));
  return b.m;
}

}  // namespace magsim::gltf
