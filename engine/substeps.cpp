// engine/substeps.cpp — how many rigid sub-steps a frame needs (SimOptions::max_substeps).
//
// A 4 g ball pulled at 10⁴ m/s² covers three radii in one 1 ms step; contacts, speculative
// margins and the magnetization all see it only at the step's ends. Splitting the frame
// bounds how far any body moves between two looks. The criterion reads the motion the
// bodies actually had (velocity and its change over the last frame, contact forces
// included), not the magnetic force alone: a pile resting against a magnet carries 10⁴ m/s²
// of magnetic load and needs no sub-steps. Only bodies that touched something in the last
// frame count: a ball in free flight moves ballistically whatever the step, and one ball
// thrown off at 8 m/s would otherwise split every frame of the whole scene for as long as it
// flies (falling_magnet, ≤ 8 sub-steps: 6.5 per frame on average over 0.6 s counting every
// body, 2.2 counting those in contact; issue #12).
#include "engine/stages.hpp"

#include <algorithm>
#include <cmath>

namespace magsim::engine {

// n = ⌈ max_{b touching} (|v_b| + |Δv_b|) Δt_r / (reach · r_min) ⌉, clamped to [1, max_substeps]
int choose_substeps(const Model& m, const State& s) {
  const SimOptions& o = m.options;
  if (o.max_substeps <= 1 || m.min_dynamic_radius <= 0) return 1;
  double speed = 0.0;
  // contact_pairs is sorted (a < b, −1 = the ground): every body that touched something
  auto consider = [&](int b) {
    if (b < 0 || m.body_type[b] != BodyType::Dynamic) return;
    const double dv = s.dvel.empty() ? 0.0 : s.dvel[b].norm();
    speed = std::max(speed, s.vel[b].norm() + dv);
  };
  for (const auto& [a, b] : s.contact_pairs) {
    consider(a);
    consider(b);
  }
  const double n = std::ceil(speed * o.dt / (o.substep_reach * m.min_dynamic_radius));
  if (!(n > 1)) return 1;  // also NaN (the safety check names the body afterwards)
  return n >= o.max_substeps ? o.max_substeps : static_cast<int>(n);
}

}  // namespace magsim::engine
