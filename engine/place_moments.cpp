// engine/place_moments.cpp — stage 1 of a step: moments take their world poses from the
// bodies they are fixed to, and magnetizations move between State and MomentSet.
#include "engine/stages.hpp"

namespace magsim::engine {

mag::MomentSet make_moment_set(const Model& m) {
  mag::MomentSet set;
  for (int j = 0; j < m.nmoment; ++j) {
    const int b = m.moment_body[j];
    if (m.moment_permanent[j])
      set.add_permanent(Vec3::Zero(), m.moment_volume[j], m.moment_m[j], b);
    else
      set.add_induced(Vec3::Zero(), m.moment_volume[j], m.moment_Ms[j], b);
    set.radius[j] = m.moment_interaction_radius[j];
  }
  set.H0 = m.H0;
  return set;
}

// p_j = x_b + R_b o_j;  permanent: m_j = R_b m_j^body, M_j = m_j / V_j
void place_moments(const Model& m, const State& s, mag::MomentSet* set) {
  for (int b = 0; b < m.nbody; ++b) {
    const int adr = m.body_moment_adr[b], num = m.body_moment_num[b];
    if (num == 0) continue;
    const Mat3 R = s.quat[b].toRotationMatrix();
    const Vec3& x = s.pos[b];
    for (int j = adr; j < adr + num; ++j) {
      set->position[j] = x + R * m.moment_offset[j];
      if (m.moment_permanent[j]) {
        set->m_perm[j] = R * m.moment_m[j];
        set->M[j] = set->m_perm[j] / m.moment_volume[j];
      }
    }
  }
}

void load_magnetization(const State& s, mag::MomentSet* set) {
  set->M1 = s.M1;
  set->M2 = s.M2;
  set->M = s.M;
  set->seeded = s.seeded;
}

void store_magnetization(const mag::MomentSet& set, State* s) {
  s->M1 = set.M1;
  s->M2 = set.M2;
  s->M = set.M;
  s->seeded = set.seeded;
}

}  // namespace magsim::engine
