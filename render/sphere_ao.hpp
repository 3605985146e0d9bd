// render/sphere_ao.hpp — an ambient-occlusion estimate per sphere from its neighbours.
//
// Piles read better when buried balls get less sky light than exposed ones. A shadow map
// only handles the sun; this gives each sphere one ambient factor from the spheres
// touching it, weighted towards those above it (the sky is the main ambient source).
#pragma once

#include <cstdint>
#include <vector>

namespace magsim::render {

class SphereAmbientOcclusion {
 public:
  /// `spheres`: n packed records of `stride` floats starting {x, y, z, r}. Writes the
  /// ambient factor in [0.3, 1] (1 = open sky) to record[ao_offset] of every sphere with
  /// wanted[i] != 0 (all of them if `wanted` is null); every sphere counts as a neighbour.
  void run(float* spheres, std::size_t stride, std::size_t n, std::size_t ao_offset,
           const std::uint8_t* wanted = nullptr);

 private:
  std::vector<std::uint32_t> cell_of_, cell_start_;
  std::vector<float> packed_;
};

}  // namespace magsim::render
