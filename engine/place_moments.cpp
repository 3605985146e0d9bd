// engine/place_moments.cpp — stage 1 of a step: moments take their world poses from the
// bodies they are fixed to.
#include "engine/stages.hpp"

namespace magsim::engine {

mag::MomentDesc make_moment_desc(const Model& m) {
  mag::MomentDesc set;
  const auto n = static_cast<std::size_t>(m.nmoment);
  set.position.assign(n, Vec3::Zero());
  set.volume = m.moment_volume;
  set.Ms.resize(n);
  set.kind.resize(n);
  set.m_perm.resize(n);
  set.group.resize(n);
  for (int j = 0; j < m.nmoment; ++j) {
    const bool perm = m.moment_permanent[j];
    set.Ms[j] = perm ? 0.0 : m.moment_Ms[j];
    set.kind[j] = perm ? mag::MomentKind::Permanent : mag::MomentKind::Induced;
    set.m_perm[j] = perm ? m.moment_m[j] : Vec3::Zero();
    set.group[j] = m.moment_body[j];
  }
  set.radius = m.moment_interaction_radius;
  set.H0 = m.H0;
  return set;
}

// p_j = x_b + R_b o_j;  permanent: m_j = R_b m_j^body, M_j = m_j / V_j
void place_moments(const Model& m, const State& s, mag::MomentDesc* set, mag::Magnetization* mz) {
  for (int b = 0; b < m.nbody; ++b) {
    const int adr = m.body_moment_adr[b], num = m.body_moment_num[b];
    if (num == 0) continue;
    const Mat3 R = s.quat[b].toRotationMatrix();
    const Vec3& x = s.pos[b];
    for (int j = adr; j < adr + num; ++j) {
      set->position[j] = x + R * m.moment_offset[j];
      if (m.moment_permanent[j]) {
        set->m_perm[j] = R * m.moment_m[j];
        if (mz) mz->M[j] = set->m_perm[j] / m.moment_volume[j];
      }
    }
  }
}

}  // namespace magsim::engine
