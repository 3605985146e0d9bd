// tools/cli/magsim_scene/gltf_output.hpp — --gltf PATH.glb: the run as one binary glTF file
// (tools/gltf/gltf_writer.hpp), filled in from the engine's Model and every recorded frame.
#pragma once

#include "engine/simulation.hpp"
#include "tools/cli/magsim_scene/magsim_scene.hpp"
#include "tools/gltf/gltf_writer.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace magsim::scene_tool {

/// The names --gltf-channels takes: the body's total moment |Σ m_j| (A·m²), the speed of its
/// centre of mass (m/s), its angular speed (rad/s).
inline const char* const kGltfChannelNames[] = {"m_norm", "speed", "spin"};
/// "m_norm,speed" → {"m_norm", "speed"}; UsageError on an unknown or repeated name.
std::vector<std::string> parse_gltf_channels(const std::string& list);

/// The file's size bound (gltf::estimate_bytes) for `scene` over `frames` frames; UsageError
/// naming the figures when it is above glTF's 4 GiB.
double check_gltf_size(const engine::SceneDesc& scene, double frames, std::size_t channels);
/// The bytes the recording holds in memory over `frames` frames.
double gltf_memory(const engine::SceneDesc& scene, double frames, std::size_t channels);

class GltfOutput {
 public:
  /// Makes the file's temporary beside a.gltf (UsageError: not a regular file; IoError: it
  /// cannot be made).
  GltfOutput(const RunPlan& a, const engine::Model& m);
  /// Records the simulation's current state as the next frame.
  void frame(const engine::Simulation& sim);
  /// Writes the file with `extras` as the asset's extras; returns its size. IoError when it
  /// cannot be written (nothing is left under the name).
  std::uint64_t write(const nlohmann::json& extras);
  const std::string& path() const { return file_.path(); }

 private:
  const engine::Model& model_;
  gltf::SceneInfo scene_;
  gltf::Recording rec_;
  gltf::GlbFile file_;
  std::vector<int> channel_ids_;  // indices into kGltfChannelNames
  std::vector<double> values_;
};

}  // namespace magsim::scene_tool
