// engine/model.cpp — SceneDesc → Model: validation, mass properties, moment tables.
//
// Everything a step reads but never writes is computed here once: COM frames, inertia
// tensors, shape and moment offsets in the COM frame, and which moment belongs to which
// body. Validation happens here too, so the step can assume finite, positive inputs.
#include "engine/model.hpp"
#include "magnetics/det_math.hpp"

#include "engine/limits.hpp"
#include "engine/options_table.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace magsim::engine {

namespace {

using mag::kPi;  // magnetics/types.hpp

bool finite(const Vec3& v) { return v.allFinite(); }
bool finite(const Quat& q) { return q.coeffs().allFinite(); }

std::string fmt(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}
std::string fmt(const Vec3& v) {
  std::ostringstream s;
  s << '[' << v.x() << ", " << v.y() << ", " << v.z() << ']';
  return s.str();
}

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::invalid_argument(where + ": " + what);
}

// limits.hpp: a finite magnitude beyond what ODE (or the magnetics) can take
void check_at_most(const std::string& where, double magnitude, double max, const char* unit) {
  if (magnitude > max)
    fail(where, "magnitude " + fmt(magnitude) + " " + unit + " exceeds " + fmt(max) + " " + unit +
                    " (engine/limits.hpp: beyond it the rigid-body or magnetics arithmetic overflows)");
}

// >= 0 and finite; `unit` (e.g. "m") is named in the message when given
void check_non_negative(const std::string& where, double x, const char* unit = nullptr) {
  if (!(x >= 0 && std::isfinite(x)))
    fail(where, std::string("must be >= 0 and finite") + (unit ? std::string(" (") + unit + ")" : "") +
                    " (got " + fmt(x) + ")");
}

std::string body_where(int i, const std::string& name) {
  return "body " + std::to_string(i) + " '" + name + "'";
}

// The method resolved: the only place the method and force_model are turned into a curve and a
// force law (Model::Resolved), so that no stage works them out again.
Model::Resolved resolve(const SimOptions& o) {
  Model::Resolved r;
  r.curve = mag::curve_of(o.magnetics);
  r.force = mag::resolve_force_model(o.force_model, o.magnetics.method);
  // classic (−∇U*) and zeeman-total (−∇E_sys) are gradients of an energy; eq. 4 (zeeman) is not
  r.force_has_energy = r.force != mag::ForceModel::Zeeman;
  return r;
}

// Each option in its range (engine/options_table.hpp: the scene file's, the flags'), then
// what no single option's range says: the machine's thread cap and the combinations.
void check_options(const SimOptions& o, const Vec3& H0) {
  for (const OptionSpec& spec : options_table())
    if (const std::string e = spec.error(spec.get(o)); !e.empty()) fail("options." + spec.key, e);
  // the same cap as magsim-scene --threads: more only slows the run, 1e5 crashes libgomp
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  if (o.threads > 4 * cores)
    fail("options.threads", "at most " + std::to_string(4 * cores) + " (4 x the " + std::to_string(cores) +
                                " cores), got " + std::to_string(o.threads));
  if (o.balance_magnetic_torque && !o.reaction_symmetric_forces)
    fail("options.balance_magnetic_torque",
         "needs reaction_symmetric_forces (it removes the torque those forces leave)");
  if (o.sleep && o.magnetics.method == mag::Method::Exact)
    fail("options.sleep", "needs a relaxation method: exact re-solves every moment, a sleeping one too");
  if (const std::string e = mag::curve_error(o.magnetics.method, o.magnetics.field.near_field.curve); !e.empty())
    fail("options.magnetics.field.near_field.curve", e);
  if (!finite(H0)) fail("H0", "must be finite (got " + fmt(H0) + ")");
  check_at_most("H0", H0.stableNorm(), limits::kMaxField, "A/m");
  // the pair model is a correction of U*: only the classic force is its gradient
  const mag::ForceModel force = resolve(o).force;
  if (o.magnetics.field.near_field.model == mag::NearField::Pair && force != mag::ForceModel::Classic)
    fail("options.magnetics.field.near_field.model", std::string("pair needs the classic force (the default's); method '") +
                                   mag::method_name(o.magnetics.method) + "' with force '" +
                                   mag::kForceModelNames.name(force) +
                                   "' has no energy for it to correct");
}

void check_shape(const std::string& where, int k, const ShapeDesc& s) {
  const std::string w = where + ": shapes[" + std::to_string(k) + "]";
  if (!finite(s.offset)) fail(w + ".offset", "must be finite (got " + fmt(s.offset) + ")");
  if (!finite(s.rotation) || s.rotation.norm() < 1e-12)
    fail(w + ".rotation", "must be a finite non-zero quaternion");
  if (!finite(s.size)) fail(w + ".size", "must be finite (got " + fmt(s.size) + ")");
  check_at_most(w + ".offset", s.offset.stableNorm(), limits::kMaxCoordinate, "m");
  check_at_most(w + ".size", s.size.cwiseAbs().maxCoeff(), limits::kMaxSize, "m");
  switch (s.kind) {
    case ShapeKind::Sphere:
      if (!(s.size.x() > 0)) fail(w + ".size", "sphere radius must be > 0 (got " + fmt(s.size.x()) + ")");
      break;
    case ShapeKind::Box:
      if (!(s.size.minCoeff() > 0))
        fail(w + ".size", "box half extents must be > 0 (got " + fmt(s.size) + ")");
      break;
    case ShapeKind::Capsule:
    case ShapeKind::Cylinder:
      if (!(s.size.x() > 0 && s.size.y() > 0))
        fail(w + ".size", "radius and half length must be > 0 (got " + fmt(s.size) + ")");
      break;
  }
}

void check_moment(const std::string& where, int k, const MomentDesc& m) {
  const std::string w = where + ": moments[" + std::to_string(k) + "]";
  if (!finite(m.offset)) fail(w + ".offset", "must be finite (got " + fmt(m.offset) + ")");
  check_at_most(w + ".offset", m.offset.stableNorm(), limits::kMaxCoordinate, "m");
  if (!(m.volume > 0 && std::isfinite(m.volume)))
    fail(w + ".volume", "must be > 0 and finite (got " + fmt(m.volume) + ")");
  check_at_most(w + ".volume", m.volume, limits::kMaxVolume, "m^3");
  if (!std::isfinite(m.interaction_radius))
    fail(w + ".interaction_radius", "must be finite: >= 0 (m), or < 0 for auto (got " +
                                        fmt(m.interaction_radius) + ")");
  if (m.permanent) {
    if (!finite(m.moment)) fail(w + ".moment", "must be finite (got " + fmt(m.moment) + ")");
    check_at_most(w + ".moment", m.moment.stableNorm(), limits::kMaxMoment, "A·m^2");
  } else if (!(m.Ms > 0 && std::isfinite(m.Ms))) {
    fail(w + ".Ms", "must be > 0 and finite (got " + fmt(m.Ms) + ")");
  } else {
    check_at_most(w + ".Ms", m.Ms, limits::kMaxMs, "A/m");
  }
}

void check_body(int i, const BodyDesc& b, const std::string& name) {
  const std::string w = body_where(i, name);
  if (!finite(b.position)) fail(w, "position is not finite (" + fmt(b.position) + ")");
  if (!finite(b.orientation) || b.orientation.norm() < 1e-12)
    fail(w, "orientation must be a finite non-zero quaternion");
  if (!finite(b.velocity)) fail(w, "velocity is not finite (" + fmt(b.velocity) + ")");
  if (!finite(b.angular_velocity))
    fail(w, "angular_velocity is not finite (" + fmt(b.angular_velocity) + ")");
  check_at_most(w + ": position", b.position.stableNorm(), limits::kMaxCoordinate, "m");
  check_at_most(w + ": velocity", b.velocity.stableNorm(), limits::kMaxSpeed, "m/s");
  check_at_most(w + ": angular_velocity", b.angular_velocity.stableNorm(), limits::kMaxAngularSpeed, "rad/s");
  if (!(b.mass >= 0 && std::isfinite(b.mass)))
    fail(w, "mass must be >= 0 and finite, 0 = density x volume (got " + fmt(b.mass) + ")");
  if (b.type == BodyType::Dynamic && b.mass == 0 && !(b.density > 0 && std::isfinite(b.density)))
    fail(w, "density must be > 0 and finite (got " + fmt(b.density) + ")");
  if (b.type == BodyType::Dynamic && b.shapes.empty())
    fail(w, "shapes: a dynamic body needs at least one shape (it has no mass otherwise)");
  for (float c : {b.color.r, b.color.g, b.color.b})
    if (!(c >= 0.0f && c <= 1.0f)) fail(w, "color components must be in [0, 1]");
  for (std::size_t k = 0; k < b.shapes.size(); ++k) check_shape(w, static_cast<int>(k), b.shapes[k]);
  for (std::size_t k = 0; k < b.moments.size(); ++k) check_moment(w, static_cast<int>(k), b.moments[k]);
}

}  // namespace

// Solid of density 1 about its centre, in its own axes (capsule/cylinder along z, h = half
// length of the axis segment):
//   sphere    V = 4/3 π r³,  I = 2/5 V r² 𝟙
//   box       V = 8 hx hy hz, I_xx = V (hy² + hz²)/3, …
//   cylinder  V = 2π r² h,   I_zz = V r²/2, I_xx = V (r²/4 + h²/3)
//   capsule   cylinder + sphere V_s = 4/3 π r³ split into two caps:
//             I_zz += 2/5 V_s r², I_xx += V_s (2/5 r² + h² + 3/4 h r)
double shape_volume_inertia(ShapeKind kind, const Vec3& size, Mat3* I) {
  I->setZero();
  const double r = size.x();
  switch (kind) {
    case ShapeKind::Sphere: {
      const double V = 4.0 / 3.0 * kPi * r * r * r;
      I->diagonal().setConstant(0.4 * V * r * r);
      return V;
    }
    case ShapeKind::Box: {
      const double x = size.x(), y = size.y(), z = size.z();
      const double V = 8.0 * x * y * z;
      I->diagonal() << V * (y * y + z * z) / 3.0, V * (x * x + z * z) / 3.0, V * (x * x + y * y) / 3.0;
      return V;
    }
    case ShapeKind::Cylinder:
    case ShapeKind::Capsule: {
      const double h = size.y();
      const double Vc = 2.0 * kPi * r * r * h;
      double Ixx = Vc * (r * r / 4.0 + h * h / 3.0);
      double Izz = Vc * r * r / 2.0;
      double V = Vc;
      if (kind == ShapeKind::Capsule) {
        const double Vs = 4.0 / 3.0 * kPi * r * r * r;
        Ixx += Vs * (0.4 * r * r + h * h + 0.75 * h * r);
        Izz += Vs * 0.4 * r * r;
        V += Vs;
      }
      I->diagonal() << Ixx, Ixx, Izz;
      return V;
    }
  }
  return 0.0;
}

double shape_bounding_radius(ShapeKind kind, const Vec3& size) {
  switch (kind) {
    case ShapeKind::Sphere: return size.x();
    case ShapeKind::Box: return size.norm();
    case ShapeKind::Capsule: return size.x() + size.y();
    case ShapeKind::Cylinder: return mag::dmath::hypot(size.x(), size.y());
  }
  return 0.0;
}

// The radius of the largest sphere about point o (body frame) inside one of the shapes,
// 0 when no shape holds o: a ball's centre gets its radius, a box's centre its smallest
// half extent, a point on a capsule's axis its radius.
static double inscribed_radius(const std::vector<ShapeDesc>& shapes, const Vec3& o) {
  double best = 0.0;
  for (const ShapeDesc& s : shapes) {
    const Vec3 p = s.rotation.normalized().conjugate() * (o - s.offset);  // in the shape's axes
    const Vec3& z = s.size;
    double d = 0.0;
    switch (s.kind) {
      case ShapeKind::Sphere: d = z.x() - p.norm(); break;
      case ShapeKind::Box: d = (z - p.cwiseAbs()).minCoeff(); break;
      case ShapeKind::Capsule: {
        const double t = std::clamp(p.z(), -z.y(), z.y());
        d = z.x() - (p - Vec3(0, 0, t)).norm();
        break;
      }
      case ShapeKind::Cylinder:
        d = std::min(z.x() - p.head<2>().norm(), z.y() - std::abs(p.z()));
        break;
    }
    best = std::max(best, d);
  }
  return best;
}

std::string camera_error(const render::Camera& c) {
  const Eigen::Vector3d eye = c.eye.cast<double>(), target = c.target.cast<double>(), up = c.up.cast<double>();
  const Eigen::Vector3d view = target - eye;
  const double scale = std::max({1.0, eye.norm(), target.norm()});
  if (!(view.norm() > 1e-6 * scale))
    return "eye " + fmt(eye) + " and target " + fmt(target) + " are the same point: no view direction";
  if (!(up.norm() > 0)) return "up must not be zero";
  if (!(view.normalized().cross(up.normalized()).norm() > 1e-3))
    return "up " + fmt(up) + " is parallel to the view direction target - eye " + fmt(view) + ": the roll is undefined";
  return {};
}

Model compile_model(const SceneDesc& scene) {
  check_options(scene.options, scene.H0);

  Model m;
  m.options = scene.options;
  if (m.options.auto_disable) m.options.sleep = false;  // ODE's own sleep was asked for: it alone
  m.resolved = resolve(scene.options);
  m.H0 = scene.H0;
  if (const std::string e = camera_error(scene.camera); !e.empty()) fail("camera", e);
  m.camera = scene.camera;
  m.name = scene.name;
  m.description = scene.description;
  m.modelling_level = scene.modelling_level;
  check_non_negative("escape_radius", scene.escape_radius);
  m.escape_radius = scene.escape_radius;
  m.nbody = static_cast<int>(scene.bodies.size());

  for (int i = 0; i < m.nbody; ++i) {
    const BodyDesc& b = scene.bodies[i];
    const std::string name = b.name.empty() ? "body_" + std::to_string(i) : b.name;
    check_body(i, b, name);

    // mass properties of the shapes, in the BodyDesc frame
    double V = 0.0;
    std::vector<double> Vs(b.shapes.size());
    std::vector<Mat3> Is(b.shapes.size());
    for (std::size_t k = 0; k < b.shapes.size(); ++k) {
      Vs[k] = shape_volume_inertia(b.shapes[k].kind, b.shapes[k].size, &Is[k]);
      V += Vs[k];
    }
    double mass = 0.0;
    Vec3 com = Vec3::Zero();
    Mat3 inertia = Mat3::Zero();
    if (b.type == BodyType::Dynamic) {
      mass = b.mass > 0 ? b.mass : b.density * V;
      const double rho = mass / V;  // uniform density that gives the stated mass
      for (std::size_t k = 0; k < b.shapes.size(); ++k) com += rho * Vs[k] * b.shapes[k].offset;
      com /= mass;
      // I = Σ_s ρ R_s I_s R_sᵀ + m_s (|d|² 𝟙 − d dᵀ),  d = o_s − c  (parallel axes)
      for (std::size_t k = 0; k < b.shapes.size(); ++k) {
        const Mat3 R = b.shapes[k].rotation.normalized().toRotationMatrix();
        const Vec3 d = b.shapes[k].offset - com;
        const double ms = rho * Vs[k];
        inertia += rho * R * Is[k] * R.transpose() +
                   ms * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
      }
      if (!(mass > 0 && std::isfinite(mass) && inertia.allFinite()))
        fail(body_where(i, name), "mass properties are not positive and finite (mass " + fmt(mass) + ")");
      if (mass < limits::kMinMass || mass > limits::kMaxMass)
        fail(body_where(i, name), std::string("mass ") + fmt(mass) + " kg (" +
                                      (b.mass > 0 ? "given" : "density x volume") + ") is outside [" +
                                      fmt(limits::kMinMass) + ", " + fmt(limits::kMaxMass) +
                                      "] kg (engine/limits.hpp: beyond it ODE's arithmetic overflows)");
    } else if (b.type == BodyType::Kinematic) {
      // ODE needs a valid mass on every body; a kinematic body never uses it
      mass = 1.0;
      inertia = Mat3::Identity() * 1e-3;
    }
    // non-dynamic bodies keep the BodyDesc frame (c = 0): their scripted motion is about
    // the origin the scene author chose

    const Quat q = b.orientation.normalized();
    m.body_name.push_back(name);
    m.body_type.push_back(b.type);
    m.body_mass.push_back(mass);
    m.body_inertia.push_back(0.5 * (inertia + inertia.transpose()));
    m.body_com.push_back(com);
    m.body_pos0.push_back(b.position + q * com);
    m.body_quat0.push_back(q);
    m.body_vel0.push_back(b.velocity);
    m.body_angvel0.push_back(b.angular_velocity);
    m.body_color.push_back(b.color);
    m.body_visible.push_back(b.visible ? 1 : 0);
    m.body_magnet.push_back(b.magnet ? 1 : 0);
    m.body_shape_adr.push_back(m.nshape);
    m.body_shape_num.push_back(static_cast<int>(b.shapes.size()));
    m.body_moment_adr.push_back(m.nmoment);
    m.body_moment_num.push_back(static_cast<int>(b.moments.size()));

    double radius = 0.0;
    for (const ShapeDesc& s : b.shapes) {
      m.shape_kind.push_back(s.kind);
      m.shape_body.push_back(i);
      m.shape_offset.push_back(s.offset - com);
      m.shape_rot.push_back(s.rotation.normalized());
      m.shape_size.push_back(s.size);
      const double sr = shape_bounding_radius(s.kind, s.size);
      m.shape_radius.push_back(sr);
      radius = std::max(radius, (s.offset - com).norm() + sr);
      ++m.nshape;
    }
    m.body_radius.push_back(radius);

    for (const MomentDesc& md : b.moments) {
      m.moment_body.push_back(i);
      m.moment_offset.push_back(md.offset - com);
      m.moment_permanent.push_back(md.permanent ? 1 : 0);
      m.moment_volume.push_back(md.volume);
      m.moment_Ms.push_back(md.permanent ? 0.0 : md.Ms);
      m.moment_m.push_back(md.permanent ? md.moment : Vec3::Zero());
      m.moment_radius.push_back(mag::dmath::cbrt(3.0 * md.volume / (4.0 * kPi)));
      m.moment_interaction_radius.push_back(
          md.interaction_radius >= 0 ? md.interaction_radius : inscribed_radius(b.shapes, md.offset));
      if (!md.permanent) ++m.induced_count;
      if (b.type == BodyType::Dynamic) m.dynamic_moments = true;
      ++m.nmoment;
    }
    if (b.type == BodyType::Dynamic) m.dynamic_bodies.push_back(i);
  }

  // speculative contact margin: auto = a quarter of the smallest shape's radius (its
  // inscribed radius: the sphere radius, smallest box half extent, capsule/cylinder radius)
  m.contact_margin = scene.options.contact_margin;
  if (m.contact_margin < 0) {
    double rmin = 0.0;
    for (int s = 0; s < m.nshape; ++s) {
      const Vec3& z = m.shape_size[s];
      const double r = m.shape_kind[s] == ShapeKind::Box ? z.minCoeff() : z.x();
      rmin = s == 0 ? r : std::min(rmin, r);
    }
    m.contact_margin = 0.25 * rmin;
  }
  for (int s = 0; s < m.nshape; ++s) {
    if (m.body_type[m.shape_body[s]] != BodyType::Dynamic) continue;
    const Vec3& z = m.shape_size[s];
    const double r = m.shape_kind[s] == ShapeKind::Box ? z.minCoeff() : z.x();
    m.min_dynamic_radius = m.min_dynamic_radius == 0.0 ? r : std::min(m.min_dynamic_radius, r);
  }
  return m;
}

}  // namespace magsim::engine
