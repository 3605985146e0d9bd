// engine/state.cpp — initial state, shape check and the FNV-1a state hash.
#include "engine/state.hpp"

#include "engine/sleep.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace magsim::engine {

State initial_state(const Model& m) {
  State s;
  s.pos = m.body_pos0;
  s.quat = m.body_quat0;
  s.vel = m.body_vel0;
  s.angvel = m.body_angvel0;
  s.dvel.assign(m.nbody, Vec3::Zero());
  s.mag_accel.assign(m.nbody, 0.0);
  s.enabled.assign(m.nbody, 1);
  prepare_sleep(m, &s);
  mag::Magnetization& mz = s.mag;
  mz.M1.assign(m.nmoment, Vec3::Zero());
  mz.M2.assign(m.nmoment, Vec3::Zero());
  mz.M.assign(m.nmoment, Vec3::Zero());
  mz.seeded.assign(m.nmoment, 0);
  for (int j = 0; j < m.nmoment; ++j) {
    if (!m.moment_permanent[j]) continue;
    // a permanent moment's M = m/V in world axes, M1 = M2 = 0 (as mag::Magnetization keeps it)
    mz.M[j] = (m.body_quat0[m.moment_body[j]] * m.moment_m[j]) / m.moment_volume[j];
    mz.seeded[j] = 1;
  }
  return s;
}

namespace {

// FNV-1a, 64 bit: h ← (h ⊕ byte) · 1099511628211, h₀ = 14695981039346656037
struct Fnv1a {
  std::uint64_t h = 14695981039346656037ull;
  void bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= c[i];
      h *= 1099511628211ull;
    }
  }
  void vecs(const std::vector<Vec3>& v) {
    for (const Vec3& x : v) bytes(x.data(), 3 * sizeof(double));
  }
};

}  // namespace

std::uint64_t state_hash(const State& s) {
  Fnv1a f;
  f.vecs(s.pos);
  for (const Quat& q : s.quat) f.bytes(q.coeffs().data(), 4 * sizeof(double));
  f.vecs(s.vel);
  f.vecs(s.angvel);
  f.vecs(s.mag.M1);
  f.vecs(s.mag.M2);
  f.vecs(s.mag.M);
  return f.h;
}

void check_state_shape(const Model& m, const State& s) {
  const auto nb = static_cast<std::size_t>(m.nbody);
  const auto nm = static_cast<std::size_t>(m.nmoment);
  if (s.pos.size() != nb || s.quat.size() != nb || s.vel.size() != nb || s.angvel.size() != nb ||
      s.enabled.size() != nb)
    throw std::invalid_argument("State does not fit the model: expected " + std::to_string(nb) +
                                " bodies, got " + std::to_string(s.pos.size()));
  const mag::Magnetization& mz = s.mag;
  if (mz.M1.size() != nm || mz.M2.size() != nm || mz.M.size() != nm || mz.seeded.size() != nm)
    throw std::invalid_argument("State does not fit the model: expected " + std::to_string(nm) +
                                " moments, got " + std::to_string(mz.M.size()));
  if (!s.dvel.empty() && s.dvel.size() != nb)
    throw std::invalid_argument("State does not fit the model: dvel has " +
                                std::to_string(s.dvel.size()) + " entries, expected " +
                                std::to_string(nb) + " (or none)");
  if (!s.mag_accel.empty() && s.mag_accel.size() != nb)
    throw std::invalid_argument("State does not fit the model: mag_accel has " +
                                std::to_string(s.mag_accel.size()) + " entries, expected " +
                                std::to_string(nb) + " (or none)");
  if (!s.eddy.B.empty() && s.eddy.B.size() != nm)
    throw std::invalid_argument("State does not fit the model: eddy.B has " +
                                std::to_string(s.eddy.B.size()) + " entries, expected " +
                                std::to_string(nm) + " (or none)");
  if (!(s.eddy.h >= 0.0) || !std::isfinite(s.eddy.h))
    throw std::invalid_argument("State eddy.h is negative or not finite");
  auto sized = [](const auto& v, std::size_t n, const char* what) {
    if (!v.empty() && v.size() != n)
      throw std::invalid_argument(std::string("State does not fit the model: ") + what + " has " +
                                  std::to_string(v.size()) + " entries, expected " +
                                  std::to_string(n) + " (or none)");
  };
  sized(s.still_time, nb, "still_time");
  sized(s.still_vel, nb, "still_vel");
  sized(s.still_angvel, nb, "still_angvel");
  sized(s.sleep_island, nb, "sleep_island");
  sized(s.H_sleep, nm, "H_sleep");
  for (std::size_t b = 0; b < s.sleep_island.size(); ++b)
    if (s.sleep_island[b] < -1 || s.sleep_island[b] >= static_cast<int>(nb))
      throw std::invalid_argument("State sleep_island[" + std::to_string(b) + "] is not a body index or -1");
  if (s.step < 0) throw std::invalid_argument("State step count is negative");
}

}  // namespace magsim::engine
