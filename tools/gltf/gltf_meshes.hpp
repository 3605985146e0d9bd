// tools/gltf/gltf_meshes.hpp — triangle meshes of the shapes (sphere, box, capsule,
// cylinder) in glTF's y-up axes, and the axis conversion they share with the nodes.
#pragma once

#include "tools/gltf/gltf_writer.hpp"

#include <cstdint>
#include <vector>

namespace magsim::gltf {

/// magsim's z-up (x, y, z) as glTF's y-up (x, z, −y): a rotation by −90° about x, so lengths,
/// angles and handedness are kept and Blender's importer inverts it exactly.
inline Vec3 to_gltf(const Vec3& v) { return Vec3(v.x(), v.z(), -v.y()); }
/// The same rotation applied to a quaternion: its vector part converted as a vector.
inline Quat to_gltf(const Quat& q) { return Quat(q.w(), q.x(), q.z(), -q.y()); }

struct MeshData {
  std::vector<float> positions;        ///< xyz per vertex, glTF axes (m)
  std::vector<float> normals;          ///< unit, per vertex
  std::vector<std::uint32_t> indices;  ///< triangles, counter-clockwise seen from outside
  std::size_t vertices() const { return positions.size() / 3; }
};

/// A shape of this kind and size about its own centre (capsules and cylinders along the
/// shape's z, i.e. glTF's −y); spheres and capsules with smooth normals, boxes and the caps
/// of cylinders flat.
MeshData shape_mesh(ShapeKind kind, const Vec3& size);
/// The ground: a square of half side `half` in the plane z = height, facing up.
MeshData ground_mesh(double half, double height);

}  // namespace magsim::gltf
