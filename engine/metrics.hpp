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
  /// the rotational part Σ ½ ωᵀ I_world ω of kinetic_energy (J): balls spinning in place
  /// hold kinetic energy that no speed or displacement shows
  double rotational_energy = 0.0;
  double max_speed = 0.0;        ///< max |v| over dynamic bodies (m/s)
  double bounding_radius = 0.0;  ///< max |x_i − x̄| over dynamic bodies, x̄ their centroid (m)
  /// max |x_i − x_magnet| over dynamic bodies other than the first magnet body (m); 0 when
  /// the scene has no magnet body
  double magnet_radius = 0.0;
  /// dynamic bodies (magnets excluded) reachable from a magnet body through the contact
  /// graph of the last step, walking through dynamic bodies only
  int attached = 0;
  /// dynamic bodies (magnets excluded) reached from a magnet body through the contact graph
  /// of the last step without passing through a body that touches the ground: a body with
  /// a contact to the ground is neither counted nor walked through. Unlike `attached`, a
  /// ball lying on the floor against a chain of balls is not held.
  int held = 0;
  /// dynamic bodies (magnets excluded) whose centre is farther than Model::escape_radius
  /// from the centroid of the magnet bodies (the magnet itself when there is one): the
  /// horizontal (x, y) distance when the scene has gravity (balls that fell off spread over
  /// the floor; sakura_tree's 8 tip magnets centre on the trunk), the 3-D distance when
  /// gravity is zero (alphabets). 0 when escape_radius is 0 or there is no magnet body.
  int escaped = 0;
  Vec3 momentum = Vec3::Zero();  ///< Σ m v over dynamic bodies (kg·m/s), for drift
  int iterations = 0;            ///< magnetization iterations of the last step
  bool converged = true;         ///< the last step's magnetization converged
  int contacts = 0;              ///< contact joints of the last step
};

Metrics compute_metrics(const Model& model, const State& s, const StepProfile& last);

/// The bodies Metrics::held counts (the lifted pile, without the bodies on the floor), in
/// the order the contact graph reaches them.
std::vector<int> held_bodies(const Model& model, const State& s);

/// The bodies Metrics::escaped counts, ascending (empty when escape_radius is 0).
std::vector<int> escaped_bodies(const Model& model, const State& s);

/// Kinetic energy of one body, ½ m |v|² + ½ ωᵀ I_world ω (J); the one formula of the
/// metrics and the energy audit.
double kinetic_energy(const Model& model, const State& s, int body);
/// Its rotational part ½ ωᵀ I_world ω (J).
double rotational_energy(const Model& model, const State& s, int body);

}  // namespace magsim::engine
