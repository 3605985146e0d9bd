// engine/frame_builder.hpp — Model + State → render::Frame (the engine builds
// an abstract scene, render/ draws it and knows nothing of physics).
#pragma once

#include "engine/state.hpp"
#include "render/frame.hpp"

namespace magsim::engine {

struct FrameOptions {
  /// Draw M1 (red) and M2 (blue) of every induced moment as arrows from its position.
  bool magnetization_arrows = false;
  /// Arrow length for |M_k| = Ms as a fraction of the moment's radius (3V/4π)^{1/3}.
  double arrow_scale = 0.9;
  /// Also draw permanent moments (green), scaled to arrow_scale × their radius.
  bool permanent_arrows = false;
};

/// Every shape of every visible body at its world pose with the body's colour, the scene's
/// camera and ground, and the optional magnetization arrows.
render::Frame build_frame(const Model& model, const State& s, const FrameOptions& opt = {});

}  // namespace magsim::engine
