// render/camera.cpp — look-at, perspective and orthographic matrices, and the scene extent
// that near/far, the ground quad and the shadow map are fitted to.
#include "render/camera.hpp"

#include <algorithm>
#include <cmath>

namespace magsim::render {

void Bounds::add(const Eigen::Vector3f& p, float pad) {
  const Eigen::Vector3f d = Eigen::Vector3f::Constant(pad);
  if (empty) {
    lo = p - d;
    hi = p + d;
    empty = false;
  } else {
    lo = lo.cwiseMin(p - d);
    hi = hi.cwiseMax(p + d);
  }
}

Bounds scene_bounds(const Frame& frame) {
  Bounds b;
  for (const Shape& s : frame.shapes) {
    // a bounding sphere per shape is loose for long boxes but always safe
    float r = 0.0f;
    switch (s.type) {
      case ShapeType::Sphere: r = s.size.x(); break;
      case ShapeType::Box: r = s.size.norm(); break;
      case ShapeType::Capsule: r = s.size.x() + s.size.y(); break;
      case ShapeType::Cylinder: r = std::hypot(s.size.x(), s.size.y()); break;
    }
    b.add(s.position, std::abs(r));
  }
  for (const Arrow& a : frame.arrows) {
    const float len = a.vec.norm();
    const float pad = 3.0f * (a.radius > 0.0f ? a.radius : 0.04f * len);
    b.add(a.origin, pad);
    b.add(a.origin + a.vec, pad);
  }
  if (b.empty) b.add(frame.camera.target, 0.05f);
  return b;
}

Eigen::Matrix4f look_at(const Eigen::Vector3f& eye, const Eigen::Vector3f& target,
                        const Eigen::Vector3f& up) {
  const Eigen::Vector3f f = (target - eye).normalized();
  Eigen::Vector3f s = f.cross(up);
  // an up vector parallel to the view direction: pick any perpendicular one
  if (s.squaredNorm() < 1e-12f) s = f.cross(std::abs(f.x()) < 0.9f ? Eigen::Vector3f::UnitX()
                                                                    : Eigen::Vector3f::UnitY());
  s.normalize();
  const Eigen::Vector3f u = s.cross(f);
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Eigen::Matrix4f perspective(float fov_y_deg, float aspect, float z_near, float z_far) {
  const float f = 1.0f / std::tan(0.5f * fov_y_deg * 3.14159265358979f / 180.0f);
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m(0, 0) = f / aspect;
  m(1, 1) = f;
  m(2, 2) = (z_far + z_near) / (z_near - z_far);
  m(2, 3) = 2.0f * z_far * z_near / (z_near - z_far);
  m(3, 2) = -1.0f;
  return m;
}

Eigen::Matrix4f orthographic(float l, float r, float b, float t, float n, float f) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m(0, 0) = 2.0f / (r - l);
  m(1, 1) = 2.0f / (t - b);
  m(2, 2) = -2.0f / (f - n);
  m(0, 3) = -(r + l) / (r - l);
  m(1, 3) = -(t + b) / (t - b);
  m(2, 3) = -(f + n) / (f - n);
  return m;
}

ViewSetup view_setup(const Frame& frame, float aspect) {
  const Camera& cam = frame.camera;
  const Bounds b = scene_bounds(frame);
  ViewSetup v;
  v.scene_center = b.center();
  v.scene_radius = std::max(b.radius(), 1e-3f);

  const float dist = (cam.eye - v.scene_center).norm();
  // the ground reaches well past the scene and fades into the background before its edge
  v.ground_extent = std::max(12.0f * v.scene_radius, 3.0f * dist);

  float z_far = dist + v.scene_radius;
  float z_near = dist - v.scene_radius;
  if (frame.ground) {
    z_far = std::max(z_far, dist + 1.5f * v.ground_extent);
    z_near = std::min(z_near, std::abs(cam.eye.z() - frame.ground_height));
  }
  z_near = std::max(0.5f * z_near, 1e-5f * z_far);
  v.z_near = cam.z_near > 0.0f ? cam.z_near : z_near;
  v.z_far = cam.z_far > 0.0f ? cam.z_far : z_far;

  const float cam_dist = std::max((cam.eye - cam.target).norm(), 1e-3f);
  v.ground_cell = 0.5f * std::pow(10.0f, std::floor(std::log10(cam_dist)));
  v.fade_start = 1.05f * cam_dist;
  v.fade_end = 2.7f * cam_dist;
  v.fade_center = cam.target;

  v.view = look_at(cam.eye, cam.target, cam.up);
  v.proj = perspective(cam.fov_y_deg, aspect, v.z_near, v.z_far);
  v.view_proj = v.proj * v.view;
  return v;
}

bool project_to_pixel(const ViewSetup& view, int width, int height, const Eigen::Vector3f& p,
                      float* px, float* py) {
  const Eigen::Vector4f c = view.view_proj * p.homogeneous();
  if (c.w() <= 0.0f) return false;
  const float x = c.x() / c.w(), y = c.y() / c.w();
  *px = 0.5f * (x + 1.0f) * float(width);
  *py = 0.5f * (1.0f - y) * float(height);
  return true;
}

}  // namespace magsim::render
