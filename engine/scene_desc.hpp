// engine/scene_desc.hpp — a scene as plain data: bodies, shapes, moments,
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
/// The shape kinds of scene files.
inline constexpr mag::NameTable<ShapeKind, 4> kShapeKindNames{{{ShapeKind::Sphere, "sphere"},
                                                               {ShapeKind::Box, "box"},
                                                               {ShapeKind::Capsule, "capsule"},
                                                               {ShapeKind::Cylinder, "cylinder"}}};

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
  /// Interaction radius a (m) of the bounded pair interaction (mag::FieldOptions::
  /// bounded_pairs): two moments are never evaluated closer than a_i + a_j. < 0 = auto: the
  /// largest sphere about the moment inside a shape of its body (a ball: its radius; a box:
  /// the distance to its nearest face), 0 when no shape holds it; 0 = a point.
  double interaction_radius = -1.0;
};

enum class BodyType {
  Dynamic,    ///< moved by forces and contacts
  Kinematic,  ///< moved by its scripted velocity, not by forces (infinite mass in contacts)
  Static      ///< never moves: a geom without a body
};
/// The body types of scene files.
inline constexpr mag::NameTable<BodyType, 3> kBodyTypeNames{
    {{BodyType::Dynamic, "dynamic"}, {BodyType::Kinematic, "kinematic"}, {BodyType::Static, "static"}}};

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

/// The broad-phase names of scene files, --space and summary.json.
inline constexpr mag::NameTable<SpaceKind, 3> kSpaceNames{
    {{SpaceKind::Hash, "hash"}, {SpaceKind::SweepAndPrune, "sap"}, {SpaceKind::Simple, "simple"}}};
inline const char* space_name(SpaceKind k) { return kSpaceNames.name(k); }
/// Parses a broad-phase name; returns false (and leaves *out alone) on an unknown name.
inline bool parse_space(const std::string& name, SpaceKind* out) { return kSpaceNames.parse(name, out); }

/// Run options. Defaults are the engine's; each scene overrides what it needs. Every member,
/// and every member of DynamicsOptions and FieldOptions, is declared in the table of options
/// (engine/options_table.cpp), under its path as the scene-file key.
struct SimOptions {
  /// The magnetization solve: its method, Δt_m, β, tolerance, cap … (defaults in
  /// mag::DynamicsOptions, equal to the table's).
  mag::DynamicsOptions magnetics;
  /// Apply the Zeeman force pairwise antisymmetrized (mag::compute_forces): momentum is
  /// conserved. false (default) = the per-moment gradient of eq. 4, which breaks action =
  /// reaction: harmless against a fixed magnet, but in falling_magnet the dynamic magnet and
  /// the balls on it fly off together at 200 m/s, so that scene turns this on.
  bool reaction_symmetric_forces = false;
  /// Remove the net torque that the reaction-symmetric Zeeman forces leave (needs
  /// reaction_symmetric_forces; no effect on the classic and zeeman-total forces, which leave
  /// none). Those forces sum to zero, but not their torques (apply_forces.cpp): in
  /// falling_magnet about 0.2 N·m at ×1 and 1 N·m at ×3, where, with 40 QuickStep iterations,
  /// it rolls the magnet and its heap off across the floor. The correction is the
  /// least one that cancels it. Off in every registry scene: at ×1, over eight runs, it
  /// changes neither the balls thrown at the landing nor the control's rest
  /// (tools/findings/falling_magnet.md).
  bool balance_magnetic_torque = false;
  /// The force on induced moments; Method (the default) is the method's own pairing
  /// (mag::resolve_force_model, applied once by compile_model into Model::resolved).
  mag::ForceModel force_model = mag::ForceModel::Method;
  /// Energy guard, for conservative forces (classic, zeeman-total; eq. 4 has no energy and is
  /// never guarded): a rigid step whose E = K + U_g + U* rises by more than
  ///   energy_guard_tolerance · (K_start + K_end + |U*_start|) + energy_guard_floor
  /// is rolled back and retaken from its start in twice as many sub-steps, up to
  /// energy_guard_max_substeps, while each retake rises less than the one before; where E
  /// still rises, the attempt that rose least is kept and counted
  /// (EnergyAudit::guard_unresolved). A retake keeps the contacts' softness of the scene's
  /// own sub-steps (OdeBridge::collide). K the kinetic energy at the step's ends, U* the
  /// co-energy at its start: the energy in play. A resting pile's contacts make E jitter by
  /// ~1e-5–1e-4 of it per step (tools/findings/energy.md); the default sits above that.
  bool energy_guard = true;
  double energy_guard_tolerance = 1e-3;  ///< relative to K_start + K_end + |U*_start|, ≥ 0
  double energy_guard_floor = 1e-6;      ///< (J), ≥ 0
  int energy_guard_max_substeps = 32;    ///< in [1, 64]
  double dt = 1e-3;                ///< rigid step Δt_r (s), the frame step
  /// Adaptive rigid sub-steps: each frame of Δt_r is split into n ODE steps of Δt_r/n, each
  /// with its own magnetization solve (warm-started from the previous sub-step) and forces,
  ///   n = ⌈ max_b (|v_b| + |Δv_b|) Δt_r / (substep_reach · r_min) ⌉,  1 ≤ n ≤ max_substeps,
  /// over the dynamic bodies b that touched another body or the ground in the last frame
  /// (a body in free flight moves ballistically and does not split the frame), v_b the
  /// body's velocity at the frame's start, Δv_b its change over the last frame (it
  /// includes the contact forces, so a resting pile under a strong pull needs no sub-steps),
  /// r_min the smallest inscribed radius of a dynamic body's shapes: no touching body moves
  /// more than substep_reach · r_min per sub-step unless the cap binds. 1 = no sub-steps.
  int max_substeps = 1;
  double substep_reach = 0.25;     ///< fraction of r_min a body may cover per sub-step, > 0
  /// The load term of the sub-steps: also n ≥ ⌈√(a_b / (substep_reach · r_min)) Δt_r⌉ with
  /// a_b = |F_b|/m_b the magnetic acceleration of a touching body b in the last frame, so
  /// that a body pressed into its contacts by the magnet sinks at most substep_reach · r_min
  /// per sub-step where QuickStep leaves the load unbalanced (substeps.cpp). false = motion only.
  bool substep_load = true;
  Vec3 gravity = Vec3(0, 0, -9.81);  ///< (m/s²)
  bool ground = true;              ///< an infinite static plane z = 0
  double friction = 0.5;           ///< Coulomb μ; 0 = frictionless contacts
  /// Rolling resistance ρ (m): each contact resists rolling and spinning with a torque of at
  /// most ρ·N, N its normal force (ODE's dContactRolling; ρ = c_rr·r for a ball of radius r
  /// and rolling coefficient c_rr). Without it spheres on a plane roll for ever. 0 = none.
  double rolling_friction = 0.0;
  /// The same between two dynamic bodies (a ball rolling on a ball), ρ (m); 0 = none. Without
  /// it a ball hanging on one neighbour at a magnet rolls to and fro on it without loss: in
  /// sakura_tree such balls swing at up to 1.7 m/s and 800 rad/s a second after landing.
  /// Three more rows on every contact between bodies (QuickStep's cost grows with them).
  double rolling_friction_bodies = 0.0;
  /// Electrical conductivity σ (S/m) of the induced bodies: the eddy-current loss of a body
  /// whose flux density changes in its own frame (moving through a field's gradient,
  /// spinning against the field), P = σ a² V |Ḃ|² / 10 per moment (engine/eddy.cpp). No field,
  /// no loss. Iron 1.0e7; 0 = none.
  double eddy_conductivity = 0.0;
  double restitution = 0.0;        ///< bounce in [0, 1]
  double erp = 0.2;                ///< ODE error reduction parameter
  double cfm = 1e-9;               ///< ODE constraint force mixing
  int quickstep_iterations = 20;
  double quickstep_w = 1.3;        ///< QuickStep successive over-relaxation W, in (0, 2) (ODE's default 1.3)
  int max_contacts = 4;            ///< per geom pair
  /// broad phase; sweep and prune: collide 2.3 vs 3.7 ms (hash) on sakura_tree, 2500 balls,
  /// same contacts (they are sorted into a fixed order), so the same state hash
  /// (tests/engine/golden_hash_test.cpp checks sap, hash and simple)
  SpaceKind space = SpaceKind::SweepAndPrune;
  bool auto_disable = false;       ///< ODE auto-disable of resting bodies
  /// Sleeping islands (engine/sleep.cpp): an island of dynamic bodies joined by contacts falls
  /// asleep when every body's mean velocities over the last sleep_time/2 have given
  /// |v̄| + |ω̄| r_body < sleep_speed for sleep_time (jitter in place averages out);
  /// asleep, its bodies leave ODE's step and its moments stay field sources with their
  /// magnetization frozen. It wakes when an awake body touches it, or when the field at one of
  /// its moments has moved since it fell asleep by more than sleep_field_tolerance × |H| (at
  /// least that fraction of 0.01 Ms).
  bool sleep = false;
  double sleep_speed = 0.02;            ///< m/s
  double sleep_time = 0.1;              ///< s
  double sleep_field_tolerance = 0.02;  ///< relative
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
  /// blow-up guard (m/s): a dynamic body faster than this ends the run with a SimulationError
  /// (engine/safety.cpp) instead of running on until values turn non-finite. No scene's body
  /// legitimately comes near it: balls snapping onto a magnet reach 3 m/s at the registry
  /// strengths and 117–123 m/s in the 10× stress sweep (tests/stability/stress_test.cpp),
  /// hence 1000 rather than 100. 0 = off. (Kept last in the struct.)
  double max_body_speed = 1000.0;
};

struct SceneDesc {
  std::string name;
  std::string description;      ///< one line: what the scene shows
  std::string modelling_level;  ///< what is simplified (moments per body, shapes…)
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
