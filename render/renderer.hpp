// render/renderer.hpp — draws a Frame offscreen (OSMesa, llvmpipe) into an RGB8 image.
//
// Spheres are ray-cast impostors (one camera-facing quad each, instanced); boxes,
// cylinders, capsule bodies and arrows are instanced unit meshes. Blinn–Phong lighting
// from the frame's directional light with a hemispherical ambient, a PCF-filtered shadow
// map fitted to the scene, a faded grid on the ground, and MSAA. GL stays inside the .cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "render/camera.hpp"
#include "render/frame.hpp"

namespace magsim::render {

/// Milliseconds spent in the last draw(), by stage (wall clock).
struct RenderProfile {
  double prepare = 0.0;  ///< instance data and uploads
  double shadow = 0.0;   ///< shadow-map pass (submission only unless GL is synchronous)
  double main = 0.0;     ///< colour pass
  double readback = 0.0; ///< resolve, glReadPixels (waits for the GPU work) and the flip
  double total = 0.0;
};

class Renderer {
 public:
  /// An OSMesa GL 3.3+ core context with a width × height framebuffer and `samples`
  /// MSAA samples per pixel (≤ 1: none). Throws std::runtime_error when the context,
  /// a framebuffer or a shader cannot be created.
  Renderer(int width, int height, int samples = 4);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Draws the frame; the image is then in pixels().
  void draw(const Frame& frame);
  /// RGB8 (sRGB-encoded), top row first, width × height × 3 bytes.
  const std::vector<std::uint8_t>& pixels() const;

  int width() const;
  int height() const;
  int samples() const;  ///< MSAA samples actually used (after clamping to GL_MAX_SAMPLES)
  /// Camera set-up of the last draw (for projecting points onto the image).
  const ViewSetup& last_view() const;
  const RenderProfile& profile() const;

  /// Linear [0, 1] → 8-bit sRGB, as the shaders encode colours.
  static std::uint8_t to_srgb8(float linear);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace magsim::render
