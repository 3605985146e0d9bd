// engine/ode_bridge.cpp — ODE in quarantine: world, space, bodies, geoms, contacts.
//
// The only file of the engine that includes <ode/ode.h>. It owns every ODE object of one
// Simulation (no globals but the library's init refcount) and turns the Model into ODE
// objects once; afterwards it only moves state in and out, collides and steps.
#include "engine/ode_bridge.hpp"
#include "magnetics/det_math.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <string>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace magsim::engine {

namespace {

static_assert(sizeof(dReal) == sizeof(double), "magsim needs ODE built in double precision");

// dInitODE2 / dCloseODE, refcounted across Simulation instances (ODE's own init is global).
std::mutex g_ode_mutex;
int g_ode_users = 0;
bool g_ode_open = false;
/// A world failed mid-step: ODE's shared stepping state is left unfinished and dCloseODE
/// would assert on it, so ODE then stays open until the process ends.
bool g_ode_poisoned = false;

// ODE's error and debug handlers abort() after the call; throwing from them unwinds
// through ODE (C++ compiled with exceptions) back to the Simulation instead.
// ODE's message handler (non-fatal warnings, e.g. a bad mass) prints them; the last one is
// kept and added to the next failure, so a run that ODE then stops says why.
std::mutex g_message_mutex;
std::string g_last_message;

void keep_ode_message(int errnum, const char* msg, va_list ap) {
  char text[512];
  std::vsnprintf(text, sizeof text, msg, ap);
  std::fprintf(stderr, "ODE message %d: %s\n", errnum, text);
  std::lock_guard<std::mutex> lock(g_message_mutex);
  g_last_message = text;
}

void throw_ode_failure(int errnum, const char* msg, va_list ap) {
  char text[512];
  std::vsnprintf(text, sizeof text, msg, ap);
  std::string what = "ODE error " + std::to_string(errnum) + ": " + text;
  {
    std::lock_guard<std::mutex> lock(g_message_mutex);
    if (!g_last_message.empty()) what += " (after ODE's message: " + g_last_message + ")";
    g_last_message.clear();
  }
  throw OdeFailure(what);
}

void ode_acquire() {
  std::lock_guard<std::mutex> lock(g_ode_mutex);
  if (g_ode_users++ == 0 && !g_ode_open) {
    if (!dInitODE2(0)) {
      g_ode_users = 0;
      throw std::runtime_error("dInitODE2 failed");
    }
    dSetErrorHandler(&throw_ode_failure);
    dSetDebugHandler(&throw_ode_failure);
    dSetMessageHandler(&keep_ode_message);
    g_ode_open = true;
  }
}

void ode_release(bool poisoned) {
  std::lock_guard<std::mutex> lock(g_ode_mutex);
  g_ode_poisoned = g_ode_poisoned || poisoned;
  if (--g_ode_users == 0 && !g_ode_poisoned) {
    dSetErrorHandler(nullptr);
    dSetDebugHandler(nullptr);
    dSetMessageHandler(nullptr);
    dCloseODE();
    g_ode_open = false;
  }
}

// Which shape (and body) a geom belongs to; the ground plane has shape = nshape.
struct GeomTag {
  int shape = 0;
  int body = -1;          ///< −1 = ground
  bool dynamic = false;   ///< its body is dynamic
};

// One narrow-phase contact, kept until all are sorted into a fixed order.
struct ContactRec {
  int a = 0, b = 0, k = 0;  ///< shape indices (a < b) and index within dCollide's output
  dContactGeom g;
};

void to_ode(const Quat& q, dQuaternion out) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

}  // namespace

struct OdeBridge::Impl {
  const Model& model;
  dWorldID world = nullptr;
  dSpaceID space = nullptr;
  dJointGroupID contact_group = nullptr;
  dGeomID ground = nullptr;  ///< not in the space: collided with dSpaceCollide2
  std::vector<dBodyID> body;    ///< (nbody) nullptr for static bodies
  std::vector<dGeomID> geom;    ///< (nshape)
  std::vector<GeomTag> tag;     ///< (nshape + 1) the last one is the ground's
  dSurfaceParameters surface{};
  dSurfaceParameters rolling{};  ///< surface of contacts with a non-dynamic body
  dSurfaceParameters between{};  ///< surface of contacts between two dynamic bodies
  int max_contacts = 4;
  bool skip_resting = false;  ///< some body is disabled (asleep) in this collide: its sleep rules apply
  double damped_h = 0.0;  ///< the step length the damping factors are set for (s)
  double margin = 0.0;  ///< base speculative contact margin μ0 (m)
  std::vector<double> shape_margin;  ///< (nshape + 1) margin μ_s each geom is grown by now
  std::thread::id data_thread;  ///< thread for which ODE's per-thread data is allocated
  bool broken = false;          ///< ODE failed mid-step: the world is unusable

  // per-step scratch (reused, no allocation once warm)
  std::vector<dContactGeom> buf;
  std::vector<ContactRec> recs;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order;  ///< (sort key, index in recs)

  explicit Impl(const Model& m) : model(m) {}

  void ensure_thread_data() {
    if (data_thread == std::this_thread::get_id()) return;
    dAllocateODEDataForThread(dAllocateMaskAll);
    data_thread = std::this_thread::get_id();
  }

  // The collision geom is the shape grown by its contact margin μ_s (speculative contacts).
  dGeomID create_geom(int s) {
    const Vec3& sz = model.shape_size[s];
    const double mu = shape_margin[s];
    switch (model.shape_kind[s]) {
      case ShapeKind::Sphere: return dCreateSphere(space, sz.x() + mu);
      case ShapeKind::Box: return dCreateBox(space, 2 * (sz.x() + mu), 2 * (sz.y() + mu), 2 * (sz.z() + mu));
      // ODE's length is the axis segment, without the caps (= 2 × half length)
      case ShapeKind::Capsule: return dCreateCapsule(space, sz.x() + mu, 2 * sz.y());
      case ShapeKind::Cylinder: return dCreateCylinder(space, sz.x() + mu, 2 * (sz.y() + mu));
    }
    throw std::logic_error("unknown shape kind");
  }

  void grow_geom(int s, double mu) {
    if (mu == shape_margin[s]) return;
    shape_margin[s] = mu;
    const Vec3& sz = model.shape_size[s];
    dGeomID g = geom[s];
    switch (model.shape_kind[s]) {
      case ShapeKind::Sphere: dGeomSphereSetRadius(g, sz.x() + mu); break;
      case ShapeKind::Box: dGeomBoxSetLengths(g, 2 * (sz.x() + mu), 2 * (sz.y() + mu), 2 * (sz.z() + mu)); break;
      case ShapeKind::Capsule: dGeomCapsuleSetParams(g, sz.x() + mu, 2 * sz.y()); break;
      case ShapeKind::Cylinder: dGeomCylinderSetParams(g, sz.x() + mu, 2 * (sz.y() + mu)); break;
    }
  }

  // ODE damps per step, v ← (1 − s) v; s = 1 − e^{−c h} gives a decay rate c (1/s) for any
  // step length h
  void set_damping(double h) {
    if (h == damped_h) return;
    const SimOptions& o = model.options;
    dWorldSetLinearDamping(world, 1.0 - mag::dmath::exp(-o.linear_damping * h));
    dWorldSetAngularDamping(world, 1.0 - mag::dmath::exp(-o.angular_damping * h));
    damped_h = h;
  }

  void build() {
    const SimOptions& o = model.options;
    if (model.nshape + 1 >= (1 << 28))  // the contact sort key (collide) holds shape indices < 2^28
      throw std::runtime_error("too many shapes for one world: " + std::to_string(model.nshape));
    world = dWorldCreate();
    dWorldSetGravity(world, o.gravity.x(), o.gravity.y(), o.gravity.z());
    dWorldSetERP(world, o.erp);
    dWorldSetCFM(world, o.cfm);
    dWorldSetQuickStepNumIterations(world, o.quickstep_iterations);
    dWorldSetQuickStepW(world, o.quickstep_w);
    dWorldSetContactSurfaceLayer(world, o.surface_layer);
    if (o.max_correcting_velocity > 0) dWorldSetContactMaxCorrectingVel(world, o.max_correcting_velocity);
    dWorldSetLinearDampingThreshold(world, 0);
    dWorldSetAngularDampingThreshold(world, 0);
    set_damping(o.dt);
    dWorldSetAutoDisableFlag(world, o.auto_disable ? 1 : 0);

    switch (o.space) {
      case SpaceKind::Hash: {
        space = dHashSpaceCreate(nullptr);
        // cells from the smallest to the largest geom (cell size 2^level m)
        double rmin = 1e30, rmax = 0;
        for (double r : model.shape_radius) {
          rmin = std::min(rmin, r);
          rmax = std::max(rmax, r);
        }
        if (rmax > 0) {
          const int lo = static_cast<int>(std::floor(std::log2(2 * rmin)));
          const int hi = std::max(lo, static_cast<int>(std::ceil(std::log2(2 * rmax))));
          dHashSpaceSetLevels(space, lo, hi);
        }
        break;
      }
      case SpaceKind::SweepAndPrune: space = dSweepAndPruneSpaceCreate(nullptr, dSAP_AXES_XYZ); break;
      case SpaceKind::Simple: space = dSimpleSpaceCreate(nullptr); break;
    }
    contact_group = dJointGroupCreate(0);

    // contact surface: Coulomb μ (friction pyramid, Approx1), soft ERP/CFM, optional bounce
    surface.mode = dContactSoftERP | dContactSoftCFM;
    if (o.friction > 0) surface.mode |= dContactApprox1;
    surface.mu = o.friction;  // 0 → frictionless
    if (o.restitution > 0) {
      surface.mode |= dContactBounce;
      surface.bounce = o.restitution;
      surface.bounce_vel = 1e-3;
    }
    surface.soft_erp = o.erp;
    surface.soft_cfm = o.cfm;
    // rolling resistance (contacts with the ground and static bodies: rolling_friction;
    // between two dynamic bodies: rolling_friction_bodies; see collide): the two rolling rows
    // and the spinning row carry a torque of at most ρ·N (dContactRolling with
    // dContactApprox1: limits ∝ the normal force)
    auto with_rolling = [&](double rho) {
      dSurfaceParameters s = surface;
      if (rho > 0) {
        s.mode |= dContactRolling | dContactApprox1;
        s.rho = rho;
      }
      return s;
    };
    rolling = with_rolling(o.rolling_friction);
    between = with_rolling(o.rolling_friction_bodies);
    max_contacts = o.max_contacts;
    buf.resize(max_contacts);
    margin = model.contact_margin;
    shape_margin.assign(model.nshape + 1, margin);
    shape_margin[model.nshape] = 0.0;  // the ground plane is not grown

    body.assign(model.nbody, nullptr);
    geom.assign(model.nshape, nullptr);
    tag.resize(model.nshape + 1);
    for (int i = 0; i < model.nbody; ++i) {
      const BodyType type = model.body_type[i];
      dQuaternion q;
      to_ode(model.body_quat0[i], q);
      const Vec3& p = model.body_pos0[i];
      dBodyID b = nullptr;
      if (type != BodyType::Static) {
        b = dBodyCreate(world);
        dMass mass;
        const Mat3& I = model.body_inertia[i];
        dMassSetParameters(&mass, model.body_mass[i], 0, 0, 0, I(0, 0), I(1, 1), I(2, 2), I(0, 1),
                           I(0, 2), I(1, 2));
        dBodySetMass(b, &mass);
        dBodySetPosition(b, p.x(), p.y(), p.z());
        dBodySetQuaternion(b, q);
        if (type == BodyType::Kinematic) dBodySetKinematic(b);
        body[i] = b;
      }
      const Mat3 R = model.body_quat0[i].toRotationMatrix();
      for (int s = model.body_shape_adr[i]; s < model.body_shape_adr[i] + model.body_shape_num[i]; ++s) {
        dGeomID g = create_geom(s);
        tag[s] = GeomTag{s, i, type == BodyType::Dynamic};
        dGeomSetData(g, &tag[s]);
        dQuaternion qs;
        const Vec3& off = model.shape_offset[s];
        if (b) {
          // composite bodies: each geom at its offset from the COM (the body origin)
          dGeomSetBody(g, b);
          to_ode(model.shape_rot[s], qs);
          dGeomSetOffsetPosition(g, off.x(), off.y(), off.z());
          dGeomSetOffsetQuaternion(g, qs);
        } else {
          // static: a geom without a body, placed once at pose ∘ offset
          const Vec3 pw = p + R * off;
          to_ode(model.body_quat0[i] * model.shape_rot[s], qs);
          dGeomSetPosition(g, pw.x(), pw.y(), pw.z());
          dGeomSetQuaternion(g, qs);
        }
        geom[s] = g;
      }
    }
    if (o.ground) {
      ground = dCreatePlane(nullptr, 0, 0, 1, 0);  // z = 0, not in the space
      tag[model.nshape] = GeomTag{model.nshape, -1, false};
      dGeomSetData(ground, &tag[model.nshape]);
    }
  }

  // Narrow phase of one candidate pair, in a fixed geom order (lower shape index first).
  static void near_callback(void* data, dGeomID o1, dGeomID o2) {
    auto* self = static_cast<Impl*>(data);
    const auto* t1 = static_cast<const GeomTag*>(dGeomGetData(o1));
    const auto* t2 = static_cast<const GeomTag*>(dGeomGetData(o2));
    if (!t1->dynamic && !t2->dynamic) return;  // two non-dynamic bodies never interact
    if (t1->body == t2->body) return;          // geoms of one rigid body
    // a sleeping body (disabled: SimOptions::sleep) against a sleeping or non-dynamic one: no
    // row for ODE to solve; the step carries such pairs over (sleep.cpp)
    auto rests = [](const GeomTag* t, dGeomID g) { return !t->dynamic || !dBodyIsEnabled(dGeomGetBody(g)); };
    if (self->skip_resting && rests(t1, o1) && rests(t2, o2)) return;
    if (t1->shape > t2->shape) {
      std::swap(o1, o2);
      std::swap(t1, t2);
    }
    const int n = dCollide(o1, o2, self->max_contacts, self->buf.data(), sizeof(dContactGeom));
    for (int k = 0; k < n; ++k) self->recs.push_back(ContactRec{t1->shape, t2->shape, k, self->buf[k]});
  }

  // How far geom s, grown by μ = shape_margin[s] (grow_geom), reaches beyond its shape along
  // the unit normal n: the difference of the two support functions, h_grown(n) − h(n).
  // Contact depths of convex shapes are support overlaps along the normal, so this is what
  // the margin adds to a depth. A sphere or capsule grows by μ in every direction; a box
  // whose half extents all grow by μ reaches μ Σ_i |n·a_i| (a_i its axes), up to √3 μ along a
  // corner's diagonal; a cylinder, whose radius and half length grow, μ (|n·z| + √(1−(n·z)²)).
  // Subtracting μ alone there read a box corner lying a gap away as penetrating by up to
  // (√3 − 1) μ, and the error reduction pushed it out against the magnet.
  double margin_along(int s, const dVector3 n) const {
    const double mu = shape_margin[s];
    if (mu == 0.0 || s == model.nshape) return mu;  // not grown; the ground plane
    const ShapeKind kind = model.shape_kind[s];
    if (kind == ShapeKind::Sphere || kind == ShapeKind::Capsule) return mu;
    const dReal* R = dGeomGetRotation(geom[s]);  // 3×4, row major: column i = axis i
    auto along = [&](int i) { return std::abs(n[0] * R[i] + n[1] * R[4 + i] + n[2] * R[8 + i]); };
    if (kind == ShapeKind::Box) return mu * (along(0) + along(1) + along(2));
    const double z = std::min(1.0, along(2));  // cylinder: axis = local z
    return mu * (z + std::sqrt(1.0 - z * z));
  }

  int collide(std::vector<std::pair<int, int>>* pairs, double dt, double dt_soft, double* max_depth,
              std::vector<std::pair<int, int>>* joined) {
    ensure_thread_data();
    recs.clear();
    skip_resting = model.options.sleep &&
                   std::any_of(body.begin(), body.end(), [](dBodyID b) { return b && !dBodyIsEnabled(b); });
    dSpaceCollide(space, this, &near_callback);
    if (ground) dSpaceCollide2(reinterpret_cast<dGeomID>(space), ground, this, &near_callback);
    // fixed order, independent of the broad phase's internal lists: sorted by (a, b, k),
    // packed in one 64-bit key (a, b < 2^28 shapes, k < 256 contacts) with the record's
    // index, so that the sort moves 16-byte keys instead of 100-byte records
    order.clear();
    for (std::size_t i = 0; i < recs.size(); ++i) {
      const ContactRec& r = recs[i];
      const std::uint64_t key = (std::uint64_t(r.a) << 36) | (std::uint64_t(r.b) << 8) | std::uint64_t(r.k);
      order.emplace_back(key, static_cast<std::uint32_t>(i));
    }
    std::sort(order.begin(), order.end());
    pairs->clear();
    if (joined) joined->clear();
    const double touch = 0.1 * margin;  // gaps below this count as touching (metrics)
    // The contacts' softness for a step of dt: the spring and damper that ERP and CFM make at
    // the step dt_soft (kp = ERP/(CFM dt_soft), kd = (1 − ERP)/CFM), kept at dt:
    //   ERP_dt = dt kp/(dt kp + kd),  CFM_dt = 1/(dt kp + kd).
    // With ERP and CFM fixed instead, an overlap d is pushed out at ERP d/dt: n times faster
    // in n sub-steps, so the energy guard's retakes fed energy into overlaps rather than
    // resolving them (step.cpp passes the sub-step the scene chose as dt_soft).
    double soft_erp = model.options.erp, soft_cfm = model.options.cfm;
    const double h0 = dt_soft;
    if (dt != h0) {
      if (soft_cfm > 0) {
        const double kp_h = soft_erp / soft_cfm * (dt / h0), kd = (1.0 - soft_erp) / soft_cfm;
        soft_erp = kp_h / (kp_h + kd);
        soft_cfm = 1.0 / (kp_h + kd);
      } else {
        soft_erp *= dt / h0;  // the limit of a stiff spring: the same correction rate ERP/h0
      }
    }
    dContact c;
    double deepest = 0.0;
    for (const auto& [key, idx] : order) {
      const ContactRec& r = recs[idx];
      // rolling resistance where a ball rolls on the world (ground, static shapes), and,
      // with its own ρ, between two bodies: three more rows on every ball–ball contact of a
      // pile doubled QuickStep's time (falling_magnet T_r 9.1 → 18.9 ms)
      c.surface = tag[r.a].dynamic && tag[r.b].dynamic ? between : rolling;
      c.surface.soft_erp = soft_erp;
      c.surface.soft_cfm = soft_cfm;
      c.geom = r.g;
      // true depth d = depth of the grown geoms − how far each grown geom reaches beyond
      // its shape along the contact normal (margin_along: μ for spheres and capsules, more
      // for a box's edges and corners)
      const double d = r.g.depth - margin_along(r.a, r.g.normal) - margin_along(r.b, r.g.normal);
      if (d < 0) {
        // speculative: a gap g = −d may close within this step but not more,
        // J v ≥ −g/Δt (ODE's contact row: J v ≥ k·depth + motionN, here depth = 0)
        c.geom.depth = 0;
        c.surface.mode |= dContactMotionN;
        c.surface.mode &= ~dContactBounce;
        c.surface.motionN = d / dt;
      } else {
        c.geom.depth = d;
        deepest = std::max(deepest, d);
      }
      dJointID j = dJointCreateContact(world, contact_group, &c);
      dBodyID b1 = dGeomGetBody(r.g.g1), b2 = dGeomGetBody(r.g.g2);
      // a gap to a sleeping body (SimOptions::sleep) that the bodies do not close within the
      // step is held against it as against the world: the awake body cannot pass it, and
      // ODE does not enable the sleeper for it; one that closes ties them (the sleeper wakes)
      if (d < 0 && skip_resting && b1 && b2 && (!dBodyIsEnabled(b1) || !dBodyIsEnabled(b2))) {
        const dReal* v1 = dBodyGetLinearVel(b1);
        const dReal* v2 = dBodyGetLinearVel(b2);
        const double closing = std::abs((v1[0] - v2[0]) * r.g.normal[0] + (v1[1] - v2[1]) * r.g.normal[1] +
                                        (v1[2] - v2[2]) * r.g.normal[2]);
        if (closing * dt < -d) {
          if (!dBodyIsEnabled(b1)) b1 = nullptr;
          if (!dBodyIsEnabled(b2)) b2 = nullptr;
        }
      }
      dJointAttach(j, b1, b2);
      if (joined && skip_resting && b1 && b2)
        joined->emplace_back(std::min(tag[r.a].body, tag[r.b].body), std::max(tag[r.a].body, tag[r.b].body));
      if (d > -touch) {
        const int ba = tag[r.a].body, bb = tag[r.b].body;
        pairs->emplace_back(std::min(ba, bb), std::max(ba, bb));
      }
    }
    std::sort(pairs->begin(), pairs->end());
    pairs->erase(std::unique(pairs->begin(), pairs->end()), pairs->end());
    if (joined) {
      std::sort(joined->begin(), joined->end());
      joined->erase(std::unique(joined->begin(), joined->end()), joined->end());
    }
    if (max_depth) *max_depth = deepest;
    return static_cast<int>(recs.size());
  }
};

OdeBridge::OdeBridge(const Model& model) : impl_(std::make_unique<Impl>(model)) {
  ode_acquire();
  try {
    impl_->ensure_thread_data();
    impl_->build();
  } catch (...) {
    ode_release(false);
    throw;
  }
}

OdeBridge::~OdeBridge() {
  Impl& m = *impl_;
  if (m.contact_group) dJointGroupDestroy(m.contact_group);
  for (dGeomID g : m.geom)
    if (g) dGeomDestroy(g);
  if (m.ground) dGeomDestroy(m.ground);
  if (m.space) dSpaceDestroy(m.space);
  if (m.world) dWorldDestroy(m.world);  // destroys the bodies
  ode_release(m.broken);
}

bool OdeBridge::broken() const { return impl_->broken; }
void OdeBridge::mark_broken() { impl_->broken = true; }

void OdeBridge::write_state(const State& s) {
  Impl& m = *impl_;
  for (int i = 0; i < m.model.nbody; ++i) {
    dBodyID b = m.body[i];
    if (!b) continue;
    dQuaternion q;
    to_ode(s.quat[i], q);
    dBodySetPosition(b, s.pos[i].x(), s.pos[i].y(), s.pos[i].z());
    dBodySetQuaternion(b, q);
    dBodySetLinearVel(b, s.vel[i].x(), s.vel[i].y(), s.vel[i].z());
    dBodySetAngularVel(b, s.angvel[i].x(), s.angvel[i].y(), s.angvel[i].z());
    const bool on = dBodyIsEnabled(b) != 0;
    if (s.enabled[i] && !on) dBodyEnable(b);
    if (!s.enabled[i] && on) dBodyDisable(b);
  }
}

void OdeBridge::read_state(State* s) const {
  const Impl& m = *impl_;
  for (int i = 0; i < m.model.nbody; ++i) {
    dBodyID b = m.body[i];
    if (!b) continue;
    const dReal* p = dBodyGetPosition(b);
    const dReal* q = dBodyGetQuaternion(b);
    const dReal* v = dBodyGetLinearVel(b);
    const dReal* w = dBodyGetAngularVel(b);
    s->pos[i] = Vec3(p[0], p[1], p[2]);
    s->quat[i] = Quat(q[0], q[1], q[2], q[3]);
    s->vel[i] = Vec3(v[0], v[1], v[2]);
    s->angvel[i] = Vec3(w[0], w[1], w[2]);
    s->enabled[i] = dBodyIsEnabled(b) ? 1 : 0;
  }
}

void OdeBridge::add_force_at(int i, const Vec3& F, const Vec3& p) {
  dBodyAddForceAtPos(impl_->body[i], F.x(), F.y(), F.z(), p.x(), p.y(), p.z());
}

void OdeBridge::add_torque(int i, const Vec3& t) {
  dBodyAddTorque(impl_->body[i], t.x(), t.y(), t.z());
}

void OdeBridge::enable(int i) {
  if (impl_->body[i]) dBodyEnable(impl_->body[i]);
}

bool OdeBridge::enabled(int i) const {
  return impl_->body[i] ? dBodyIsEnabled(impl_->body[i]) != 0 : false;
}

Vec3 OdeBridge::position(int i) const {
  if (!impl_->body[i]) return Vec3::Zero();
  const dReal* p = dBodyGetPosition(impl_->body[i]);
  return Vec3(p[0], p[1], p[2]);
}

void OdeBridge::set_velocity(int i, const Vec3& v) {
  if (impl_->body[i]) dBodySetLinearVel(impl_->body[i], v.x(), v.y(), v.z());
}

int OdeBridge::collide(std::vector<std::pair<int, int>>* pairs, double h, double h_soft,
                       double* max_depth, std::vector<std::pair<int, int>>* joined) {
  return impl_->collide(pairs, h, h_soft > 0 ? h_soft : h, max_depth, joined);
}

void OdeBridge::quickstep(unsigned long seed, double h) {
  Impl& m = *impl_;
  m.ensure_thread_data();
  // QuickStep reorders constraint rows with ODE's global RNG: seed it from the step so the
  // result depends on the state alone
  dRandSetSeed(seed);
  m.set_damping(h);
  int ok = 0;
  try {
    ok = dWorldQuickStep(m.world, h);
  } catch (...) {
    m.broken = true;
    throw;
  }
  dJointGroupEmpty(m.contact_group);
  if (!ok) throw OdeFailure("dWorldQuickStep failed (out of memory)");
}

// Each dynamic body's geoms grow by μ = μ0 + (|v| + (|F|/m + |g|) Δt) Δt, the distance it
// can cover this step, capped at 4 shape radii: a ball pulled hard toward a magnet gets a
// speculative contact before it can jump into or through it.
void OdeBridge::update_margins(const State& s, const std::vector<Vec3>& magnetic_force,
                               double dt) {
  Impl& m = *impl_;
  const Model& md = m.model;
  if (m.margin <= 0) return;  // speculative contacts off
  const double g = md.options.gravity.norm();
  for (int b : md.dynamic_bodies) {
    const double reach = (s.vel[b].norm() + (magnetic_force[b].norm() / md.body_mass[b] + g) * dt) * dt;
    for (int k = md.body_shape_adr[b]; k < md.body_shape_adr[b] + md.body_shape_num[b]; ++k)
      m.grow_geom(k, std::min(m.margin + reach, 4.0 * md.shape_radius[k]));
  }
}

void OdeBridge::discard_contacts() { dJointGroupEmpty(impl_->contact_group); }

}  // namespace magsim::engine
