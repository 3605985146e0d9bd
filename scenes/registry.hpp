// scenes/registry.hpp — the one table of scenes, shared by the scene binary,
// the tests and the benchmarks.
#pragma once

#include "engine/scene_desc.hpp"

#include <string>
#include <vector>

namespace magsim::scenes {

/// Knobs every scene accepts; 0 / 1 leave the scene's own defaults.
struct SceneParams {
  int count = 0;          ///< number of balls / letters (0 = the paper's count)
  double strength = 1.0;  ///< multiplies every permanent moment (stress sweeps)
};

struct SceneEntry {
  const char* name;     ///< e.g. "balls_up"
  const char* summary;  ///< one line for --help
  engine::SceneDesc (*build)(const SceneParams&);
};

/// balls_up, alphabets, falling_magnet, sakura_tree, crystal_balls (the paper's §5 and ours).
const std::vector<SceneEntry>& registry();
/// nullptr when unknown.
const SceneEntry* find_scene(const std::string& name);

}  // namespace magsim::scenes
