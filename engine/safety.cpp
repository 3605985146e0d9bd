// engine/safety.cpp — the checks that keep a blown-up step from entering the state.
// Each scans a flat array for the first non-finite entry; the message names the step, the
// body (index and name) and the quantity, so a failure can be traced to its source.
#include "engine/safety.hpp"

#include <cmath>
#include <cstdio>

namespace magsim::engine {

namespace {

// "nan", "inf" or "-inf" for the first non-finite component of v
template <class V>
std::string bad_value(const V& v) {
  for (int k = 0; k < v.size(); ++k) {
    const double x = v[k];
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  }
  return "?";
}

template <class V>
[[noreturn]] void raise(const Model& m, long step, int body, const std::string& quantity,
                        const V& value, const std::string& detail = {}) {
  const std::string& name = m.body_name[body];
  throw SimulationError(step, body, name, quantity,
                        "step " + std::to_string(step) + ": body " + std::to_string(body) + " '" +
                            name + "': " + quantity + detail + " is not finite (" +
                            bad_value(value) + ")");
}

}  // namespace

void check_magnetization(const Model& m, const mag::Magnetization& mz, long step) {
  for (int j = 0; j < m.nmoment; ++j) {
    if (!mz.M[j].allFinite())
      raise(m, step, m.moment_body[j], "magnetization", mz.M[j], " of moment " + std::to_string(j));
    if (!mz.M1[j].allFinite())
      raise(m, step, m.moment_body[j], "magnetization", mz.M1[j], " M1 of moment " + std::to_string(j));
    if (!mz.M2[j].allFinite())
      raise(m, step, m.moment_body[j], "magnetization", mz.M2[j], " M2 of moment " + std::to_string(j));
  }
}

void check_forces(const Model& m, const Workspace& ws, long step) {
  for (int j = 0; j < m.nmoment; ++j) {
    if (!ws.F[j].allFinite())
      raise(m, step, m.moment_body[j], "magnetic force", ws.F[j], " on moment " + std::to_string(j));
    if (!ws.tau[j].allFinite())
      raise(m, step, m.moment_body[j], "magnetic torque", ws.tau[j], " on moment " + std::to_string(j));
  }
}

void check_bodies(const Model& m, const State& s, long step) {
  for (int b = 0; b < m.nbody; ++b) {
    if (m.body_type[b] == BodyType::Static) continue;
    // velocities first: a blow-up shows there one step before it reaches the pose
    if (!s.vel[b].allFinite()) raise(m, step, b, "velocity", s.vel[b]);
    if (!s.angvel[b].allFinite()) raise(m, step, b, "angular velocity", s.angvel[b]);
    if (!s.pos[b].allFinite()) raise(m, step, b, "position", s.pos[b]);
    if (!s.quat[b].coeffs().allFinite()) raise(m, step, b, "orientation", s.quat[b].coeffs());
    // the blow-up guard: finite but absurd speeds (dynamic bodies; kinematic ones move as told)
    const double v = s.vel[b].norm(), limit = m.options.max_body_speed;
    if (limit > 0 && v > limit && m.body_type[b] == BodyType::Dynamic) {
      const std::string& name = m.body_name[b];
      char what[160];
      std::snprintf(what, sizeof what, "speed %.4g m/s exceeds options.max_body_speed = %g m/s (a blow-up?)", v, limit);
      throw SimulationError(step, b, name, "speed",
                            "step " + std::to_string(step) + ": body " + std::to_string(b) + " '" + name + "': " + what);
    }
  }
}

}  // namespace magsim::engine
