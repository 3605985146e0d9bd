// engine/scene_desc.hpp — a scene as plain data (STYLE.md §1): bodies, shapes, moments,
// materials and run options, defaults in-class, SI units in comments. A SceneDesc compiles
// into a read-only Model; everything that changes lives in State.
#pragma once

#include "magnetics/magnetization.hpp"
#include "render/frame.hpp"

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace magsim::engine {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

enum class ShapeKind { Sphere, Box, Capsule, Cylinder };

/// A collision + render primitive fixed to a body. Capsules/cylinders lie along local z.
struct ShapeDesc {
  ShapeKind kind = ShapeKind::Sphere;
  Vec3 offset = Vec3::Zero();           ///< position in the body frame (m)
  Quat rotation = Quat::Identity();     ///< orientation in the body frame
  /// sphere {r,-,-}; box half extents {hx,hy,hz}; capsule/cylinder {r, half length,-} (m)
  Vec3 size = Vec3(0.005, 0.005, 0.005);
};

/// A magnetic moment fixed to a body.
struct MomentDesc {
  Vec3 offset = Vec3::Zero();  ///< position in the body frame (m)
  bool permanent = false;
  double volume = 0.0;         ///< material volume the moment stands for (m³), > 0
  double Ms = 1.6e6;           ///< induced: saturation magnetization (A/m); iron 1.6e6
  Vec3 moment = Vec3::Zero();  ///< permanent: body-frame moment (A·m²)
};

enum class BodyType {
  Dynamic,    ///< moved by forces and contacts
  Kinematic,  ///< moved by its scripted velocity, not by forces (infinite mass in contacts)
  Static      ///< never moves: a geom without a body
};

struct BodyDesc {
  std::string name;
  BodyType type = BodyType::Dynamic;
  Vec3 position = Vec3::Zero();          ///< (m)
  Quat orientation = Quat::Identity();
  Vec3 velocity = Vec3::Zero();          ///< (m/s); kinematic: held constant
  Vec3 angular_velocity = Vec3::Zero();  ///< (rad/s); kinematic: held constant
  double density = 7870.0;               ///< (kg/m³) used when mass ≤ 0; iron 7870
  double mass = 0.0;                     ///< (kg) if > 0 overrides density·volume
  std::vector<ShapeDesc> shapes;
  std::vector<MomentDesc> moments;
  render::Color color{0.55f, 0.56f, 0.58f};
  bool visible = true;                   ///< e.g. the invisible moment of alphabets
  bool magnet = false;                   ///< counts as "the magnet" for attachment metrics
};

enum class SpaceKind { Hash, SweepAndPrune, Simple };

/// "hash", "sap", "simple" (scene files, --space, summary.json).
inline const char* space_name(SpaceKind k) {
  switch (k) {
    case SpaceKind::Hash: return "hash";
    case SpaceKind::SweepAndPrune: return "sap";
    case SpaceKind::Simple: return "simple";
  }
  return "?";
}
/// Parses a broad-phase name; returns false (and leaves *out alone) on an unknown name.
inline bool parse_space(const std::string& name, SpaceKind* out) {
  for (SpaceKind k : {SpaceKind::Hash, SpaceKind::SweepAndPrune, SpaceKind::Simple})
    if (name == space_name(k)) {
      *out = k;
      return true;
    }
  return false;
}

/// Run options. Defaults are the engine's; each scene overrides what it needs.
struct SimOptions {
  /// The paper's θ dynamics with the sub-pair re-aligned (DESIGN §6): the paper's literal
  /// update (Method::Ours) does not converge in weakly magnetized piles (balls_up: the cap
  /// every step, balls ejected), so the engine's default is the re-aligned one.
  mag::Method method = mag::Method::OursRealigned;
  /// Δt_m, β, tolerance, cap … (method is set from above). Scenes stop the sweeps at
  /// max |ΔM|/Ms < 1e-4 or 100 sweeps per rigid step: warm-started from the last step, a
  /// converging method needs a handful; a cap hit is counted in the profile.
  mag::DynamicsOptions magnetics = [] {
    mag::DynamicsOptions d;
    d.tol = 1e-4;
    d.max_iter = 100;
    return d;
  }();
  /// Apply the Zeeman force pairwise antisymmetrized (mag::compute_forces): momentum is
  /// conserved. false (default) = the per-moment gradient of eq. 4, which breaks action =
  /// reaction: harmless against a fixed magnet, but in falling_magnet the dynamic magnet and
  /// the balls on it fly off together at 200 m/s, so that scene turns this on.
  bool reaction_symmetric_forces = false;
  double dt = 1e-3;                ///< rigid step Δt_r (s)
  Vec3 gravity = Vec3(0, 0, -9.81);  ///< (m/s²)
  bool ground = true;              ///< an infinite static plane z = 0
  double friction = 0.5;           ///< Coulomb μ; 0 = frictionless contacts
  double restitution = 0.0;        ///< bounce in [0, 1]
  double erp = 0.2;                ///< ODE error reduction parameter
  double cfm = 1e-9;               ///< ODE constraint force mixing
  int quickstep_iterations = 20;
  int max_contacts = 4;            ///< per geom pair
  /// broad phase; sweep and prune: collide 2.3 vs 3.7 ms (hash) on sakura_tree, 2500 balls,
  /// same contacts (they are sorted into a fixed order), so the same state hash
  SpaceKind space = SpaceKind::SweepAndPrune;
  bool auto_disable = false;       ///< ODE auto-disable of resting bodies
  double linear_damping = 0.0;     ///< velocity decay rate c (1/s): v ← v·e^{−cΔt} per step; 0 = none
  double angular_damping = 0.0;    ///< the same for angular velocity (1/s)
  double surface_layer = 0.0;      ///< ODE contact surface layer: resting penetration allowed (m)
  /// cap on the velocity ODE uses to push penetrating bodies apart (m/s); 0 = unlimited
  double max_correcting_velocity = 0.0;
  /// speculative contact distance μ0 (m): shapes closer than this get a contact that lets
  /// them close the gap within the step but not pass it, so a body pulled hard toward a
  /// magnet cannot tunnel into or through it; a dynamic body's shapes also reach as far as
  /// the body can move in the step, (|v| + (|F|/m + |g|)Δt)Δt, up to 4 shape radii.
  /// < 0 = auto (¼ of the smallest shape radius), 0 = off
  double contact_margin = -1.0;
  int threads = 0;                 ///< OpenMP threads for magnetics (0 = all; 1 below 256 moments)
};

struct SceneDesc {
  std::string name;
  std::string description;      ///< one line: what the scene shows
  std::string modelling_level;  ///< DESIGN §2: what is simplified (moments per body, shapes…)
  std::vector<BodyDesc> bodies;
  Vec3 H0 = Vec3::Zero();       ///< uniform external field (A/m)
  SimOptions options;
  render::Camera camera;        ///< framed on the action
  double default_seconds = 2.0; ///< simulated time of a default run
  /// (m) "escaped" (Metrics::escaped) = a dynamic non-magnet body whose centre is farther
  /// than this from the centroid of the magnet bodies: horizontal (x, y) distance when the
  /// scene has gravity, 3-D distance without; 0 = not measured
  double escape_radius = 0.0;
};

}  // namespace magsim::engine
