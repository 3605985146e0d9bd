// scenes/moment_set.cpp — a scene's moments at their initial poses.
#include "scenes/moment_set.hpp"

namespace magsim::scenes {

mag::MomentSet moment_set_at_rest(const engine::SceneDesc& scene) {
  mag::MomentSet set;
  set.H0 = scene.H0;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const engine::BodyDesc& body = scene.bodies[b];
    const Eigen::Matrix3d R = body.orientation.normalized().toRotationMatrix();
    for (const engine::MomentDesc& m : body.moments) {
      const mag::Vec3 p = body.position + R * m.offset;
      const auto grp = static_cast<std::int32_t>(b);
      if (m.permanent) set.add_permanent(p, m.volume, R * m.moment, grp);
      else set.add_induced(p, m.volume, m.Ms, grp);
    }
  }
  return set;
}

}  // namespace magsim::scenes
