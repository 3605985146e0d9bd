// render/renderer_passes.cpp — the colour passes into the scene target, in this order:
// 1. meshes;
// 2. sphere depth where a sphere covers the whole pixel (no colour; cheap);
// 3. a copy of that depth, for step 5 to read;
// 4. ground, shaded only where the early depth test lets it through;
// 5. sphere colour, back to front: the quads' early depth test skips most hidden
//    fragments, an exact test against the copy discards the rest before shading, and
//    partly covered edge pixels blend over whatever lies behind.
// Then the down-sampling (2×2 supersampling) and the read-back into the RGB8 image.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "render/renderer_impl.hpp"

namespace magsim::render {

// Binds and clears the scene target and the shadow map; what every colour pass uses.
ColorPassSetup Renderer::Impl::begin_color_pass(const Frame& frame, const LightSetup& light,
                                                const InstanceCounts& n) {
  glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  glViewport(0, 0, rw, rh);
  ColorPassSetup c{frame,
                   light,
                   {Renderer::to_srgb8(frame.background.r) / 255.0f,
                    Renderer::to_srgb8(frame.background.g) / 255.0f,
                    Renderer::to_srgb8(frame.background.b) / 255.0f},
                   n.shadows ? 1 : 0,
                   0.0f};
  glClearColor(c.clear[0], c.clear[1], c.clear[2], 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, shadow_tex);
  c.pixel_angle =
      2.0f * std::tan(0.5f * frame.camera.fov_y_deg * 3.14159265f / 180.0f) / float(rh);
  return c;
}

// Makes prog current with the camera, light and shadow-map uniforms all colour programs share.
void Renderer::Impl::use_color_program(GLuint p, const ColorPassSetup& c) const {
  glUseProgram(p);
  set_mat4(p, "u_view_proj", view.view_proj);
  set_vec3(p, "u_eye", c.frame.camera.eye);
  set_vec3(p, "u_light_dir", c.light.dir);
  set_mat4(p, "u_light_vp", c.light.view_proj);
  glUniform1f(loc(p, "u_shadow_texel"), c.light.shadow_texel);
  glUniform1f(loc(p, "u_shadow_uv"), 1.0f / float(shadow_size));
  glUniform1f(loc(p, "u_pixel_angle"), c.pixel_angle);
}

void Renderer::Impl::mesh_pass(const ColorPassSetup& c, const InstanceCounts& n) {
  if (n.meshes == 0) return;
  use_color_program(prog_mesh[c.shadows], c);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  draw_meshes(n);
  glDisable(GL_CULL_FACE);
}

void Renderer::Impl::sphere_depth_pass(const ColorPassSetup& c, const InstanceCounts& n) {
  if (n.visible == 0) return;
  use_color_program(prog_sphere_depth, c);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glBindVertexArray(sphere_vao);
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n.visible);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, depth_copy_fbo);
  glBlitFramebuffer(0, 0, rw, rh, 0, 0, rw, rh, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
}

// The shadowed rectangle with the shadow program variant, the strips around it without.
void Renderer::Impl::ground_pass(const ColorPassSetup& c) {
  const Frame& frame = c.frame;
  if (!frame.ground) return;
  glBindVertexArray(ground_vao);
  // grid cell and fade: from the camera (view_setup), the same in every frame of a run
  const float cell = view.ground_cell;
  for (int part = 0; part < 2; ++part) {
    const GLsizei first = part == 0 ? 0 : ground_inner;
    const GLsizei count = part == 0 ? ground_inner : ground_outer;
    if (count == 0) continue;
    const GLuint p = prog_ground[part == 0 ? c.shadows : 0];
    use_color_program(p, c);
    glUniform1f(loc(p, "u_ground_height"), frame.ground_height);
    set_vec3(p, "u_ground_color", frame.ground_color);
    glUniform3f(loc(p, "u_background_srgb"), c.clear[0], c.clear[1], c.clear[2]);
    glUniform3f(loc(p, "u_ground_center"), view.fade_center.x(), view.fade_center.y(),
                frame.ground_height);
    glUniform1f(loc(p, "u_grid"), cell);
    glUniform2f(loc(p, "u_fade"), view.fade_start, view.fade_end);
    glDrawArrays(GL_TRIANGLES, first, count);
  }
}

// Blends over what lies behind without writing depth, then restores the default state.
void Renderer::Impl::sphere_color_pass(const ColorPassSetup& c, const InstanceCounts& n) {
  if (n.visible == 0) return;
  use_color_program(prog_sphere[c.shadows], c);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, depth_copy);
  glActiveTexture(GL_TEXTURE0);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  glBindVertexArray(sphere_vao);
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n.visible);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, 0);
  glActiveTexture(GL_TEXTURE0);
}

// Down-samples (when ss > 1) and reads the image back into `pixels`, bottom row first in
// GL and so flipped.
void Renderer::Impl::read_back() {
  GLuint read_fbo = scene_fbo;
  if (ss > 1) {
    // a 2:1 linear blit samples between four texels: an exact 2×2 box filter
    glBindFramebuffer(GL_READ_FRAMEBUFFER, scene_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, output_fbo);
    glBlitFramebuffer(0, 0, rw, rh, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_LINEAR);
    read_fbo = output_fbo;
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, read_fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  rgba.resize(std::size_t(width) * std::size_t(height) * 4);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  pixels.resize(std::size_t(width) * std::size_t(height) * 3);
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* src = rgba.data() + std::size_t(height - 1 - y) * std::size_t(width) * 4;
    std::uint8_t* dst = pixels.data() + std::size_t(y) * std::size_t(width) * 3;
    for (int x = 0; x < width; ++x) {
      dst[3 * x + 0] = src[4 * x + 0];
      dst[3 * x + 1] = src[4 * x + 1];
      dst[3 * x + 2] = src[4 * x + 2];
    }
  }
}

}  // namespace magsim::render
