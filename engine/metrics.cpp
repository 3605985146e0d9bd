// engine/metrics.cpp — energy, speed, extent, attachment (attached, held, escaped) and
// momentum of a state.
#include "engine/metrics.hpp"

#include <algorithm>

namespace magsim::engine {

namespace {

// Dynamic bodies reachable from any magnet body through contact pairs, walking through
// dynamic bodies only. `attached` (skip_grounded = false): a ball on the floor is not attached
// because the floor touches it, but one lying on the floor against a chain of balls is.
// `held` (skip_grounded = true): a body that touches the ground (a contact pair with −1) is
// supported by the floor, not held by the magnet, so it is neither counted nor walked
// through. Magnet bodies are the seeds, whether or not they touch the ground themselves.
std::vector<int> reachable(const Model& m, const State& s, bool skip_grounded) {
  std::vector<int> found;
  if (s.contact_pairs.empty()) return found;
  std::vector<std::vector<int>> adj(m.nbody);
  std::vector<std::uint8_t> grounded(m.nbody, 0);
  for (const auto& [a, b] : s.contact_pairs) {
    if (a < 0 || b < 0) {  // the ground
      grounded[a < 0 ? b : a] = skip_grounded ? 1 : 0;
      continue;
    }
    adj[a].push_back(b);
    adj[b].push_back(a);
  }
  std::vector<std::uint8_t> seen(m.nbody, 0);
  std::vector<int> queue;
  for (int b = 0; b < m.nbody; ++b)
    if (m.body_magnet[b]) {
      seen[b] = 1;
      queue.push_back(b);
    }
  for (std::size_t head = 0; head < queue.size(); ++head) {
    for (int nb : adj[queue[head]]) {
      if (seen[nb] || grounded[nb] || m.body_type[nb] != BodyType::Dynamic) continue;
      seen[nb] = 1;
      found.push_back(nb);
      queue.push_back(nb);
    }
  }
  return found;
}

// Dynamic non-magnet bodies farther than R_esc from c, the centroid of the magnet bodies:
// |x − c| over (x, y) only when there is gravity (a ball that fell spreads out on the
// floor; height says nothing about escape), over (x, y, z) in zero gravity.
std::vector<int> find_escaped(const Model& m, const State& s) {
  std::vector<int> escaped;
  if (!(m.escape_radius > 0)) return escaped;
  Vec3 c = Vec3::Zero();
  int magnets = 0;
  for (int b = 0; b < m.nbody; ++b)
    if (m.body_magnet[b]) {
      c += s.pos[b];
      ++magnets;
    }
  if (magnets == 0) return escaped;
  c /= static_cast<double>(magnets);
  const bool horizontal = m.options.gravity.norm() != 0.0;
  for (int b : m.dynamic_bodies) {
    if (m.body_magnet[b]) continue;
    Vec3 d = s.pos[b] - c;
    if (horizontal) d.z() = 0.0;
    if (d.norm() > m.escape_radius) escaped.push_back(b);
  }
  return escaped;
}

}  // namespace

std::vector<int> escaped_bodies(const Model& m, const State& s) { return find_escaped(m, s); }

std::vector<int> held_bodies(const Model& m, const State& s) { return reachable(m, s, true); }

double rotational_energy(const Model& m, const State& s, int b) {
  // ½ ωᵀ (R I Rᵀ) ω = ½ ω_bᵀ I ω_b with ω_b = Rᵀ ω the body-frame angular velocity
  const Vec3 w_body = s.quat[b].toRotationMatrix().transpose() * s.angvel[b];
  return 0.5 * w_body.dot(m.body_inertia[b] * w_body);
}

double kinetic_energy(const Model& m, const State& s, int b) {
  // E = ½ m |v|² + ½ ωᵀ (R I Rᵀ) ω
  return 0.5 * m.body_mass[b] * s.vel[b].squaredNorm() + rotational_energy(m, s, b);
}

Metrics compute_metrics(const Model& m, const State& s, const StepProfile& last) {
  Metrics r;
  r.time = static_cast<double>(s.step) * m.options.dt;
  r.steps = s.step;
  r.dynamic_bodies = static_cast<int>(m.dynamic_bodies.size());
  r.iterations = last.iterations;
  r.converged = last.converged;
  r.contacts = last.contacts;

  Vec3 centroid = Vec3::Zero();
  for (int b : m.dynamic_bodies) {
    const double mass = m.body_mass[b];
    const Vec3& v = s.vel[b];
    r.kinetic_energy += kinetic_energy(m, s, b);
    r.rotational_energy += rotational_energy(m, s, b);
    r.max_speed = std::max(r.max_speed, v.norm());
    r.momentum += mass * v;
    centroid += s.pos[b];
  }
  if (!m.dynamic_bodies.empty()) {
    centroid /= static_cast<double>(m.dynamic_bodies.size());
    for (int b : m.dynamic_bodies) r.bounding_radius = std::max(r.bounding_radius, (s.pos[b] - centroid).norm());
  }
  const auto magnet = std::find(m.body_magnet.begin(), m.body_magnet.end(), 1);
  if (magnet != m.body_magnet.end()) {
    const int mb = static_cast<int>(magnet - m.body_magnet.begin());
    for (int b : m.dynamic_bodies)
      if (!m.body_magnet[b]) r.magnet_radius = std::max(r.magnet_radius, (s.pos[b] - s.pos[mb]).norm());
  }
  r.attached = static_cast<int>(reachable(m, s, false).size());
  r.held = static_cast<int>(reachable(m, s, true).size());
  r.escaped = static_cast<int>(find_escaped(m, s).size());
  return r;
}

}  // namespace magsim::engine
