// render/frame.hpp — the plain frame description the engine hands to the renderer.
// No GL, no physics: shapes, transforms, colours, arrows and a camera. World is z-up,
// metres. Header-only so that everything except the renderer builds without GL.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace magsim::render {

struct Color {
  float r = 0.8f, g = 0.8f, b = 0.8f;  ///< linear RGB in [0, 1]
};

enum class ShapeType { Sphere, Box, Capsule, Cylinder };

/// One solid. Local frame: capsules and cylinders lie along their local z axis.
struct Shape {
  ShapeType type = ShapeType::Sphere;
  Eigen::Vector3f position = Eigen::Vector3f::Zero();              ///< centre (m)
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();  ///< body → world
  /// sphere: {radius, -, -}; box: half extents {hx, hy, hz};
  /// capsule / cylinder: {radius, half length of the axis segment, -} (m)
  Eigen::Vector3f size = Eigen::Vector3f(0.01f, 0.01f, 0.01f);
  Color color;
};

/// A vector drawn as a shaft with a cone head, from `origin` to `origin + vec`.
struct Arrow {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();  ///< (m)
  Eigen::Vector3f vec = Eigen::Vector3f::UnitZ();    ///< (m)
  float radius = 0.0f;  ///< shaft radius (m); 0 → 4 % of the arrow's length
  Color color{1.0f, 0.1f, 0.1f};
};

struct Camera {
  Eigen::Vector3f eye{0.5f, -0.5f, 0.4f};  ///< (m)
  Eigen::Vector3f target{0.0f, 0.0f, 0.0f};
  Eigen::Vector3f up{0.0f, 0.0f, 1.0f};
  float fov_y_deg = 40.0f;
  float z_near = 0.0f;  ///< 0 → chosen from the scene's extent
  float z_far = 0.0f;   ///< 0 → chosen from the scene's extent
};

struct Frame {
  Camera camera;
  std::vector<Shape> shapes;
  std::vector<Arrow> arrows;
  bool ground = true;         ///< draw the plane z = ground_height
  float ground_height = 0.0f;  ///< (m)
  Color ground_color{0.85f, 0.85f, 0.82f};
  Color background{0.93f, 0.95f, 0.98f};
  /// direction *towards* the light (need not be unit)
  Eigen::Vector3f light_dir{0.35f, -0.45f, 1.0f};
  bool shadows = true;
};

}  // namespace magsim::render
