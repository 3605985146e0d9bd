// tools/gltf/gltf_writer.cpp — the recording, the glTF JSON and binary chunks, and the file
// written beside its name and renamed (gltf_writer.hpp).
#include "tools/gltf/gltf_writer.hpp"

#include "tools/gltf/gltf_meshes.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <tuple>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace magsim::gltf {

using nlohmann::json;

const char* shape_kind_name(ShapeKind k) {
  switch (k) {
    case ShapeKind::Sphere: return "sphere";
    case ShapeKind::Box: return "box";
    case ShapeKind::Capsule: return "capsule";
    case ShapeKind::Cylinder: return "cylinder";
  }
  return "sphere";
}

Recording::Recording(const SceneInfo& scene)
    : bodies_(scene.bodies.size()), nchan_(scene.channels.size()) {
  if (nchan_ > 3) throw Refused("at most 3 channels, got " + std::to_string(nchan_));
  for (const Body& b : scene.bodies) moving_index_.push_back(b.moves ? static_cast<int>(moving_++) : -1);
}

void Recording::add_frame(double t, const std::vector<Vec3>& pos, const std::vector<Quat>& quat,
                          const std::vector<double>& channels) {
  if (!times_.empty() && !(t > times_.back())) throw std::invalid_argument("glTF frames: times must increase");
  if (pos.size() != bodies_ || quat.size() != bodies_ || channels.size() != bodies_ * nchan_)
    throw std::invalid_argument("glTF frames: one pose per body and the channels of every body");
  const bool first = times_.empty();
  times_.push_back(t);
  for (std::size_t b = 0; b < bodies_; ++b) {
    const int k = moving_index_[b];
    if (k < 0) continue;
    for (int i = 0; i < 3; ++i) trans_.push_back(static_cast<float>(pos[b][i]));
    float q[4] = {static_cast<float>(quat[b].w()), static_cast<float>(quat[b].x()), static_cast<float>(quat[b].y()),
                  static_cast<float>(quat[b].z())};
    if (!first) {  // the sign nearest the previous key: LINEAR interpolation takes the short way
      const float* p = &rot_[((times_.size() - 2) * moving_ + static_cast<std::size_t>(k)) * 4];
      if (p[0] * q[0] + p[1] * q[1] + p[2] * q[2] + p[3] * q[3] < 0)
        for (float& c : q) c = -c;
    }
    rot_.insert(rot_.end(), q, q + 4);
  }
  for (double c : channels) chan_.push_back(static_cast<float>(c));
}

double estimate_bytes(double bodies, double shapes, double meshes, double moving, double frames, double channels) {
  // binary: a mesh is at most 34 rings of 32 vertices (24 B) and 1024 triangles (12 B); per
  // frame a time, per moving body a translation and a rotation, per body a channel vector.
  // JSON: measured sizes of a node, accessor, sampler and channel, doubled, plus the names
  const double helpers = channels > 0 ? bodies : 0;
  const double bin = meshes * (34 * 32 * 24 + 1024 * 12 + 64) + 4 * frames + 28 * moving * frames +
                     12 * helpers * frames;
  const double text = 16384 + 2048 * meshes + 2 * (300 * bodies + 200 * shapes + 200 * helpers) +
                      64 * (bodies + shapes + helpers) + 2 * 520 * moving + 2 * 260 * helpers;
  return 28 + bin + text;
}

namespace {

// glTF's component types and buffer-view targets
constexpr int kFloat = 5126, kUint = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }
json quat_xyzw(const Quat& q) { return json::array({q.x(), q.y(), q.z(), q.w()}); }

// the renderer's material rule (render/shaders.cpp, material_metal): near-grey is metal
double metalness(const std::array<float, 3>& c) {
  const double mx = std::max({c[0], c[1], c[2]}), mn = std::min({c[0], c[1], c[2]});
  const double sat = (mx - mn) / std::max(mx, 1e-4);
  const double x = std::clamp((sat - 0.06) / (0.25 - 0.06), 0.0, 1.0);
  return 1.0 - x * x * (3 - 2 * x);
}

// A camera's node rotation in glTF's axes: glTF cameras look along their local −z with +y up,
// so the columns are the world's right, up and backward directions (converted as vectors; the
// camera's own frame is glTF's by definition and is not converted).
Quat camera_rotation(const Camera& c) {
  const Vec3 f = (c.target - c.eye).normalized();
  Vec3 r = f.cross(c.up);
  if (r.norm() < 1e-12) r = f.unitOrthogonal();
  r.normalize();
  const Vec3 u = r.cross(f);
  Eigen::Matrix3d m;
  m.col(0) = to_gltf(r);
  m.col(1) = to_gltf(u);
  m.col(2) = to_gltf(Vec3(-f));
  return Quat(m).normalized();
}

// the size components that shape a kind (a sphere's radius; a capsule's or cylinder's radius
// and half length), the others 0: shapes that differ only in unused components share a mesh
Vec3 used_size(ShapeKind kind, const Vec3& size) {
  switch (kind) {
    case ShapeKind::Sphere: return Vec3(size.x(), 0, 0);
    case ShapeKind::Capsule:
    case ShapeKind::Cylinder: return Vec3(size.x(), size.y(), 0);
    case ShapeKind::Box: break;
  }
  return size;
}

// strictly increasing float keys: a time that rounds onto the previous one is moved up by
// one float step (only when frames are closer than float precision)
std::vector<float> key_times(const std::vector<double>& t) {
  std::vector<float> k(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    k[i] = static_cast<float>(t[i]);
    if (i > 0 && !(k[i] > k[i - 1])) k[i] = std::nextafter(k[i - 1], INFINITY);
  }
  return k;
}

}  // namespace

GlbParts build_glb(const SceneInfo& scene, const Recording& rec) {
  if (scene.channels.size() > 3) throw Refused("at most 3 channels, got " + std::to_string(scene.channels.size()));
  GlbParts parts;
  parts.scene = &scene;
  parts.rec = &rec;
  json j;
  j["asset"] = {{"version", "2.0"}, {"generator", "magsim"}, {"extras", scene.asset_extras}};
  json buffer_views = json::array(), accessors = json::array(), meshes = json::array(), materials = json::array();
  json nodes = json::array();
  std::uint64_t offset = 0;
  auto view = [&](std::uint64_t bytes, int target) {
    json v{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
    if (target) v["target"] = target;
    buffer_views.push_back(v);
    offset += bytes;
    return static_cast<int>(buffer_views.size() - 1);
  };

  // materials: one per colour
  std::map<std::array<float, 3>, int> material_of;
  auto material = [&](const std::array<float, 3>& c, const std::string& name, double metal, double rough) {
    const auto it = material_of.find(c);
    if (it != material_of.end() && name.empty()) return it->second;
    materials.push_back({{"name", name.empty() ? "magsim " + std::to_string(materials.size()) : name},
                         {"pbrMetallicRoughness",
                          {{"baseColorFactor", {c[0], c[1], c[2], 1.0}}, {"metallicFactor", metal}, {"roughnessFactor", rough}}}});
    const int m = static_cast<int>(materials.size() - 1);
    if (name.empty()) material_of[c] = m;
    return m;
  };
  // meshes: one per kind, size and colour
  using MeshKey = std::tuple<int, double, double, double, std::array<float, 3>>;
  std::map<MeshKey, int> mesh_of;
  auto add_mesh = [&](const MeshData& d, const std::string& name, int mat) {
    const std::uint64_t vb = d.positions.size() * 4, ib = d.indices.size() * 4;
    std::vector<unsigned char> bytes(2 * vb + ib);
    std::memcpy(bytes.data(), d.positions.data(), vb);
    std::memcpy(bytes.data() + vb, d.normals.data(), vb);
    std::memcpy(bytes.data() + 2 * vb, d.indices.data(), ib);
    parts.mesh_bytes.push_back(std::move(bytes));
    json lo = {d.positions[0], d.positions[1], d.positions[2]}, hi = lo;
    for (std::size_t v = 0; v < d.vertices(); ++v)
      for (int i = 0; i < 3; ++i) {
        lo[i] = std::min(lo[i].get<float>(), d.positions[3 * v + i]);
        hi[i] = std::max(hi[i].get<float>(), d.positions[3 * v + i]);
      }
    const int pv = view(vb, kArrayBuffer), nv = view(vb, kArrayBuffer), iv = view(ib, kElementArrayBuffer);
    accessors.push_back({{"bufferView", pv}, {"componentType", kFloat}, {"count", d.vertices()}, {"type", "VEC3"},
                         {"min", lo}, {"max", hi}});
    accessors.push_back({{"bufferView", nv}, {"componentType", kFloat}, {"count", d.vertices()}, {"type", "VEC3"}});
    accessors.push_back({{"bufferView", iv}, {"componentType", kUint}, {"count", d.indices.size()}, {"type", "SCALAR"}});
    const int a = static_cast<int>(accessors.size());
    meshes.push_back({{"name", name},
                      {"primitives", {{{"attributes", {{"POSITION", a - 3}, {"NORMAL", a - 2}}}, {"indices", a - 1},
                                       {"material", mat}}}}});
    return static_cast<int>(meshes.size() - 1);
  };

  // a node per body (node b = body b), then the shape and channel nodes under them
  const std::size_t nb = scene.bodies.size();
  nodes = json::array();
  for (std::size_t b = 0; b < nb; ++b) nodes.push_back(json::object());
  std::vector<int> helper(nb, -1);
  for (std::size_t b = 0; b < nb; ++b) {
    const Body& body = scene.bodies[b];
    json extras{{"magsim_body", b}, {"type", body.type}, {"mass", body.mass}};
    if (body.has_moment) extras["moment"] = vec(body.moment);
    if (body.induced_moments > 0) extras["induced_moments"] = body.induced_moments;
    if (!body.visible) extras["visible"] = false;
    json node{{"name", body.name}, {"translation", vec(to_gltf(body.position))},
              {"rotation", quat_xyzw(to_gltf(body.orientation.normalized()))}, {"extras", extras}};
    json children = json::array();
    if (body.visible)
      for (std::size_t k = 0; k < body.shapes.size(); ++k) {
        const Shape& s = body.shapes[k];
        const Vec3 size = used_size(s.kind, s.size);
        const MeshKey key{static_cast<int>(s.kind), size.x(), size.y(), size.z(), body.color};
        auto it = mesh_of.find(key);
        if (it == mesh_of.end()) {
          char name[160];
          std::snprintf(name, sizeof name, "%s %g %g %g", shape_kind_name(s.kind), size.x(), size.y(), size.z());
          it = mesh_of.emplace(key, add_mesh(shape_mesh(s.kind, size), name,
                                             material(body.color, "", metalness(body.color),
                                                      0.5 - 0.2 * metalness(body.color)))).first;
        }
        json sn{{"name", body.name + "." + shape_kind_name(s.kind) + std::to_string(k)}, {"mesh", it->second},
                {"extras", {{"shape", shape_kind_name(s.kind)}, {"size", vec(size)}}}};
        if (!s.offset.isZero()) sn["translation"] = vec(to_gltf(s.offset));
        if (!s.rotation.coeffs().isApprox(Quat::Identity().coeffs(), 0.0)) sn["rotation"] = quat_xyzw(to_gltf(s.rotation));
        children.push_back(nodes.size());
        nodes.push_back(sn);
      }
    if (!scene.channels.empty()) {
      helper[b] = static_cast<int>(nodes.size());
      children.push_back(nodes.size());
      nodes.push_back({{"name", body.name + ".channels"}, {"extras", {{"magsim_channels", scene.channels}}}});
    }
    if (!children.empty()) node["children"] = children;
    nodes[b] = node;
  }
  json roots = json::array();
  for (std::size_t b = 0; b < nb; ++b) roots.push_back(b);
  if (scene.ground) {
    const int m = material(scene.ground_color, "ground", 0.0, 0.9);
    const int mesh = add_mesh(ground_mesh(scene.ground_half_size, scene.ground_height), "ground", m);
    roots.push_back(nodes.size());
    nodes.push_back({{"name", "ground"}, {"mesh", mesh}, {"extras", {{"magsim_ground", true}}}});
  }
  {
    const Camera& c = scene.camera;
    const double dist = std::max((c.eye - c.target).norm(), 1e-6);
    const double znear = c.z_near > 0 ? c.z_near : 0.01 * dist;
    const double zfar = c.z_far > 0 ? c.z_far : std::max(100 * dist, 4 * scene.ground_half_size);
    j["cameras"] = {{{"name", "camera"}, {"type", "perspective"},
                     {"perspective", {{"yfov", c.fov_y_deg * 3.14159265358979323846 / 180}, {"aspectRatio", c.aspect},
                                      {"znear", znear}, {"zfar", zfar}}}}};
    roots.push_back(nodes.size());
    // extras: the scene's camera in magsim's axes, to check the node against
    nodes.push_back({{"name", "camera"}, {"camera", 0}, {"translation", vec(to_gltf(c.eye))},
                     {"rotation", quat_xyzw(camera_rotation(c))},
                     {"extras", {{"magsim_camera", {{"eye", vec(c.eye)}, {"target", vec(c.target)}, {"up", vec(c.up)}}}}}});
  }

  // the animation: one key accessor, a translation and a rotation per moving body, a scale
  // per channel node
  const std::size_t nf = rec.frames();
  if (nf > 0 && (rec.moving() > 0 || !scene.channels.empty())) {
    const std::vector<float> keys = key_times(rec.times());
    const int tv = view(nf * 4, 0);
    accessors.push_back({{"bufferView", tv}, {"componentType", kFloat}, {"count", nf}, {"type", "SCALAR"},
                         {"min", {keys.front()}}, {"max", {keys.back()}}});
    const int time_acc = static_cast<int>(accessors.size() - 1);
    json samplers = json::array(), channels = json::array();
    auto animate = [&](int node, const char* path, int view_index, std::uint64_t byte_offset, const char* type) {
      accessors.push_back({{"bufferView", view_index}, {"byteOffset", byte_offset}, {"componentType", kFloat},
                           {"count", nf}, {"type", type}});
      samplers.push_back({{"input", time_acc}, {"output", accessors.size() - 1}, {"interpolation", "LINEAR"}});
      channels.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", node}, {"path", path}}}});
    };
    if (rec.moving() > 0) {
      const int av = view(rec.moving() * nf * 28, 0);
      std::size_t k = 0;
      for (std::size_t b = 0; b < nb; ++b) {
        if (!scene.bodies[b].moves) continue;
        animate(static_cast<int>(b), "translation", av, k * nf * 28, "VEC3");
        animate(static_cast<int>(b), "rotation", av, k * nf * 28 + nf * 12, "VEC4");
        ++k;
      }
    }
    if (!scene.channels.empty()) {
      const int cv = view(nb * nf * 12, 0);
      for (std::size_t b = 0; b < nb; ++b) animate(helper[b], "scale", cv, b * nf * 12, "VEC3");
    }
    j["animations"] = {{{"name", "run"}, {"samplers", samplers}, {"channels", channels}}};
  }
  parts.bin_bytes = offset;
  j["buffers"] = {{{"byteLength", offset}}};
  j["bufferViews"] = buffer_views;
  j["accessors"] = accessors;
  j["meshes"] = meshes;
  j["materials"] = materials;
  j["nodes"] = nodes;
  j["scenes"] = {{{"name", scene.name}, {"nodes", roots},
                  {"extras", {{"magsim_channels", scene.channels}}}}};
  j["scene"] = 0;
  parts.json = j.dump();
  while (parts.json.size() % 4) parts.json += ' ';
  return parts;
}

bool GlbParts::write_bin(std::FILE* f) const {
  for (const std::vector<unsigned char>& m : mesh_bytes)
    if (std::fwrite(m.data(), 1, m.size(), f) != m.size()) return false;
  const std::size_t nf = rec->frames();
  if (nf == 0 || (rec->moving() == 0 && scene->channels.empty())) return true;
  const std::vector<float> keys = key_times(rec->times());
  if (std::fwrite(keys.data(), 4, nf, f) != nf) return false;
  std::vector<float> buf;
  for (std::size_t k = 0; k < rec->moving(); ++k) {
    buf.clear();
    for (std::size_t i = 0; i < nf; ++i) {
      const float* t = rec->translation(i, k);
      buf.insert(buf.end(), {t[0], t[2], -t[1]});
    }
    for (std::size_t i = 0; i < nf; ++i) {
      const float* q = rec->rotation(i, k);  // w x y z → glTF's x y z w, axes converted
      buf.insert(buf.end(), {q[1], q[3], -q[2], q[0]});
    }
    if (std::fwrite(buf.data(), 4, buf.size(), f) != buf.size()) return false;
  }
  const std::size_t nc = rec->channel_count();
  if (nc > 0)
    for (std::size_t b = 0; b < scene->bodies.size(); ++b) {
      buf.clear();
      for (std::size_t i = 0; i < nf; ++i) {
        const float* c = rec->channels(i, b);
        // Blender's importer reads a scale (x, y, z) as (x, z, y): channel k lands on its axis k
        buf.insert(buf.end(), {c[0], nc > 2 ? c[2] : 1.0f, nc > 1 ? c[1] : 1.0f});
      }
      if (std::fwrite(buf.data(), 4, buf.size(), f) != buf.size()) return false;
    }
  return true;
}

// ---- the file ----------------------------------------------------------------------------

GlbFile::GlbFile(const std::string& path) : path_(path), target_(path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno != ENOENT) throw WriteError(std::string("cannot look at it (") + std::strerror(errno) + ")");
    const mode_t mask = ::umask(0);  // a new file gets what open(O_CREAT, 0666) would give it
    ::umask(mask);
    mode_ = 0666 & ~mask;
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    std::error_code ec;
    if (!parent.empty() && !std::filesystem::exists(parent, ec)) {
      std::filesystem::create_directories(parent, ec);
      if (ec) throw WriteError("cannot create the folder " + parent.string() + " (" + ec.message() + ")");
    }
  } else {
    const bool link = S_ISLNK(st.st_mode);
    if (link) {
      char real[PATH_MAX];
      if (!::realpath(path.c_str(), real) || ::stat(real, &st) != 0)
        throw Refused(std::string("is a symbolic link that leads to no file (") + std::strerror(errno) + ")");
      target_ = real;
    }
    if (!S_ISREG(st.st_mode)) throw Refused("exists and is not a regular file; it is not replaced");
    mode_ = st.st_mode & 07777;
  }
  const std::size_t slash = target_.rfind('/');
  const std::string dir = slash == std::string::npos ? "" : target_.substr(0, slash + 1);
  const std::string base = slash == std::string::npos ? target_ : target_.substr(slash + 1);
  tmp_ = dir + "." + base + ".XXXXXX";
  fd_ = ::mkstemp(tmp_.data());
  if (fd_ < 0) throw WriteError(std::string("cannot create a file beside it (") + std::strerror(errno) + ")");
}

GlbFile::~GlbFile() {
  if (fd_ >= 0) {
    ::close(fd_);
    ::unlink(tmp_.c_str());
  }
}

std::uint64_t GlbFile::write(const SceneInfo& scene, const Recording& rec) {
  if (fd_ < 0) throw WriteError("already written");
  const GlbParts parts = build_glb(scene, rec);
  const std::uint64_t total = 12 + 8 + parts.json.size() + 8 + parts.bin_bytes;
  if (static_cast<double>(total) > kMaxBytes)
    throw Refused("the file would be " + std::to_string(total) + " bytes, above glTF's limit of 4 GiB");
  const int fd = fd_;
  fd_ = -1;  // from here on this function closes and removes it
  auto fail = [&](const std::string& what, int err) {
    ::unlink(tmp_.c_str());
    throw WriteError(what + " (" + std::strerror(err) + ")");
  };
  std::FILE* f = ::fdopen(fd, "wb");
  if (!f) {
    const int err = errno;
    ::close(fd);
    fail("cannot write " + tmp_, err);
  }
  auto u32 = [&](std::uint64_t v) {
    const std::uint32_t x = static_cast<std::uint32_t>(v);  // little-endian, as on x86-64
    std::fwrite(&x, 4, 1, f);
  };
  errno = 0;
  u32(0x46546C67);  // "glTF"
  u32(2);
  u32(total);
  u32(parts.json.size());
  u32(0x4E4F534A);  // "JSON"
  std::fwrite(parts.json.data(), 1, parts.json.size(), f);
  u32(parts.bin_bytes);
  u32(0x004E4942);  // "BIN\0"
  const bool ok = parts.write_bin(f) && std::fflush(f) == 0 && !std::ferror(f);
  const int err = errno ? errno : EIO;
  if (::fchmod(fd, mode_) != 0 && ok) {
    const int e = errno;
    std::fclose(f);
    fail("cannot set the permissions of " + tmp_, e);
  }
  if (std::fclose(f) != 0 || !ok) fail("writing " + tmp_ + " failed", ok ? errno : err);
  if (::rename(tmp_.c_str(), target_.c_str()) != 0) fail("cannot rename " + tmp_ + " over it", errno);
  return total;
}

}  // namespace magsim::gltf
