// engine/substeps.cpp — how many rigid sub-steps a frame needs (SimOptions::max_substeps).
//
// A 4 g ball pulled at 10⁴ m/s² covers three radii in one 1 ms step; contacts, speculative
// margins and the magnetization all see it only at the step's ends. Splitting the frame
// bounds how far any body moves between two looks. Two terms, over the bodies that touched
// something in the last frame; a ball in free flight moves ballistically whatever the step,
// and one ball thrown off at 8 m/s would otherwise split every frame of the whole scene for
// as long as it flies (falling_magnet, ≤ 8 sub-steps, 6.5 per frame on average over 0.6 s
// counting every body, 2.2 counting those in contact):
//  - motion, over the bodies that touched another body (not only the ground plane: see
//    choose_substeps): the velocity the body had and its change over the last frame
//    (contact forces included), (|v| + |Δv|) h ≤ reach · r_min;
//  - load (SimOptions::substep_load): the magnetic acceleration a = |F|/m the contacts hold,
//    a h² ≤ reach · r_min. A pile resting against a magnet does not move, but QuickStep
//    leaves a fraction ε of each contact force unbalanced, and the body sinks ε a h² into its
//    contacts in a sub-step of h; the error reduction then pushes it out against the magnet,
//    which pulls it back in at about a h √(2ε). In alphabets (letters pressed onto the
//    collider at ~10⁵ m/s²) the contacts' largest pushes, up to 12.6 J of work in a frame,
//    came right after frames of a single sub-step (25 letters, each step traced).
//    Scenes whose piles rest under such loads split every frame: alphabets 13
//    sub-steps per frame, and the magnetization, re-solved per sub-step from a nearer
//    start, converges where it hit its cap before (35 frames of 2000 instead of 1531).
#include "engine/stages.hpp"

#include <algorithm>
#include <cmath>

namespace magsim::engine {

// n = ⌈ max( max_{b touching a body} (|v_b| + |Δv_b|) Δt_r / (reach · r_min),
//            max_{b touching anything} √(a_b Δt_r² / (reach · r_min)) ) ⌉,  a_b = |F_b| / m_b,
// clamped to [1, max_substeps]; F_b the magnetic force of the last (sub-)step (State::mag_accel).
int choose_substeps(const Model& m, const State& s) {
  const SimOptions& o = m.options;
  if (o.max_substeps <= 1 || m.min_dynamic_radius <= 0) return 1;
  const bool load = o.substep_load && !s.mag_accel.empty();
  double speed = 0.0, acc = 0.0;
  // contact_pairs is sorted (a < b, −1 = the ground): every body that touched something.
  // A contact with the ground plane does not count for the motion term: a half-space cannot
  // be tunnelled, and a ball rolling or sliding on it moves along the contact (in
  // falling_magnet one ball thrown off at 2.5 m/s, rolling out on the floor, split every
  // frame of the scene for a second). Its load still counts.
  auto consider = [&](int b, bool motion) {
    if (b < 0 || m.body_type[b] != BodyType::Dynamic) return;
    if (o.sleep && !s.sleep_island.empty() && s.sleep_island[b] >= 0) return;  // not stepped
    if (motion) {
      const double dv = s.dvel.empty() ? 0.0 : s.dvel[b].norm();
      speed = std::max(speed, s.vel[b].norm() + dv);
    }
    if (load) acc = std::max(acc, s.mag_accel[b]);
  };
  for (const auto& [a, b] : s.contact_pairs) {
    const bool on_ground = a < 0;
    consider(a, !on_ground);
    consider(b, !on_ground);
  }
  const double reach = o.substep_reach * m.min_dynamic_radius;
  const double n =
      std::max(std::ceil(speed * o.dt / reach), std::ceil(std::sqrt(acc / reach) * o.dt));
  if (!(n > 1)) return 1;  // also NaN (the safety check names the body afterwards)
  return n >= o.max_substeps ? o.max_substeps : static_cast<int>(n);
}

}  // namespace magsim::engine
