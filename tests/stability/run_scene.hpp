// tests/stability/run_scene.hpp — runs a registry scene and keeps what the stability tests
// measure: the metrics series and their maxima over a trailing window.
#pragma once

#include "engine/simulation.hpp"
#include "scenes/registry.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace magsim::test {

/// E = K + U_g + U* from 0.05 s on, step by step: the most it stood above its running minimum
/// (rise) and E(0.05 s) − E(now) (lost), in J, as tools/scripts/ensemble.py reads them.
struct EnergyWatch {
  explicit EnergyWatch(double dt) : from(std::lround(0.05 / dt)) {}
  void after_step(long k, double E) {
    if (k == from) start = low = E;
    if (k < from) return;
    low = std::min(low, E);
    rise = std::max(rise, E - low);
    lost = start - E;
  }
  long from;
  double start = 0, low = 0, rise = 0, lost = 0;
};

struct SceneRun {
  engine::Metrics last;
  double tail_max_speed = 0;     ///< max body speed over the trailing window (m/s)
  /// the same over the bodies not escaped (Metrics::escaped) at each sample: what is left
  /// around the magnet, without the few thrown off that slide on for ever (m/s)
  double tail_max_speed_inside = 0;
  /// the fastest body the engine counts as held (engine::held_bodies: the lifted pile,
  /// without the balls on the floor) over the trailing window, as a viewer of 20 frames per
  /// second sees it: displacement over 50 ms (m/s; summary.json's series held_max_speed at
  /// --fps 20, which tools/scripts/ensemble.py reads)
  double tail_max_speed_held = 0;
  double tail_max_ke = 0;        ///< max kinetic energy over the trailing window (J)
  double max_speed = 0;          ///< over the whole run (m/s)
  double max_bounding_radius = 0;
  int min_attached_tail = 1 << 30;
  double cap_fraction = 0;       ///< steps whose magnetization hit the cap
  /// E = K + U_g + U* from 0.05 s on: the most it stood above its running minimum, and
  /// E(0.05 s) − E(end) (J; as tools/scripts/ensemble.py's energy_rise and energy_lost)
  double energy_rise = 0, energy_lost = 0;
  bool failed = false;           ///< SimulationError
  std::string error;
  std::uint64_t hash = 0;
};

/// max |v| over the dynamic bodies that are not escaped (engine::escaped_bodies)
inline double speed_inside(const engine::Simulation& sim) {
  const std::vector<int> out = engine::escaped_bodies(sim.model(), sim.state());
  double v = 0;
  for (int b : sim.model().dynamic_bodies)
    if (!std::binary_search(out.begin(), out.end(), b)) v = std::max(v, sim.state().vel[b].norm());
  return v;
}

/// Runs `name` for `seconds` with `method`; the trailing window is the last `tail` seconds.
/// `edit`, when given, changes the built scene before it runs (e.g. one of its options).
/// The magnetics run on one thread unless `edit` says otherwise: CTest runs two tests at
/// once on 2 cores, and two 2-thread runs stall each other's OpenMP barriers (falling_magnet
/// 1 s: 259 s under CTest -j2 against 73 s on one thread). States do not depend on the
/// thread count (golden_hash_test.cpp).
inline SceneRun run_scene(const std::string& name, mag::Method method, double seconds,
                          double tail, int count = 0, double strength = 1.0,
                          double dt_m = 0.0,
                          const std::function<void(engine::SceneDesc&)>& edit = {}) {
  scenes::SceneParams p;
  p.count = count;
  p.strength = strength;
  engine::SceneDesc d = scenes::find_scene(name)->build(p);
  d.options.magnetics.method = method;
  d.options.threads = 1;
  if (dt_m > 0) d.options.magnetics.dt = dt_m;
  if (edit) edit(d);
  engine::Simulation sim(d);
  SceneRun r;
  const long n = static_cast<long>(seconds / d.options.dt + 0.5);
  const long tail_from = n - static_cast<long>(tail / d.options.dt + 0.5);
  long caps = 0;
  const long frame = std::max(1L, std::lround(0.05 / d.options.dt));  // 20 frames per second
  std::vector<engine::Vec3> prev;  // the centres at the previous 20 fps frame
  EnergyWatch energy(d.options.dt);
  try {
    for (long k = 1; k <= n; ++k) {
      sim.step();
      energy.after_step(k, engine::total_energy(sim.energy()));
      caps += sim.last_profile().cap_hit;
      if (k % frame == 0) {
        if (k >= tail_from && !prev.empty())
          for (int b : engine::held_bodies(sim.model(), sim.state()))
            r.tail_max_speed_held = std::max(r.tail_max_speed_held, (sim.state().pos[b] - prev[b]).norm() /
                                                                        (static_cast<double>(frame) * d.options.dt));
        prev = sim.state().pos;
      }
      if (k % 5 != 0 && k != n) continue;
      const engine::Metrics m = sim.metrics();
      r.max_speed = std::max(r.max_speed, m.max_speed);
      r.max_bounding_radius = std::max(r.max_bounding_radius, m.bounding_radius);
      if (k >= tail_from) {
        r.tail_max_speed = std::max(r.tail_max_speed, m.max_speed);
        r.tail_max_speed_inside = std::max(r.tail_max_speed_inside, speed_inside(sim));
        r.tail_max_ke = std::max(r.tail_max_ke, m.kinetic_energy);
        r.min_attached_tail = std::min(r.min_attached_tail, m.attached);
      }
    }
  } catch (const engine::SimulationError& e) {
    r.failed = true;
    r.error = e.what();
  }
  r.energy_rise = energy.rise;
  r.energy_lost = energy.lost;
  r.last = sim.metrics();
  r.cap_fraction = static_cast<double>(caps) / std::max(1L, sim.steps());
  r.hash = sim.state_hash();
  return r;
}

}  // namespace magsim::test
