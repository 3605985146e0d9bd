// render/renderer.hpp — draws a Frame offscreen (OSMesa, llvmpipe) into an RGB8 image.
//
// Spheres are ray-cast impostors (one camera-facing quad each, instanced, hidden ones
// culled on the CPU); boxes, cylinders, capsule bodies and arrows are instanced unit
// meshes. Blinn–Phong lighting from the frame's directional light with a hemispherical
// ambient (per-sphere ambient occlusion), a PCF-filtered shadow map fitted to the scene,
// and a grid on the ground that fades into the background. Anti-aliasing: analytic edge
// coverage for spheres and grid lines, optional 2×2 supersampling for everything (MSAA
// is slow on llvmpipe; see renderer.cpp). GL stays inside the .cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "render/camera.hpp"
#include "render/frame.hpp"

namespace magsim::render {

/// Milliseconds spent in the last draw(), by stage (wall clock). GL work is queued and
/// runs when the image is read back, so the stages are only meaningful with
/// Renderer::set_profiling(true), which waits for each stage to finish (a little slower).
struct RenderProfile {
  double prepare = 0.0;       ///< instance data, sorting and uploads
  double shadow = 0.0;        ///< shadow-map pass
  double meshes = 0.0;        ///< boxes, cylinders, arrows
  double sphere_depth = 0.0;  ///< sphere depth pre-pass and its copy
  double ground = 0.0;        ///< ground plane
  double spheres = 0.0;       ///< sphere colour pass
  double readback = 0.0;      ///< down-sampling, glReadPixels and the flip
  double total = 0.0;
  std::size_t spheres_total = 0;   ///< sphere impostors in the frame (capsule caps included)
  std::size_t spheres_camera = 0;  ///< drawn in the colour passes (not certainly hidden)
};

class Renderer {
 public:
  /// An OSMesa GL 3.3+ core context with a width × height image. samples ≤ 1: one sample
  /// per pixel (spheres and grid lines still get analytic edge anti-aliasing; mesh edges
  /// do not); samples ≥ 2: 2×2 supersampling, about 3× the time. Throws
  /// std::runtime_error when the context, a framebuffer or a shader cannot be created
  /// (with the GL info log).
  Renderer(int width, int height, int samples = 1);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Draws the frame; the image is then in pixels().
  void draw(const Frame& frame);
  /// RGB8 (sRGB-encoded), top row first, width × height × 3 bytes.
  const std::vector<std::uint8_t>& pixels() const;

  int width() const;
  int height() const;
  int samples() const;  ///< samples per pixel actually used: 1 or 4
  /// Camera set-up of the last draw (for projecting points onto the image).
  const ViewSetup& last_view() const;
  const RenderProfile& profile() const;
  /// Wait for each stage to finish so that profile() times the stages separately.
  void set_profiling(bool on);

  /// Linear [0, 1] → 8-bit sRGB, as the shaders encode colours.
  static std::uint8_t to_srgb8(float linear);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace magsim::render
