// render/meshes.hpp — the unit meshes that boxes, cylinders and arrow heads are instanced
// from. Plain vertex arrays, no GL; each instance scales them by its size.
#pragma once

#include <cstdint>
#include <vector>

namespace magsim::render {

/// Indexed triangles, vertices packed as {x, y, z, nx, ny, nz}, counter-clockwise outside.
struct Mesh {
  std::vector<float> vertices;
  std::vector<std::uint32_t> indices;
  int vertex_count() const { return int(vertices.size() / 6); }
};

/// The cube [−1, 1]³ with flat faces (scaled by half extents).
Mesh unit_box();
/// Radius 1, axis z ∈ [−1, 1], smooth sides and flat caps (scaled by {r, r, half length}).
Mesh unit_cylinder(int segments);
/// Base of radius 1 at z = 0 (closed by a disk), tip at z = 1.
Mesh unit_cone(int segments);

}  // namespace magsim::render
