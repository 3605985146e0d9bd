// engine/model.hpp — the read-only Model compiled from a SceneDesc.
//
// compile_model() validates the description (std::invalid_argument naming the body and the
// field) and lays it out as structure-of-arrays, MuJoCo style: per-body mass properties,
// shapes and moments addressed by (adr, num) ranges, moments in body order so that moment
// j of the Model is moment j of the magnetics layer's MomentDesc (make_moment_desc), with
// group id = its body index.
//
// Body frame choice: the engine's body frame is the **centre-of-mass frame** — the
// BodyDesc frame translated by the centre of mass c (same orientation), because ODE needs
// the centre of mass at the body origin. Shape and moment offsets are stored relative to c;
// body_com keeps c (in the BodyDesc frame) so that the description's origin can be recovered:
//   p_origin = p_com − R c.
// Masses of overlapping shapes add up (no boolean union).
#pragma once

#include "engine/scene_desc.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace magsim::engine {

using Mat3 = Eigen::Matrix3d;

struct Model {
  // sizes
  int nbody = 0;
  int nshape = 0;
  int nmoment = 0;

  // options (validated)
  SimOptions options;
  /// The method resolved once, by compile_model: every stage reads these rather than working
  /// them out again from options.magnetics.method and options.force_model.
  struct Resolved {
    mag::Curve curve = mag::Curve::Tanh;               ///< the magnetization curve f
    mag::ForceModel force = mag::ForceModel::Classic;  ///< the force on induced moments
    bool force_has_energy = true;  ///< the force is −∇ of an energy, so the energy guard can check it
  } resolved;
  Vec3 H0 = Vec3::Zero();  ///< uniform external field (A/m)
  render::Camera camera;
  std::string name, description, modelling_level;
  double escape_radius = 0.0;  ///< SceneDesc::escape_radius (m), ≥ 0; 0 = not measured

  // bodies
  std::vector<std::string> body_name;         ///< (nbody)
  std::vector<BodyType> body_type;            ///< (nbody)
  std::vector<double> body_mass;              ///< (nbody) kg; 0 for static bodies
  std::vector<Mat3> body_inertia;             ///< (nbody) kg·m², about the COM, body axes
  std::vector<Vec3> body_com;                 ///< (nbody) COM in the BodyDesc frame (m)
  std::vector<Vec3> body_pos0;                ///< (nbody) initial COM position (m)
  std::vector<Quat> body_quat0;               ///< (nbody) initial orientation
  std::vector<Vec3> body_vel0;                ///< (nbody) initial COM velocity (m/s)
  std::vector<Vec3> body_angvel0;             ///< (nbody) initial angular velocity (rad/s)
  std::vector<render::Color> body_color;      ///< (nbody)
  std::vector<std::uint8_t> body_visible;     ///< (nbody)
  std::vector<std::uint8_t> body_magnet;      ///< (nbody) counts as "the magnet"
  std::vector<int> body_shape_adr;            ///< (nbody) first shape
  std::vector<int> body_shape_num;            ///< (nbody)
  std::vector<int> body_moment_adr;           ///< (nbody) first moment
  std::vector<int> body_moment_num;           ///< (nbody)
  std::vector<double> body_radius;            ///< (nbody) bounding radius about the COM (m)

  // shapes
  std::vector<ShapeKind> shape_kind;  ///< (nshape)
  std::vector<int> shape_body;        ///< (nshape)
  std::vector<Vec3> shape_offset;     ///< (nshape) position in the COM frame (m)
  std::vector<Quat> shape_rot;        ///< (nshape) orientation in the body frame
  std::vector<Vec3> shape_size;       ///< (nshape) as ShapeDesc::size (m)
  std::vector<double> shape_radius;   ///< (nshape) bounding radius about its centre (m)

  // moments
  std::vector<int> moment_body;              ///< (nmoment)
  std::vector<Vec3> moment_offset;           ///< (nmoment) position in the COM frame (m)
  std::vector<std::uint8_t> moment_permanent;  ///< (nmoment)
  std::vector<double> moment_volume;         ///< (nmoment) m³
  std::vector<double> moment_Ms;             ///< (nmoment) A/m (induced)
  std::vector<Vec3> moment_m;                ///< (nmoment) body-frame moment, A·m² (permanent)
  std::vector<double> moment_radius;         ///< (nmoment) (3V/4π)^{1/3}, for arrows (m)
  /// (nmoment) interaction radius of the bounded pairs (m), MomentDesc::interaction_radius
  /// resolved
  std::vector<double> moment_interaction_radius;

  // derived
  double contact_margin = 0.0;      ///< resolved SimOptions::contact_margin (m), ≥ 0
  /// smallest inscribed radius of a dynamic body's shapes (m): the length the sub-step
  /// criterion measures motion in (SimOptions::max_substeps); 0 without dynamic shapes
  double min_dynamic_radius = 0.0;
  std::vector<int> dynamic_bodies;  ///< indices of the dynamic bodies, ascending
  int induced_count = 0;
  bool dynamic_moments = false;  ///< some moment sits on a dynamic body (forces are needed)
};

/// Validates `scene` and compiles it. Throws std::invalid_argument with a one-line message
/// naming the body (index and name) and the field, e.g.
///   "body 3 'ball_3': shapes[0].size: sphere radius must be > 0 (got -0.01)".
Model compile_model(const SceneDesc& scene);

/// Empty when the camera can render, else why not: eye and target at one point (nothing to
/// look along: blank frames), or up zero or parallel to the view direction (no roll).
std::string camera_error(const render::Camera& c);

/// Mass properties of one shape of density ρ about its own centre, in its own axes:
/// returns the volume (m³) and writes I/ρ (m⁵) to *inertia_per_density.
double shape_volume_inertia(ShapeKind kind, const Vec3& size, Mat3* inertia_per_density);

/// Bounding radius of a shape about its centre (m).
double shape_bounding_radius(ShapeKind kind, const Vec3& size);

}  // namespace magsim::engine
