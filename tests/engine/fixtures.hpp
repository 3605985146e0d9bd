// tests/engine/fixtures.hpp — small scenes shared by the engine tests.
#pragma once

#include "engine/scene_desc.hpp"

#include <string>

namespace magsim::test {

using engine::BodyDesc;
using engine::BodyType;
using engine::MomentDesc;
using engine::Quat;
using engine::SceneDesc;
using engine::ShapeDesc;
using engine::ShapeKind;
using engine::Vec3;

using mag::kPi;  // magnetics/types.hpp
inline constexpr double kR = 0.005;  // ball radius (m)

inline double sphere_volume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

/// An iron ball of radius r with one induced moment at its centre.
inline BodyDesc iron_ball(const std::string& name, const Vec3& p, double r = kR) {
  BodyDesc b;
  b.name = name;
  b.position = p;
  b.shapes.push_back({ShapeKind::Sphere, Vec3::Zero(), Quat::Identity(), Vec3(r, r, r)});
  MomentDesc m;
  m.volume = sphere_volume(r);
  m.Ms = 1.6e6;
  b.moments.push_back(m);
  return b;
}

/// An empty world with nothing outside acting: no gravity, no ground; ours-realigned on one
/// magnetics thread.
inline SceneDesc free_space(const std::string& name) {
  SceneDesc s;
  s.name = name;
  s.options.magnetics.method = mag::Method::OursRealigned;
  s.options.threads = 1;
  s.options.gravity = Vec3::Zero();
  s.options.ground = false;
  return s;
}

/// A static 1 cm cube magnet with a permanent moment m (A·m², body frame).
inline BodyDesc cube_magnet(const Vec3& p, const Vec3& m) {
  BodyDesc b;
  b.name = "magnet";
  b.type = BodyType::Static;
  b.position = p;
  b.magnet = true;
  b.color = {0.8f, 0.1f, 0.1f};
  b.shapes.push_back({ShapeKind::Box, Vec3::Zero(), Quat::Identity(), Vec3(0.005, 0.005, 0.005)});
  MomentDesc md;
  md.permanent = true;
  md.volume = 1e-6;
  md.moment = m;
  b.moments.push_back(md);
  return b;
}

/// n³ balls in a cube lattice (pitch 2.05 r) resting on the ground below a cube magnet.
/// One magnetics thread and a cap of 200 iterations keep the tests fast on a busy machine;
/// these scenes test the engine, not the convergence of the dynamics.
inline SceneDesc pile_under_magnet(int n, double strength = 1.0) {
  SceneDesc s;
  s.name = "pile";
  s.options.magnetics.method = mag::Method::OursRealigned;
  s.options.threads = 1;
  s.options.magnetics.max_iter = 200;
  const double pitch = 2.05 * kR;
  const double top = kR + (n - 1) * pitch;
  s.bodies.push_back(cube_magnet(Vec3(0, 0, top + 0.02), Vec3(0, 0, strength)));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        s.bodies.push_back(iron_ball("ball_" + std::to_string(s.bodies.size() - 1),
                                     Vec3((i - 0.5 * (n - 1)) * pitch, (j - 0.5 * (n - 1)) * pitch,
                                          kR + k * pitch)));
  return s;
}

}  // namespace magsim::test
