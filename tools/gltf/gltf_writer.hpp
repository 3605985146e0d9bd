// tools/gltf/gltf_writer.hpp — a run as one binary glTF 2.0 file (.glb), from plain data: the
// bodies with their shapes, the poses of the moving ones per frame, and optional per-body
// scalar channels. No engine types, so that any front end (magsim-scene, a Python module)
// can fill it in.
//
// The file (tools/PROGRAMS.md, "The glTF file"):
// - axes: magsim is z-up, glTF y-up; every position, direction and quaternion vector part
//   (x, y, z) is written as (x, z, −y), which Blender's importer turns back exactly;
// - a node per body at its centre-of-mass pose, named after it, extras {"magsim_body": index,
//   "type", "mass", "moment" (A·m², body frame, magsim axes; bodies with permanent moments),
//   "induced_moments" (where there are any)};
//   under it a node per shape at its offset, whose mesh is shared by every shape of the same
//   kind, size (the components the kind uses) and colour;
// - materials from the renderer's colours (near-grey = metal, as render/shaders.cpp shades);
//   a ground quad; a camera node from the scene's camera;
// - one animation "run": every sampler takes its keys from ONE accessor of the frames'
//   simulated times; a translation and a rotation channel per moving body, LINEAR, with each
//   quaternion's sign chosen to be continuous with the previous key's;
// - channels: up to three per-body scalars per frame carried as the animated scale of a
//   childless node "<body>.channels" under the body: channel k in Blender's scale axis k (in
//   glTF's x, z, y, because the importer swaps y and z of a scale). Blender 3.4 reads scale
//   animation, not KHR_animation_pointer; an unused axis holds 1.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace magsim::gltf {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

enum class ShapeKind { Sphere, Box, Capsule, Cylinder };
const char* shape_kind_name(ShapeKind k);

/// A solid fixed to a body; capsules and cylinders lie along its local z.
struct Shape {
  ShapeKind kind = ShapeKind::Sphere;
  /// sphere {r, -, -}; box half extents; capsule/cylinder {r, half length of the axis, -} (m)
  Vec3 size = Vec3::Zero();
  Vec3 offset = Vec3::Zero();           ///< in the body's centre-of-mass frame (m)
  Quat rotation = Quat::Identity();     ///< in the body's frame
};

struct Body {
  std::string name;
  std::string type = "dynamic";         ///< "dynamic", "kinematic" or "static"
  double mass = 0.0;                    ///< kg (0 for static bodies)
  bool moves = true;                    ///< gets translation and rotation channels
  bool visible = true;                  ///< false: no shape nodes (an invisible moment)
  std::array<float, 3> color{0.55f, 0.56f, 0.58f};  ///< linear RGB
  bool has_moment = false;              ///< it carries permanent moments: extras "moment"
  Vec3 moment = Vec3::Zero();           ///< their sum (A·m², body frame)
  int induced_moments = 0;              ///< extras "induced_moments" when > 0
  Vec3 position = Vec3::Zero();         ///< centre of mass at rest or at the first frame (m)
  Quat orientation = Quat::Identity();
  std::vector<Shape> shapes;
};

struct Camera {
  Vec3 eye{0.5, -0.5, 0.4}, target{0, 0, 0}, up{0, 0, 1};
  double fov_y_deg = 40.0;
  double aspect = 16.0 / 9.0;
  double z_near = 0.0, z_far = 0.0;     ///< 0: chosen from the distance to the target
};

struct SceneInfo {
  std::string name;
  std::vector<Body> bodies;
  Camera camera;
  bool ground = true;
  double ground_height = 0.0;           ///< the plane z = ground_height (m)
  double ground_half_size = 1.0;        ///< half the side of the ground quad (m)
  std::array<float, 3> ground_color{0.85f, 0.85f, 0.82f};
  std::vector<std::string> channels;    ///< names of the per-body channels, at most 3
  nlohmann::json asset_extras = nlohmann::json::object();  ///< asset.extras: the run's outcome
};

/// A file is refused (bad input: exit 1 in magsim-scene): a path that is not a regular file
/// or a symlink to one, a size above the format's limit, a bad channel count.
struct Refused : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// Creating, writing or renaming failed (an I/O error: exit 3); nothing is left under the name.
struct WriteError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The frames of the run: times and poses of the moving bodies (Body::moves), channel values.
class Recording {
 public:
  Recording(const SceneInfo& scene);
  /// Appends a frame at time t (s, above the previous frame's): pos and quat of every body
  /// (nbody entries, the non-moving ones ignored), channels nbody × channels.size() values
  /// (body-major; empty without channels). Quaternions are stored with the sign nearest the
  /// previous key's.
  void add_frame(double t, const std::vector<Vec3>& pos, const std::vector<Quat>& quat,
                 const std::vector<double>& channels);
  std::size_t frames() const { return times_.size(); }
  const std::vector<double>& times() const { return times_; }
  /// (frame, moving index): z-up magsim axes, float
  const float* translation(std::size_t frame, std::size_t moving) const { return &trans_[(frame * moving_ + moving) * 3]; }
  const float* rotation(std::size_t frame, std::size_t moving) const { return &rot_[(frame * moving_ + moving) * 4]; }  // w x y z
  const float* channels(std::size_t frame, std::size_t body) const { return &chan_[(frame * bodies_ + body) * nchan_]; }
  std::size_t moving() const { return moving_; }
  std::size_t channel_count() const { return nchan_; }
  /// Bytes held per frame.
  static double bytes_per_frame(double moving, double bodies, double channels) {
    return 8.0 + moving * 28.0 + bodies * channels * 4.0;
  }

 private:
  std::vector<int> moving_index_;       // body → index among the moving bodies, −1
  std::size_t moving_ = 0, bodies_ = 0, nchan_ = 0;
  std::vector<double> times_;
  std::vector<float> trans_, rot_, chan_;
};

/// An upper bound of the file's size (bytes) for a scene of `bodies` bodies, `shapes` shapes of
/// `meshes` distinct kinds, sizes and colours, `moving` moving bodies, `frames` frames and
/// `channels` channels, with body names of at most 64 bytes on average.
double estimate_bytes(double bodies, double shapes, double meshes, double moving, double frames, double channels);
/// The largest .glb the format allows (its length fields are 32-bit): 4 GiB − 1.
constexpr double kMaxBytes = 4294967295.0;

/// The output file: a temporary file beside `path` made when it is opened (so a path that
/// cannot be written fails before a run), written and renamed over `path` by write(); removed
/// if write() is never called or fails. `path` may be absent (its missing folders are made),
/// a regular file (its permission bits are kept) or a symlink to one (the target is
/// replaced); anything else is Refused.
class GlbFile {
 public:
  explicit GlbFile(const std::string& path);
  ~GlbFile();
  GlbFile(const GlbFile&) = delete;
  GlbFile& operator=(const GlbFile&) = delete;
  /// Writes the scene and its recording and renames the file into place; returns its size
  /// (bytes). Throws WriteError (I/O) or Refused (over kMaxBytes, bad channels).
  std::uint64_t write(const SceneInfo& scene, const Recording& rec);
  const std::string& path() const { return path_; }

 private:
  std::string path_, target_, tmp_;
  unsigned mode_ = 0644;
  int fd_ = -1;
};

/// The JSON chunk and the binary chunk of the file (gltf_writer.cpp), for GlbFile::write.
struct GlbParts {
  std::string json;  ///< padded with spaces to a multiple of 4
  std::uint64_t bin_bytes = 0;
  /// Writes the binary chunk's body (bin_bytes bytes) to f; false on a write error.
  bool write_bin(std::FILE* f) const;
  std::vector<std::vector<unsigned char>> mesh_bytes;  // the meshes' data, in order
  const SceneInfo* scene = nullptr;
  const Recording* rec = nullptr;
};
GlbParts build_glb(const SceneInfo& scene, const Recording& rec);

}  // namespace magsim::gltf
