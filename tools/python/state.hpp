// tools/python/state.hpp — magsim.State: a copy of a simulation's whole state (engine::State,
// the derived data a restore needs included) with the fingerprint of its scene's bodies, so
// that set_state refuses a state of another scene. Pickled as bytes.
#pragma once

#include "engine/state.hpp"

#include <cstdint>
#include <string>

namespace magsim::python {

struct State {
  engine::State s;
  std::uint64_t fingerprint = 0;  ///< scene_fingerprint of the scene it was taken from
};

/// FNV-1a over the scene's bodies as a scene file writes them (options aside: a state moves
/// between runs of one scene at other thread counts or tolerances).
std::uint64_t scene_fingerprint(const engine::SceneDesc& scene);

/// The state as bytes and back (a format of this build, for pickle; from_bytes throws
/// std::invalid_argument on bytes it did not write).
std::string to_bytes(const State& st);
State from_bytes(const std::string& b);

}  // namespace magsim::python
