// tools/cli/magsim_scene/gltf_output.cpp — the engine's bodies, shapes, camera and frames as
// the glTF writer's plain data (gltf_output.hpp).
#include "tools/cli/magsim_scene/gltf_output.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

namespace magsim::scene_tool {

namespace {

gltf::ShapeKind shape_kind(engine::ShapeKind k) {
  switch (k) {
    case engine::ShapeKind::Sphere: return gltf::ShapeKind::Sphere;
    case engine::ShapeKind::Box: return gltf::ShapeKind::Box;
    case engine::ShapeKind::Capsule: return gltf::ShapeKind::Capsule;
    case engine::ShapeKind::Cylinder: return gltf::ShapeKind::Cylinder;
  }
  return gltf::ShapeKind::Sphere;
}

struct Counts {
  double bodies = 0, shapes = 0, meshes = 0, moving = 0;
};

Counts counts(const engine::SceneDesc& s) {
  Counts c;
  std::set<std::tuple<int, double, double, double, float, float, float>> distinct;
  for (const engine::BodyDesc& b : s.bodies) {
    c.bodies += 1;
    if (b.type != engine::BodyType::Static) c.moving += 1;
    if (!b.visible) continue;
    for (const engine::ShapeDesc& sh : b.shapes) {
      c.shapes += 1;
      distinct.emplace(static_cast<int>(sh.kind), sh.size.x(), sh.size.y(), sh.size.z(), b.color.r, b.color.g, b.color.b);  // ≥ the file's
    }
  }
  c.meshes = static_cast<double>(distinct.size()) + 1;  // and the ground
  return c;
}

// the ground reaches 12 scene radii, as the renderer's (render/camera.cpp), or 20 times the
// camera's distance from the scene: the renderer fades its edge out, a plain quad cannot
double ground_half_size(const engine::Model& m) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (int b = 0; b < m.nbody; ++b) {
    if (!m.body_visible[b]) continue;
    lo = lo.cwiseMin(m.body_pos0[b] - Eigen::Vector3d::Constant(m.body_radius[b]));
    hi = hi.cwiseMax(m.body_pos0[b] + Eigen::Vector3d::Constant(m.body_radius[b]));
  }
  if (lo.x() > hi.x()) lo = hi = Eigen::Vector3d::Zero();
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-3);
  const double dist = (m.camera.eye.cast<double>() - centre).norm();
  return std::max(12 * radius, 20 * dist);
}

}  // namespace

std::vector<std::string> parse_gltf_channels(const std::string& list) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string name = list.substr(start, comma - start);
    bool known = false;
    for (const char* n : kGltfChannelNames) known = known || name == n;
    if (!known) throw UsageError("--gltf-channels: unknown channel '" + name + "'; known: m_norm, speed, spin");
    if (std::find(out.begin(), out.end(), name) != out.end())
      throw UsageError("--gltf-channels: '" + name + "' is named twice");
    out.push_back(name);
    start = comma + 1;
  }
  return out;
}

double check_gltf_size(const engine::SceneDesc& scene, double frames, std::size_t channels) {
  const Counts c = counts(scene);
  const double bytes = gltf::estimate_bytes(c.bodies, c.shapes, c.meshes, c.moving, frames, static_cast<double>(channels));
  if (bytes > gltf::kMaxBytes) {
    char msg[512];
    std::snprintf(msg, sizeof msg,
                  "--gltf: the file would take up to %.2f GB (%.0f bodies, %.0f of them moving, %.0f frames, %zu "
                  "channels: 28 bytes a moving body a frame%s), above glTF's limit of 4 GiB (4.29 GB); "
                  "record fewer frames (--fps, --seconds) or fewer bodies",
                  bytes / 1e9, c.bodies, c.moving, frames, channels, channels ? ", 12 a body a frame" : "");
    throw UsageError(msg);
  }
  return bytes;
}

double gltf_memory(const engine::SceneDesc& scene, double frames, std::size_t channels) {
  const Counts c = counts(scene);
  return frames * gltf::Recording::bytes_per_frame(c.moving, c.bodies, static_cast<double>(channels));
}

namespace {

gltf::SceneInfo scene_info(const RunPlan& a, const engine::Model& m, const std::vector<std::string>& channels) {
  gltf::SceneInfo s;
  s.name = m.name;
  s.channels = channels;
  for (int b = 0; b < m.nbody; ++b) {
    gltf::Body body;
    body.name = m.body_name[b];
    body.type = engine::kBodyTypeNames.name(m.body_type[b]);
    body.mass = m.body_mass[b];
    body.moves = m.body_type[b] != engine::BodyType::Static;
    body.visible = m.body_visible[b] != 0;
    body.color = {m.body_color[b].r, m.body_color[b].g, m.body_color[b].b};
    for (int j = m.body_moment_adr[b]; j < m.body_moment_adr[b] + m.body_moment_num[b]; ++j)
      if (m.moment_permanent[j]) {
        body.has_moment = true;
        body.moment += m.moment_m[j];
      } else {
        ++body.induced_moments;
      }
    body.position = m.body_pos0[b];
    body.orientation = m.body_quat0[b];
    for (int k = m.body_shape_adr[b]; k < m.body_shape_adr[b] + m.body_shape_num[b]; ++k) {
      gltf::Shape sh;
      sh.kind = shape_kind(m.shape_kind[k]);
      sh.size = m.shape_size[k];
      sh.offset = m.shape_offset[k];
      sh.rotation = m.shape_rot[k];
      body.shapes.push_back(sh);
    }
    s.bodies.push_back(std::move(body));
  }
  s.camera.eye = m.camera.eye.cast<double>();
  s.camera.target = m.camera.target.cast<double>();
  s.camera.up = m.camera.up.cast<double>();
  s.camera.fov_y_deg = m.camera.fov_y_deg;
  s.camera.aspect = static_cast<double>(a.width) / a.height;
  s.camera.z_near = m.camera.z_near;
  s.camera.z_far = m.camera.z_far;
  s.ground = m.options.ground;
  const render::Frame defaults;
  s.ground_height = defaults.ground_height;
  s.ground_color = {defaults.ground_color.r, defaults.ground_color.g, defaults.ground_color.b};
  s.ground_half_size = ground_half_size(m);
  return s;
}

gltf::GlbFile open_file(const std::string& path) {
  try {
    return gltf::GlbFile(path);
  } catch (const gltf::Refused& e) {
    throw UsageError("--gltf " + path + ": " + e.what());
  } catch (const gltf::WriteError& e) {
    throw IoError("--gltf " + path + ": " + e.what());
  }
}

}  // namespace

GltfOutput::GltfOutput(const RunPlan& a, const engine::Model& m)
    : model_(m), scene_(scene_info(a, m, a.gltf_channels.empty() ? std::vector<std::string>{} : parse_gltf_channels(a.gltf_channels))),
      rec_(scene_),
      file_(open_file(a.gltf)) {
  for (const std::string& c : scene_.channels)
    for (int i = 0; i < 3; ++i)
      if (c == kGltfChannelNames[i]) channel_ids_.push_back(i);
}

void GltfOutput::frame(const engine::Simulation& sim) {
  const engine::State& s = sim.state();
  values_.clear();
  for (int b = 0; b < model_.nbody && !channel_ids_.empty(); ++b)
    for (int id : channel_ids_) {
      if (id == 0) {
        engine::Vec3 total = engine::Vec3::Zero();
        for (int j = model_.body_moment_adr[b]; j < model_.body_moment_adr[b] + model_.body_moment_num[b]; ++j)
          total += mag::moment(sim.moments(), s.mag, static_cast<std::size_t>(j));
        values_.push_back(total.norm());
      } else {
        values_.push_back(id == 1 ? s.vel[b].norm() : s.angvel[b].norm());
      }
    }
  rec_.add_frame(sim.time(), s.pos, s.quat, values_);
}

std::uint64_t GltfOutput::write(const nlohmann::json& extras) {
  scene_.asset_extras = extras;
  try {
    return file_.write(scene_, rec_);
  } catch (const std::runtime_error& e) {  // Refused (over 4 GiB after all) or WriteError
    throw IoError("--gltf " + file_.path() + ": " + e.what());
  }
}

}  // namespace magsim::scene_tool
