// render/camera.hpp — view and projection matrices (OpenGL conventions, written with Eigen)
// and the scene extent they are fitted to. No GL: tests use these to predict where a point
// lands on the image.
#pragma once

#include "render/frame.hpp"

namespace magsim::render {

/// Axis-aligned bounds of everything the frame draws except the ground (m).
struct Bounds {
  Eigen::Vector3f lo = Eigen::Vector3f::Zero();
  Eigen::Vector3f hi = Eigen::Vector3f::Zero();
  bool empty = true;

  void add(const Eigen::Vector3f& p, float pad = 0.0f);
  Eigen::Vector3f center() const { return 0.5f * (lo + hi); }
  float radius() const { return 0.5f * (hi - lo).norm(); }  ///< of the bounding sphere
};

/// Bounds of the frame's shapes and arrows; an empty frame gives a 0.1 m box at the target.
Bounds scene_bounds(const Frame& frame);

/// Right-handed look-at: the camera looks down its −z axis (gluLookAt semantics).
Eigen::Matrix4f look_at(const Eigen::Vector3f& eye, const Eigen::Vector3f& target,
                        const Eigen::Vector3f& up);
/// Perspective projection to clip space, depth in [−w, w] (gluPerspective semantics).
Eigen::Matrix4f perspective(float fov_y_deg, float aspect, float z_near, float z_far);
/// Orthographic projection of the box [l, r] × [b, t] × [−n, −f] (glOrtho semantics).
Eigen::Matrix4f orthographic(float l, float r, float b, float t, float n, float f);

/// Everything the renderer derives from the frame's camera and extent.
struct ViewSetup {
  Eigen::Matrix4f view = Eigen::Matrix4f::Identity();
  Eigen::Matrix4f proj = Eigen::Matrix4f::Identity();
  Eigen::Matrix4f view_proj = Eigen::Matrix4f::Identity();
  float z_near = 0.01f, z_far = 100.0f;  ///< (m)
  Eigen::Vector3f scene_center = Eigen::Vector3f::Zero();  ///< (m)
  float scene_radius = 0.1f;                                ///< (m)
  float ground_extent = 1.0f;  ///< half side of the ground quad around scene_center (m)
  /// Ground grid cell and fade (m), from the camera alone (eye–target distance d): cell
  /// 0.5 × 10^⌊log10 d⌋, fading out between 1.05 d and 2.7 d from the target. Not from the
  /// scene's extent, which grows when a body flies off: the floor kept its look through a
  /// video and between two runs shown side by side only by chance.
  float ground_cell = 0.05f;
  float fade_start = 1.0f, fade_end = 2.0f;
  Eigen::Vector3f fade_center = Eigen::Vector3f::Zero();  ///< the camera target (m)
};

/// Camera matrices for an image of aspect width/height; near/far from the scene's extent
/// (the ground quad included) unless the camera sets them.
ViewSetup view_setup(const Frame& frame, float aspect);

/// Pixel coordinates (x right, y down from the top row, pixel centres at +0.5) of a world
/// point; returns false when the point is behind the camera.
bool project_to_pixel(const ViewSetup& view, int width, int height, const Eigen::Vector3f& p,
                      float* px, float* py);

}  // namespace magsim::render
