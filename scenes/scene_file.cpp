// scenes/scene_file.cpp — scenes as JSON files (nlohmann::json), mirroring SceneDesc.
//
// Schema (every key optional unless marked; defaults are SceneDesc's; SI units; keys are
// the SceneDesc field names; "comment" is allowed in every object and ignored; // and /* */
// comments are allowed in the text). Full description with an example: SCENE_FILE.md.
//
//   {
//     "name": "two_balls",                      // default: the file name without .json
//     "description": "…", "modelling_level": "…",
//     "default_seconds": 2.0,                   // > 0 (s)
//     "escape_radius": 0,                       // >= 0 (m); 0 = "escaped" not measured
//     "H0": [0, 0, 0],                          // uniform external field (A/m)
//     "camera": {"eye": [x,y,z], "target": [x,y,z], "up": [x,y,z],
//                "fov_y_deg": 40, "z_near": 0, "z_far": 0},
//     "options": {
//       "method": "ours" | "ours-realigned" | "kim2018" | "damping-llg" | "exact",
//       "dt": 1e-3, "gravity": [0,0,-9.81], "ground": true, "friction": 0.5,
//       "restitution": 0, "erp": 0.2, "cfm": 1e-9, "quickstep_iterations": 20,
//       "max_contacts": 4, "space": "sap" | "hash" | "simple", "auto_disable": false,
//       "linear_damping": 0, "angular_damping": 0, "surface_layer": 0,
//       "max_correcting_velocity": 0, "contact_margin": -1, "threads": 0,
//       "force_model": "method" | "zeeman" | "classic", "max_substeps": 1,
//       "substep_reach": 0.25, "rolling_friction": 0, "quickstep_w": 1.3,
//       "field_solver": "direct" | "barnes-hut" | "auto", "bh_theta": 0.3,  // (0, 1]
//       "bh_threshold": 2500,                   // auto: Barnes–Hut from this many moments
//       "max_body_speed": 1000,                 // blow-up guard (m/s), 0 = off
//       "magnetics": {"dt": 1e-7, "beta": 5, "alpha": 0.2, "gamma_c_max": 1,
//                     "adaptive_gamma_bound": true, "adaptive_gamma_cap": 2.5,
//                     "tol": 1e-4, "max_iter": 100, "min_pair_angle": 1e-6,
//                     "theta_integrator": "exact" | "euler", "softening": 0,
//                     "bounded_pairs": false}
//     },
//     "bodies": [                               // required
//       {"name": "ball_0", "type": "dynamic" | "kinematic" | "static",
//        "position": [x,y,z], "orientation": [w,x,y,z],
//        "velocity": [..], "angular_velocity": [..],
//        "density": 7870, "mass": 0,            // mass > 0 overrides density·volume
//        "color": [r,g,b], "visible": true, "magnet": false,
//        "shapes": [{"kind": "sphere" | "box" | "capsule" | "cylinder",
//                    "offset": [x,y,z], "rotation": [w,x,y,z],
//                    "size": r | [r] | [hx,hy,hz] | [r, half_length]}],
//        "moments": [{"offset": [x,y,z], "permanent": false, "volume": V,   // V > 0 (m³)
//                     "Ms": 1.6e6,               // induced only (A/m)
//                     "moment": [mx,my,mz],      // permanent only (A·m², body frame)
//                     "interaction_radius": -1}]} // bounded pairs (m); < 0 = from the shape
//     ]
//   }
//
// Errors are one line: "<file>: <json path>: <what>", e.g.
//   "scene.json: bodies[3].shapes[0].size: must be 3 positive numbers (half extents)".
#include "scenes/scene_file.hpp"

#include "engine/limits.hpp"
#include "engine/model.hpp"
#include "magnetics/magnetization.hpp"
#include "scenes/json_unique_keys.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <stdexcept>

namespace magsim::scenes {

using engine::BodyDesc;
using engine::BodyType;
using engine::MomentDesc;
using engine::Quat;
using engine::SceneDesc;
using engine::ShapeDesc;
using engine::ShapeKind;
using engine::SimOptions;
using engine::SpaceKind;
using engine::Vec3;
using json = nlohmann::json;

namespace {

class Reader {
 public:
  explicit Reader(std::string origin) : origin_(std::move(origin)) {}

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw std::runtime_error(origin_ + ": " + (path.empty() ? "" : path + ": ") + what);
  }

  // objects and their keys
  void object(const json& j, const std::string& path) const {
    if (!j.is_object()) fail(path.empty() ? "(top level)" : path, "must be an object");
  }
  void keys(const json& j, const std::string& path, std::initializer_list<const char*> allowed) const {
    object(j, path);
    for (auto it = j.begin(); it != j.end(); ++it) {
      bool ok = it.key() == "comment";
      for (const char* a : allowed) ok = ok || it.key() == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail(join(path, it.key()), "unknown key (allowed: " + list + ")");
      }
    }
  }
  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  static std::string index(const std::string& path, std::size_t i) {
    return path + "[" + std::to_string(i) + "]";
  }

  // scalars
  double number(const json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, "must be a number");
    const double x = j.get<double>();
    if (!std::isfinite(x)) fail(path, "must be finite");
    return x;
  }
  double positive(const json& j, const std::string& path) const {
    const double x = number(j, path);
    if (!(x > 0)) fail(path, "must be > 0 (got " + fmt(x) + ")");
    return x;
  }
  double non_negative(const json& j, const std::string& path) const {
    const double x = number(j, path);
    if (!(x >= 0)) fail(path, "must be >= 0 (got " + fmt(x) + ")");
    return x;
  }
  double in_range(const json& j, const std::string& path, double lo, double hi) const {
    const double x = number(j, path);
    if (!(x >= lo && x <= hi)) fail(path, "must be in [" + fmt(lo) + ", " + fmt(hi) + "] (got " + fmt(x) + ")");
    return x;
  }
  int integer(const json& j, const std::string& path, int lo, int hi) const {
    if (!j.is_number_integer()) fail(path, "must be an integer");
    const long long x = j.get<long long>();
    if (x < lo || x > hi)
      fail(path, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " + std::to_string(x) + ")");
    return static_cast<int>(x);
  }
  // engine/limits.hpp: finite magnitudes beyond what ODE (or the magnetics) can take
  void at_most(const std::string& path, double magnitude, double max, const char* unit) const {
    if (magnitude > max)
      fail(path, "magnitude " + fmt(magnitude) + " " + unit + " exceeds " + fmt(max) + " " + unit +
                     " (engine/limits.hpp: beyond it the rigid-body or magnetics arithmetic overflows)");
  }
  Vec3 bounded(const json& j, const std::string& path, double max, const char* unit) const {
    const Vec3 v = vec3(j, path);
    at_most(path, v.stableNorm(), max, unit);
    return v;
  }
  bool boolean(const json& j, const std::string& path) const {
    if (!j.is_boolean()) fail(path, "must be true or false");
    return j.get<bool>();
  }
  std::string string(const json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, "must be a string");
    return j.get<std::string>();
  }

  // arrays of numbers
  std::vector<double> numbers(const json& j, const std::string& path, const std::string& want) const {
    if (!j.is_array()) fail(path, "must be " + want);
    std::vector<double> v;
    for (const json& x : j) {
      if (!x.is_number()) fail(path, "must be " + want);
      v.push_back(x.get<double>());
      if (!std::isfinite(v.back())) fail(path, "must be " + want + " (non-finite value)");
    }
    return v;
  }
  Vec3 vec3(const json& j, const std::string& path) const {
    const std::vector<double> v = numbers(j, path, "3 numbers [x, y, z]");
    if (v.size() != 3) fail(path, "must be 3 numbers [x, y, z]");
    return Vec3(v[0], v[1], v[2]);
  }
  Eigen::Vector3f vec3f(const json& j, const std::string& path) const { return vec3(j, path).cast<float>(); }
  Quat quat(const json& j, const std::string& path) const {
    const std::vector<double> v = numbers(j, path, "4 numbers [w, x, y, z]");
    if (v.size() != 4) fail(path, "must be 4 numbers [w, x, y, z]");
    const Quat q(v[0], v[1], v[2], v[3]);
    if (q.norm() < 1e-12) fail(path, "must be a non-zero quaternion [w, x, y, z]");
    return q.normalized();
  }
  render::Color color(const json& j, const std::string& path) const {
    const std::vector<double> v = numbers(j, path, "3 numbers [r, g, b] in [0, 1]");
    if (v.size() != 3) fail(path, "must be 3 numbers [r, g, b] in [0, 1]");
    for (double c : v)
      if (!(c >= 0 && c <= 1)) fail(path, "must be 3 numbers [r, g, b] in [0, 1]");
    return render::Color{static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])};
  }

  static std::string fmt(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
  }

 private:
  std::string origin_;
};

// A value of `key` in `obj` when present: f(value, path) is called with it.
template <class F>
void opt(const json& obj, const char* key, const std::string& path, F&& f) {
  const auto it = obj.find(key);
  if (it != obj.end()) f(*it, Reader::join(path, key));
}

ShapeKind shape_kind(const Reader& r, const json& j, const std::string& path) {
  const std::string s = r.string(j, path);
  if (s == "sphere") return ShapeKind::Sphere;
  if (s == "box") return ShapeKind::Box;
  if (s == "capsule") return ShapeKind::Capsule;
  if (s == "cylinder") return ShapeKind::Cylinder;
  r.fail(path, "unknown shape kind '" + s + "' (sphere, box, capsule, cylinder)");
}

BodyType body_type(const Reader& r, const json& j, const std::string& path) {
  const std::string s = r.string(j, path);
  if (s == "dynamic") return BodyType::Dynamic;
  if (s == "kinematic") return BodyType::Kinematic;
  if (s == "static") return BodyType::Static;
  r.fail(path, "unknown body type '" + s + "' (dynamic, kinematic, static)");
}

SpaceKind space_kind(const Reader& r, const json& j, const std::string& path) {
  const std::string s = r.string(j, path);
  SpaceKind k;
  if (engine::parse_space(s, &k)) return k;
  r.fail(path, "unknown space '" + s + "' (hash, sap, simple)");
}

mag::Method method(const Reader& r, const json& j, const std::string& path) {
  const std::string s = r.string(j, path);
  mag::Method m;
  if (!mag::parse_method(s, &m))
    r.fail(path, "unknown method '" + s + "' (ours, ours-realigned, kim2018, damping-llg, exact)");
  return m;
}

Vec3 shape_size(const Reader& r, ShapeKind kind, const json& j, const std::string& path) {
  switch (kind) {
    case ShapeKind::Sphere: {
      const char* want = "must be a positive radius (a number or [r])";
      if (j.is_number()) {
        const double x = r.number(j, path);
        if (!(x > 0)) r.fail(path, std::string(want) + " (got " + Reader::fmt(x) + ")");
        return Vec3(x, x, x);
      }
      const std::vector<double> v = r.numbers(j, path, "a positive radius (a number or [r])");
      if (v.size() != 1 || !(v[0] > 0)) r.fail(path, want);
      return Vec3(v[0], v[0], v[0]);
    }
    case ShapeKind::Box: {
      const char* want = "must be 3 positive numbers (half extents [hx, hy, hz])";
      const std::vector<double> v = r.numbers(j, path, "3 positive numbers (half extents [hx, hy, hz])");
      if (v.size() != 3 || !(v[0] > 0 && v[1] > 0 && v[2] > 0)) r.fail(path, want);
      return Vec3(v[0], v[1], v[2]);
    }
    case ShapeKind::Capsule:
    case ShapeKind::Cylinder: {
      const char* want = "must be 2 positive numbers [radius, half_length]";
      const std::vector<double> v = r.numbers(j, path, "2 positive numbers [radius, half_length]");
      if (v.size() != 2 || !(v[0] > 0 && v[1] > 0)) r.fail(path, want);
      return Vec3(v[0], v[1], 0.0);
    }
  }
  return Vec3::Zero();
}

ShapeDesc read_shape(const Reader& r, const json& j, const std::string& path) {
  r.keys(j, path, {"kind", "offset", "rotation", "size"});
  ShapeDesc s;
  opt(j, "kind", path, [&](const json& v, const std::string& p) { s.kind = shape_kind(r, v, p); });
  opt(j, "offset", path, [&](const json& v, const std::string& p) { s.offset = r.bounded(v, p, engine::limits::kMaxCoordinate, "m"); });
  opt(j, "rotation", path, [&](const json& v, const std::string& p) { s.rotation = r.quat(v, p); });
  if (!j.contains("size")) r.fail(Reader::join(path, "size"), "required");
  s.size = shape_size(r, s.kind, j.at("size"), Reader::join(path, "size"));
  r.at_most(Reader::join(path, "size"), s.size.cwiseAbs().maxCoeff(), engine::limits::kMaxSize, "m");
  return s;
}

MomentDesc read_moment(const Reader& r, const json& j, const std::string& path) {
  r.keys(j, path, {"offset", "permanent", "volume", "Ms", "moment", "interaction_radius"});
  MomentDesc m;
  opt(j, "offset", path, [&](const json& v, const std::string& p) { m.offset = r.bounded(v, p, engine::limits::kMaxCoordinate, "m"); });
  opt(j, "permanent", path, [&](const json& v, const std::string& p) { m.permanent = r.boolean(v, p); });
  if (!j.contains("volume")) r.fail(Reader::join(path, "volume"), "required (> 0, m³)");
  m.volume = r.positive(j.at("volume"), Reader::join(path, "volume"));
  r.at_most(Reader::join(path, "volume"), m.volume, engine::limits::kMaxVolume, "m^3");
  opt(j, "Ms", path, [&](const json& v, const std::string& p) {
    if (m.permanent) r.fail(p, "only for induced moments (\"permanent\": false)");
    m.Ms = r.positive(v, p);
    r.at_most(p, m.Ms, engine::limits::kMaxMs, "A/m");
  });
  opt(j, "moment", path, [&](const json& v, const std::string& p) {
    if (!m.permanent) r.fail(p, "only for permanent moments (\"permanent\": true)");
    m.moment = r.bounded(v, p, engine::limits::kMaxMoment, "A·m^2");
  });
  opt(j, "interaction_radius", path, [&](const json& v, const std::string& p) { m.interaction_radius = r.number(v, p); });
  // a permanent moment without "moment" used to load as a zero magnet
  if (m.permanent && !j.contains("moment"))
    r.fail(Reader::join(path, "moment"), "required for a permanent moment ([mx, my, mz], A·m², body frame)");
  return m;
}

BodyDesc read_body(const Reader& r, const json& j, const std::string& path, std::size_t i) {
  r.keys(j, path, {"name", "type", "position", "orientation", "velocity", "angular_velocity",
                   "density", "mass", "shapes", "moments", "color", "visible", "magnet"});
  BodyDesc b;
  b.name = "body_" + std::to_string(i);
  opt(j, "name", path, [&](const json& v, const std::string& p) { b.name = r.string(v, p); });
  opt(j, "type", path, [&](const json& v, const std::string& p) { b.type = body_type(r, v, p); });
  opt(j, "position", path, [&](const json& v, const std::string& p) { b.position = r.bounded(v, p, engine::limits::kMaxCoordinate, "m"); });
  opt(j, "orientation", path, [&](const json& v, const std::string& p) { b.orientation = r.quat(v, p); });
  opt(j, "velocity", path, [&](const json& v, const std::string& p) { b.velocity = r.bounded(v, p, engine::limits::kMaxSpeed, "m/s"); });
  opt(j, "angular_velocity", path, [&](const json& v, const std::string& p) {
    b.angular_velocity = r.bounded(v, p, engine::limits::kMaxAngularSpeed, "rad/s");
  });
  opt(j, "density", path, [&](const json& v, const std::string& p) { b.density = r.positive(v, p); });
  opt(j, "mass", path, [&](const json& v, const std::string& p) {
    b.mass = r.non_negative(v, p);
    if (b.mass > 0 && (b.mass < engine::limits::kMinMass || b.mass > engine::limits::kMaxMass))
      r.fail(p, "must be 0 (density x volume) or in [" + Reader::fmt(engine::limits::kMinMass) + ", " +
                    Reader::fmt(engine::limits::kMaxMass) + "] kg (got " + Reader::fmt(b.mass) +
                    "; engine/limits.hpp: beyond it ODE's arithmetic overflows)");
  });
  opt(j, "color", path, [&](const json& v, const std::string& p) { b.color = r.color(v, p); });
  opt(j, "visible", path, [&](const json& v, const std::string& p) { b.visible = r.boolean(v, p); });
  opt(j, "magnet", path, [&](const json& v, const std::string& p) { b.magnet = r.boolean(v, p); });
  opt(j, "shapes", path, [&](const json& v, const std::string& p) {
    if (!v.is_array()) r.fail(p, "must be an array of shapes");
    for (std::size_t k = 0; k < v.size(); ++k) b.shapes.push_back(read_shape(r, v[k], Reader::index(p, k)));
  });
  opt(j, "moments", path, [&](const json& v, const std::string& p) {
    if (!v.is_array()) r.fail(p, "must be an array of moments");
    for (std::size_t k = 0; k < v.size(); ++k) b.moments.push_back(read_moment(r, v[k], Reader::index(p, k)));
  });
  if (b.type == BodyType::Dynamic && b.shapes.empty())
    r.fail(Reader::join(path, "shapes"), "a dynamic body needs at least one shape");
  return b;
}

void read_magnetics(const Reader& r, const json& j, const std::string& path, mag::DynamicsOptions* d) {
  r.keys(j, path, {"dt", "beta", "alpha", "gamma_c_max", "adaptive_gamma_bound", "adaptive_gamma_cap",
                   "tol", "criterion", "max_iter", "min_pair_angle", "theta_integrator", "softening",
                   "bounded_pairs"});
  opt(j, "dt", path, [&](const json& v, const std::string& p) { d->dt = r.in_range(v, p, 1e-9, 1e-6); });
  opt(j, "beta", path, [&](const json& v, const std::string& p) { d->beta = r.positive(v, p); });
  opt(j, "alpha", path, [&](const json& v, const std::string& p) { d->alpha = r.in_range(v, p, 1e-12, 1.0); });
  opt(j, "gamma_c_max", path, [&](const json& v, const std::string& p) { d->gamma_c_max = r.in_range(v, p, 1.0 / 3.0, 1e12); });
  opt(j, "adaptive_gamma_bound", path, [&](const json& v, const std::string& p) { d->adaptive_gamma_bound = r.boolean(v, p); });
  opt(j, "adaptive_gamma_cap", path, [&](const json& v, const std::string& p) { d->adaptive_gamma_cap = r.positive(v, p); });
  opt(j, "tol", path, [&](const json& v, const std::string& p) { d->tol = r.in_range(v, p, 1e-300, 0.999999); });
  opt(j, "max_iter", path, [&](const json& v, const std::string& p) { d->max_iter = r.integer(v, p, 1, 100000000); });
  opt(j, "min_pair_angle", path, [&](const json& v, const std::string& p) { d->min_pair_angle = r.in_range(v, p, 1e-300, 0.0099999); });
  opt(j, "theta_integrator", path, [&](const json& v, const std::string& p) {
    const std::string s = r.string(v, p);
    if (s == "exact") d->theta_integrator = mag::ThetaIntegrator::Exact;
    else if (s == "euler") d->theta_integrator = mag::ThetaIntegrator::Euler;
    else r.fail(p, "unknown theta integrator '" + s + "' (exact, euler)");
  });
  opt(j, "criterion", path, [&](const json& v, const std::string& p) {
    const std::string s = r.string(v, p);
    if (s == "residual") d->criterion = mag::DynamicsOptions::Criterion::Residual;
    else if (s == "change") d->criterion = mag::DynamicsOptions::Criterion::Change;
    else r.fail(p, "unknown criterion '" + s + "' (residual, change)");
  });
  opt(j, "softening", path, [&](const json& v, const std::string& p) { d->field.softening = r.non_negative(v, p); });
  opt(j, "bounded_pairs", path, [&](const json& v, const std::string& p) { d->field.bounded_pairs = r.boolean(v, p); });
  const std::string e = mag::validate(*d);
  if (!e.empty()) r.fail(path, e);
}

void read_options(const Reader& r, const json& j, const std::string& path, SimOptions* o) {
  r.keys(j, path, {"method", "dt", "gravity", "ground", "friction", "restitution", "erp", "cfm",
                   "quickstep_iterations", "max_contacts", "space", "auto_disable", "linear_damping",
                   "angular_damping", "surface_layer", "max_correcting_velocity", "contact_margin",
                   "threads", "reaction_symmetric_forces", "field_solver", "bh_theta", "bh_threshold",
                   "magnetics", "force_model", "max_substeps", "substep_reach", "rolling_friction",
                   "quickstep_w", "max_body_speed"});
  opt(j, "method", path, [&](const json& v, const std::string& p) { o->method = method(r, v, p); });
  opt(j, "dt", path, [&](const json& v, const std::string& p) {
    o->dt = r.number(v, p);
    if (!(o->dt > 0 && o->dt <= 0.1)) r.fail(p, "must be in (0, 0.1] s (got " + Reader::fmt(o->dt) + ")");
  });
  opt(j, "gravity", path, [&](const json& v, const std::string& p) { o->gravity = r.bounded(v, p, engine::limits::kMaxGravity, "m/s^2"); });
  opt(j, "ground", path, [&](const json& v, const std::string& p) { o->ground = r.boolean(v, p); });
  opt(j, "friction", path, [&](const json& v, const std::string& p) { o->friction = r.non_negative(v, p); });
  opt(j, "restitution", path, [&](const json& v, const std::string& p) { o->restitution = r.in_range(v, p, 0, 1); });
  opt(j, "erp", path, [&](const json& v, const std::string& p) { o->erp = r.in_range(v, p, 0, 1); });
  opt(j, "cfm", path, [&](const json& v, const std::string& p) { o->cfm = r.non_negative(v, p); });
  opt(j, "quickstep_iterations", path, [&](const json& v, const std::string& p) { o->quickstep_iterations = r.integer(v, p, 1, 100000); });
  opt(j, "max_contacts", path, [&](const json& v, const std::string& p) { o->max_contacts = r.integer(v, p, 1, 64); });
  opt(j, "space", path, [&](const json& v, const std::string& p) { o->space = space_kind(r, v, p); });
  opt(j, "auto_disable", path, [&](const json& v, const std::string& p) { o->auto_disable = r.boolean(v, p); });
  opt(j, "linear_damping", path, [&](const json& v, const std::string& p) { o->linear_damping = r.non_negative(v, p); });
  opt(j, "angular_damping", path, [&](const json& v, const std::string& p) { o->angular_damping = r.non_negative(v, p); });
  opt(j, "surface_layer", path, [&](const json& v, const std::string& p) { o->surface_layer = r.non_negative(v, p); });
  opt(j, "max_correcting_velocity", path, [&](const json& v, const std::string& p) { o->max_correcting_velocity = r.non_negative(v, p); });
  opt(j, "contact_margin", path, [&](const json& v, const std::string& p) { o->contact_margin = r.number(v, p); });
  opt(j, "threads", path, [&](const json& v, const std::string& p) { o->threads = r.integer(v, p, 0, 1024); });
  opt(j, "force_model", path, [&](const json& v, const std::string& p) {
    const std::string s = r.string(v, p);
    if (!engine::parse_force_choice(s, &o->force_model)) r.fail(p, "unknown force model '" + s + "' (method, zeeman, classic)");
  });
  opt(j, "max_substeps", path, [&](const json& v, const std::string& p) { o->max_substeps = r.integer(v, p, 1, 64); });
  opt(j, "substep_reach", path, [&](const json& v, const std::string& p) { o->substep_reach = r.positive(v, p); });
  opt(j, "rolling_friction", path, [&](const json& v, const std::string& p) { o->rolling_friction = r.non_negative(v, p); });
  opt(j, "quickstep_w", path, [&](const json& v, const std::string& p) {
    o->quickstep_w = r.number(v, p);
    if (!(o->quickstep_w > 0 && o->quickstep_w < 2)) r.fail(p, "must be in (0, 2) (got " + Reader::fmt(o->quickstep_w) + ")");
  });
  opt(j, "reaction_symmetric_forces", path, [&](const json& v, const std::string& p) { o->reaction_symmetric_forces = r.boolean(v, p); });
  mag::FieldOptions& f = o->magnetics.field;
  opt(j, "field_solver", path, [&](const json& v, const std::string& p) {
    const std::string s = r.string(v, p);
    if (!mag::parse_field_solver(s, &f.solver)) r.fail(p, "unknown field solver '" + s + "' (direct, barnes-hut, auto)");
  });
  opt(j, "bh_theta", path, [&](const json& v, const std::string& p) {
    f.bh_theta = r.number(v, p);
    if (!(f.bh_theta > 0 && f.bh_theta <= 1)) r.fail(p, "must be in (0, 1] (got " + Reader::fmt(f.bh_theta) + ")");
  });
  opt(j, "bh_threshold", path, [&](const json& v, const std::string& p) { f.auto_threshold = r.integer(v, p, 0, 1000000000); });
  opt(j, "max_body_speed", path, [&](const json& v, const std::string& p) { o->max_body_speed = r.non_negative(v, p); });
  opt(j, "magnetics", path, [&](const json& v, const std::string& p) { read_magnetics(r, v, p, &o->magnetics); });
  o->magnetics.method = o->method;
}

void read_camera(const Reader& r, const json& j, const std::string& path, render::Camera* c) {
  r.keys(j, path, {"eye", "target", "up", "fov_y_deg", "z_near", "z_far"});
  opt(j, "eye", path, [&](const json& v, const std::string& p) { c->eye = r.vec3f(v, p); });
  opt(j, "target", path, [&](const json& v, const std::string& p) { c->target = r.vec3f(v, p); });
  opt(j, "up", path, [&](const json& v, const std::string& p) { c->up = r.vec3f(v, p); });
  opt(j, "fov_y_deg", path, [&](const json& v, const std::string& p) {
    c->fov_y_deg = static_cast<float>(r.in_range(v, p, 1.0, 179.0));
  });
  opt(j, "z_near", path, [&](const json& v, const std::string& p) { c->z_near = static_cast<float>(r.non_negative(v, p)); });
  opt(j, "z_far", path, [&](const json& v, const std::string& p) { c->z_far = static_cast<float>(r.non_negative(v, p)); });
  // a degenerate view rendered blank (eye = target) or a guessed orientation (up ∥ view)
  if (const std::string e = engine::camera_error(*c); !e.empty()) r.fail(path, e);
}

// The scene name becomes the output folder out/<name>_<method>: no path separators, no "."
// or ".." component, no control bytes, valid UTF-8 (the JSON parser checks the UTF-8 of
// strings, but not of the file name a default name comes from).
std::string bad_name_reason(const std::string& name) {
  if (name.empty()) return "must not be empty";
  if (name == "." || name == "..") return "must not be '.' or '..'";
  std::size_t i = 0;
  while (i < name.size()) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (c == '/' || c == '\\') return "must not contain '/' or '\\' (it names the output folder)";
    if (c < 0x20 || c == 0x7f) return "must not contain control characters";
    int extra = c < 0x80 ? 0 : (c & 0xe0) == 0xc0 ? 1 : (c & 0xf0) == 0xe0 ? 2 : (c & 0xf8) == 0xf0 ? 3 : -1;
    if (extra < 0 || (extra == 1 && c < 0xc2) || i + extra >= name.size())
      return "must be valid UTF-8";
    for (int k = 1; k <= extra; ++k)
      if ((static_cast<unsigned char>(name[i + k]) & 0xc0) != 0x80) return "must be valid UTF-8";
    i += 1 + extra;
  }
  return {};
}

std::string stem(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  std::string s = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = s.rfind('.');
  return dot == std::string::npos ? s : s.substr(0, dot);
}

}  // namespace

SceneDesc parse_scene_json(const std::string& text, const std::string& origin) {
  const Reader r(origin);
  json doc;
  try {
    doc = parse_unique_keys(text, /*ignore_comments=*/true);
  } catch (const DuplicateKeyError& e) {  // "bodies[0].position: duplicate key"
    r.fail("", e.what());
  } catch (const json::exception& e) {  // parse_error, or out_of_range for 1e999
    std::string what = e.what();
    const std::size_t close = what.find("] ");  // drop "[json.exception.parse_error.101] "
    if (what.rfind("[json.exception", 0) == 0 && close != std::string::npos) what = what.substr(close + 2);
    r.fail("", "malformed JSON: " + what);
  }

  r.keys(doc, "", {"name", "description", "modelling_level", "default_seconds", "escape_radius",
                   "H0", "camera", "options", "bodies"});
  SceneDesc s;
  s.name = stem(origin);
  opt(doc, "name", "", [&](const json& v, const std::string& p) { s.name = r.string(v, p); });
  if (const std::string why = bad_name_reason(s.name); !why.empty())
    r.fail(doc.contains("name") ? "name" : "(file name)", "the scene name " + why);
  opt(doc, "description", "", [&](const json& v, const std::string& p) { s.description = r.string(v, p); });
  opt(doc, "modelling_level", "", [&](const json& v, const std::string& p) { s.modelling_level = r.string(v, p); });
  opt(doc, "default_seconds", "", [&](const json& v, const std::string& p) { s.default_seconds = r.positive(v, p); });
  opt(doc, "escape_radius", "", [&](const json& v, const std::string& p) { s.escape_radius = r.non_negative(v, p); });
  opt(doc, "H0", "", [&](const json& v, const std::string& p) { s.H0 = r.bounded(v, p, engine::limits::kMaxField, "A/m"); });
  opt(doc, "camera", "", [&](const json& v, const std::string& p) { read_camera(r, v, p, &s.camera); });
  opt(doc, "options", "", [&](const json& v, const std::string& p) { read_options(r, v, p, &s.options); });
  if (!doc.contains("bodies")) r.fail("bodies", "required (an array of bodies)");
  const json& bodies = doc.at("bodies");
  if (!bodies.is_array()) r.fail("bodies", "must be an array of bodies");
  for (std::size_t i = 0; i < bodies.size(); ++i)
    s.bodies.push_back(read_body(r, bodies[i], Reader::index("bodies", i), i));
  return s;
}

SceneDesc load_scene_file(const std::string& path) {
  // a directory opens as an ifstream and reads as empty ("malformed JSON" would mislead)
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw std::runtime_error(path + ": is a directory, not a scene file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open the scene file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw std::runtime_error(path + ": cannot read the scene file");
  return parse_scene_json(text.str(), path);
}

}  // namespace magsim::scenes
