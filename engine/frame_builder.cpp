// engine/frame_builder.cpp — shapes at world poses, magnetization arrows, camera.
#include "engine/frame_builder.hpp"

namespace magsim::engine {

namespace {

render::ShapeType render_type(ShapeKind k) {
  switch (k) {
    case ShapeKind::Sphere: return render::ShapeType::Sphere;
    case ShapeKind::Box: return render::ShapeType::Box;
    case ShapeKind::Capsule: return render::ShapeType::Capsule;
    case ShapeKind::Cylinder: return render::ShapeType::Cylinder;
  }
  return render::ShapeType::Sphere;
}

render::Arrow arrow(const Vec3& origin, const Vec3& vec, render::Color c) {
  render::Arrow a;
  a.origin = origin.cast<float>();
  a.vec = vec.cast<float>();
  a.color = c;
  return a;
}

}  // namespace

render::Frame build_frame(const Model& m, const State& s, const FrameOptions& opt) {
  render::Frame f;
  f.camera = m.camera;
  f.ground = m.options.ground;
  f.shapes.reserve(m.nshape);
  for (int b = 0; b < m.nbody; ++b) {
    if (!m.body_visible[b]) continue;
    const Quat& q = s.quat[b];
    for (int k = m.body_shape_adr[b]; k < m.body_shape_adr[b] + m.body_shape_num[b]; ++k) {
      render::Shape sh;
      sh.type = render_type(m.shape_kind[k]);
      sh.position = (s.pos[b] + q * m.shape_offset[k]).cast<float>();
      sh.orientation = (q * m.shape_rot[k]).cast<float>();
      sh.size = m.shape_size[k].cast<float>();
      sh.color = m.body_color[b];
      f.shapes.push_back(sh);
    }
  }
  if (opt.magnetization_arrows || opt.permanent_arrows) {
    for (int j = 0; j < m.nmoment; ++j) {
      const int b = m.moment_body[j];
      const Vec3 p = s.pos[b] + s.quat[b] * m.moment_offset[j];
      const double len = opt.arrow_scale * m.moment_radius[j];
      if (m.moment_permanent[j]) {
        const Vec3 mw = s.quat[b] * m.moment_m[j];
        if (opt.permanent_arrows && mw.norm() > 0)
          f.arrows.push_back(arrow(p, len * mw.normalized(), {0.1f, 0.75f, 0.2f}));
      } else if (opt.magnetization_arrows && s.mag.seeded[j]) {
        const double Ms = m.moment_Ms[j];
        f.arrows.push_back(arrow(p, (len / Ms) * s.mag.M1[j], {0.9f, 0.1f, 0.1f}));
        f.arrows.push_back(arrow(p, (len / Ms) * s.mag.M2[j], {0.1f, 0.2f, 0.9f}));
      }
    }
  }
  return f;
}

}  // namespace magsim::engine
