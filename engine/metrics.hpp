// engine/metrics.hpp — scalar summaries of a state, for stability tests and charts.
#pragma once

#include "engine/profile.hpp"
#include "engine/state.hpp"

namespace magsim::engine {

struct Metrics {
  double time = 0.0;             ///< simulated time (s)
  long steps = 0;
  int dynamic_bodies = 0;
  double kinetic_energy = 0.0;   ///< Σ ½ m |v|² + ½ ωᵀ I_world ω over dynamic bodies (J)
  double max_speed = 0.0;        ///< max |v| over dynamic bodies (m/s)
  double bounding_radius = 0.0;  ///< max |x_i − x̄| over dynamic bodies, x̄ their centroid (m)
  /// max |x_i − x_magnet| over dynamic bodies other than the first magnet body (m); 0 when
  /// the scene has no magnet body
  double magnet_radius = 0.0;
  /// dynamic bodies (magnets excluded) reachable from a magnet body through the contact
  /// graph of the last step, walking through dynamic bodies only
  int attached = 0;
  Vec3 momentum = Vec3::Zero();  ///< Σ m v over dynamic bodies (kg·m/s), for drift
  int iterations = 0;            ///< magnetization iterations of the last step
  bool converged = true;         ///< the last step's magnetization converged
  int contacts = 0;              ///< contact joints of the last step
};

Metrics compute_metrics(const Model& model, const State& s, const StepProfile& last);

}  // namespace magsim::engine
