// engine/sleep.cpp — sleeping islands (SimOptions::sleep).
//
// An island is a set of dynamic bodies joined by contacts. A body is still while its mean
// velocities over the last half sleep_time, as exponential averages,
//   v̄ ← v̄ + (v − v̄) h/τ,  ω̄ ← ω̄ + (ω − ω̄) h/τ,  τ = sleep_time/2,
// give |v̄| + |ω̄| r_b < sleep_speed (r_b the bounding radius; ω̄ is left out for a body whose
// turning changes nothing the model sees: spheres and induced moments at its centre). A pile's
// contacts make bodies jitter fast in place; their mean velocity is the creep a viewer sees.
// An island falls asleep when it rests on the world (one of its bodies touches the ground, a
// static or a kinematic body: a body slow at the top of its flight, or starting from rest,
// is not at rest) and every body in it has been still for sleep_time, one in 100 of them
// allowed to rattle in place at up to 5 × sleep_speed (kRattle below). Asleep:
//   - its bodies are disabled in ODE (no step, no gravity, no contact rows) with v = ω = 0;
//   - its moments stay field sources, their magnetization frozen (MomentDesc::frozen): the
//     relaxation leaves them as they are, so a sleeping island's own field never changes;
//   - its forces are still summed with everyone's, but given to no body.
// It wakes when
//   - an awake dynamic body or a moving kinematic body overlaps one of its bodies, or closes
//     the gap to it within the sub-step (a contact joint the sub-step's collisions tie to it,
//     ode_bridge.cpp; a gap not closed holds the mover as the world would);
//   - the field at one of its moments has moved by more than
//       tol · max(|H_sleep|, 0.01 Ms)    (tol = sleep_field_tolerance; Ms → |M| for a magnet)
//     since the island fell asleep: only awake sources can move it;
//   - the user asks (Simulation::wake_all).
// Every decision reads the State and the step's contacts, in body order: the same inputs
// give the same islands on every path.
#include "engine/sleep.hpp"

#include "engine/ode_bridge.hpp"

#include <algorithm>
#include <numeric>

namespace magsim::engine {

namespace {

// A pile's rattlers: bodies squeezed by the field that the contact solver never quite settles
// jitter in place with mean speeds of a few sleep_speeds (falling_magnet: up to 4 × 0.02 m/s
// while the rest creeps below 0.02). An island may hold one in kRattlersPer, each below
// kRattle × sleep_speed; they sleep with it.
constexpr double kRattle = 5.0;
constexpr int kRattlersPer = 100;

bool asleep(const State& s, int b) { return !s.sleep_island.empty() && s.sleep_island[b] >= 0; }

bool kinematic_moving(const Model& m, const State& s, int b) {
  return b >= 0 && m.body_type[b] == BodyType::Kinematic &&
         (s.vel[b] != Vec3::Zero() || s.angvel[b] != Vec3::Zero());
}

// Whether a body's orientation changes anything the model sees: not for a body of spheres and
// induced moments all at its centre of mass.
bool turn_matters(const Model& m, int b) {
  for (int k = m.body_shape_adr[b]; k < m.body_shape_adr[b] + m.body_shape_num[b]; ++k)
    if (m.shape_kind[k] != ShapeKind::Sphere || m.shape_offset[k] != Vec3::Zero()) return true;
  for (int j = m.body_moment_adr[b]; j < m.body_moment_adr[b] + m.body_moment_num[b]; ++j)
    if (m.moment_permanent[j] || m.moment_offset[j] != Vec3::Zero()) return true;
  return false;
}

int find(std::vector<int>& parent, int a) {
  while (parent[a] != a) {
    parent[a] = parent[parent[a]];
    a = parent[a];
  }
  return a;
}

// Joins the sets of a and b; the root is the lower index, so an island's id is its lowest body.
void unite(std::vector<int>& parent, int a, int b) {
  const int ra = find(parent, a), rb = find(parent, b);
  if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
}

void wake_island(const Model& m, int island, State* s, OdeBridge* ode) {
  for (int b : m.dynamic_bodies) {
    if (s->sleep_island[b] != island) continue;
    s->sleep_island[b] = -1;
    s->still_time[b] = 0.0;
    s->enabled[b] = 1;
    if (ode) ode->enable(b);
  }
}

}  // namespace

void prepare_sleep(const Model& m, State* s) {
  if (!m.options.sleep) return;
  s->still_time.resize(m.nbody, 0.0);
  s->still_vel.resize(m.nbody, Vec3::Zero());
  s->still_angvel.resize(m.nbody, Vec3::Zero());
  s->sleep_island.resize(m.nbody, -1);
  s->H_sleep.resize(m.nmoment, Vec3::Zero());
}

int asleep_count(const State& s) {
  return static_cast<int>(std::count_if(s.sleep_island.begin(), s.sleep_island.end(),
                                        [](int i) { return i >= 0; }));
}

bool world_asleep(const Model& m, const State& s) {
  if (!m.options.sleep || m.dynamic_bodies.empty() || !s.magnetized) return false;
  for (int b : m.dynamic_bodies)
    if (!asleep(s, b)) return false;
  for (int b = 0; b < m.nbody; ++b)
    if (kinematic_moving(m, s, b)) return false;
  return true;
}

void freeze_sleeping(const Model& m, const State& s, mag::MomentDesc* set) {
  if (!m.options.sleep) return;
  set->frozen.assign(m.nmoment, 0);
  for (int j = 0; j < m.nmoment; ++j) set->frozen[j] = asleep(s, m.moment_body[j]) ? 1 : 0;
}

int wake_touched(const Model& m, const std::vector<std::pair<int, int>>& pairs,
                 const mag::MomentDesc& set, const std::vector<Vec3>& F,
                 const std::vector<Vec3>& tau, State* next, OdeBridge* ode) {
  if (!m.options.sleep || asleep_count(*next) == 0) return 0;
  int woken = 0;
  auto mover = [&](int b) {
    if (b < 0) return false;
    if (m.body_type[b] == BodyType::Dynamic) return !asleep(*next, b);
    return kinematic_moving(m, *next, b);
  };
  for (const auto& [a, b] : pairs) {
    for (const auto& [sleeper, other] : {std::pair{a, b}, std::pair{b, a}}) {
      if (sleeper < 0 || !asleep(*next, sleeper) || !mover(other)) continue;
      const int island = next->sleep_island[sleeper];
      // the bodies join this sub-step with the magnetic forces everyone else was given
      for (int c : m.dynamic_bodies) {
        if (next->sleep_island[c] != island) continue;
        for (int j = m.body_moment_adr[c]; j < m.body_moment_adr[c] + m.body_moment_num[c]; ++j) {
          if (j >= static_cast<int>(F.size())) break;
          ode->add_force_at(c, F[j], set.position[j]);
          if (m.moment_permanent[j] && j < static_cast<int>(tau.size())) ode->add_torque(c, tau[j]);
        }
      }
      wake_island(m, island, next, ode);
      ++woken;
    }
  }
  return woken;
}

void carry_sleeping_pairs(const Model& m, const std::vector<std::pair<int, int>>& before, State* next) {
  if (!m.options.sleep || asleep_count(*next) == 0) return;
  auto rests = [&](int b) { return b < 0 || m.body_type[b] != BodyType::Dynamic || asleep(*next, b); };
  const std::size_t n = next->contact_pairs.size();
  for (const auto& [a, b] : before)
    if (rests(a) && rests(b) && (asleep(*next, std::max(a, b)) || (a >= 0 && asleep(*next, a))))
      next->contact_pairs.emplace_back(a, b);
  if (next->contact_pairs.size() == n) return;
  std::sort(next->contact_pairs.begin(), next->contact_pairs.end());
  next->contact_pairs.erase(std::unique(next->contact_pairs.begin(), next->contact_pairs.end()),
                            next->contact_pairs.end());
}

void settle(const Model& m, State* next, std::vector<int>* fell_asleep) {
  fell_asleep->clear();
  if (!m.options.sleep) return;
  const SimOptions& o = m.options;
  // a sleeper ODE enabled (a joint tied it to an enabled body) woke, with its island
  for (int b : m.dynamic_bodies)
    if (asleep(*next, b) && next->enabled[b]) wake_island(m, next->sleep_island[b], next, nullptr);
  // still time of the awake bodies; touching a moving kinematic body is never still
  std::vector<std::uint8_t> pushed(m.nbody, 0);
  for (const auto& [a, b] : next->contact_pairs) {
    if (kinematic_moving(m, *next, a) && b >= 0) pushed[b] = 1;
    if (kinematic_moving(m, *next, b) && a >= 0) pushed[a] = 1;
  }
  const double a = std::min(1.0, 2.0 * o.dt / o.sleep_time);  // h/τ
  std::vector<std::uint8_t> quiet(m.nbody, 0);
  for (int b : m.dynamic_bodies) {
    if (asleep(*next, b)) continue;
    next->still_vel[b] += a * (next->vel[b] - next->still_vel[b]);
    next->still_angvel[b] += a * (next->angvel[b] - next->still_angvel[b]);
    const double turn = turn_matters(m, b) ? next->still_angvel[b].norm() * m.body_radius[b] : 0.0;
    const double speed = next->still_vel[b].norm() + turn;
    quiet[b] = speed < o.sleep_speed ? 1 : 0;
    const bool still = !pushed[b] && speed < kRattle * o.sleep_speed;
    next->still_time[b] = still ? next->still_time[b] + o.dt : 0.0;
  }
  // islands of awake dynamic bodies (contacts with the ground, static and kinematic bodies
  // do not join islands)
  std::vector<int> parent(m.nbody);
  std::iota(parent.begin(), parent.end(), 0);
  auto joins = [&](int b) { return b >= 0 && m.body_type[b] == BodyType::Dynamic && !asleep(*next, b); };
  for (const auto& [a, b] : next->contact_pairs) {
    if (joins(a) && joins(b)) unite(parent, a, b);
  }
  // an island is restless while a body has not been still for sleep_time, while more than one
  // in kRattlersPer of its bodies rattle (still, but not quiet), or while it touches no body
  // of the world
  std::vector<std::uint8_t> restless(m.nbody, 0);
  std::vector<int> size(m.nbody, 0), rattlers(m.nbody, 0);
  for (int b : m.dynamic_bodies) {
    if (asleep(*next, b)) continue;
    const int r = find(parent, b);
    ++size[r];
    if (!quiet[b]) ++rattlers[r];
    if (next->still_time[b] < o.sleep_time) restless[r] = 1;
  }
  std::vector<std::uint8_t> supported(m.nbody, 0);
  auto world = [&](int b) { return b < 0 || m.body_type[b] != BodyType::Dynamic; };
  for (const auto& [a, b] : next->contact_pairs) {
    if (world(a) && joins(b)) supported[find(parent, b)] = 1;
    if (world(b) && joins(a)) supported[find(parent, a)] = 1;
  }
  for (int b : m.dynamic_bodies)
    if (!asleep(*next, b) && find(parent, b) == b && (rattlers[b] > size[b] / kRattlersPer || !supported[b]))
      restless[b] = 1;
  for (int b : m.dynamic_bodies) {
    if (asleep(*next, b) || restless[find(parent, b)]) continue;
    fell_asleep->push_back(b);
    next->vel[b] = Vec3::Zero();
    next->angvel[b] = Vec3::Zero();
    next->enabled[b] = 0;
  }
}

int finish_sleep(const Model& m, const std::vector<int>& fell_asleep, const std::vector<Vec3>& H,
                 State* next) {
  if (!m.options.sleep || H.size() != static_cast<std::size_t>(m.nmoment)) return 0;
  const double tol = m.options.sleep_field_tolerance;
  // the islands asleep before this step: has an awake source moved the field at them?
  std::vector<int> wake;
  for (int b : m.dynamic_bodies) {
    const int island = next->sleep_island[b];
    if (island < 0 || std::find(wake.begin(), wake.end(), island) != wake.end()) continue;
    for (int j = m.body_moment_adr[b]; j < m.body_moment_adr[b] + m.body_moment_num[b]; ++j) {
      const double scale = m.moment_permanent[j] ? next->mag.M[j].norm() : m.moment_Ms[j];
      const double limit = tol * std::max(next->H_sleep[j].norm(), 0.01 * scale);
      if ((H[j] - next->H_sleep[j]).norm() > limit) {
        wake.push_back(island);
        break;
      }
    }
  }
  for (int island : wake) wake_island(m, island, next, nullptr);
  // the islands that fell asleep at this state: their magnetization is converged (they were
  // solved free), and this is the field they are held against; an island's id is its lowest
  // body index, found again from the contacts among them
  if (!fell_asleep.empty()) {
    std::vector<int> parent(m.nbody);
    std::iota(parent.begin(), parent.end(), 0);
    std::vector<std::uint8_t> fell(m.nbody, 0);
    for (int b : fell_asleep) fell[b] = 1;
    for (const auto& [a, b] : next->contact_pairs) {
      if (a >= 0 && fell[a] && fell[b]) unite(parent, a, b);
    }
    for (int b : fell_asleep) {
      next->sleep_island[b] = find(parent, b);
      next->still_time[b] = 0.0;
      for (int j = m.body_moment_adr[b]; j < m.body_moment_adr[b] + m.body_moment_num[b]; ++j)
        next->H_sleep[j] = H[j];
    }
  }
  return static_cast<int>(wake.size());
}

void wake_all(const Model& m, State* s) {
  if (s->sleep_island.empty()) return;
  for (int b : m.dynamic_bodies)
    if (s->sleep_island[b] >= 0) wake_island(m, s->sleep_island[b], s, nullptr);
}

}  // namespace magsim::engine
