// render/renderer_shadow.cpp — the light's side of a frame: the orthographic shadow map
// fitted to the casters, the ground split into the part that map covers and the rest,
// and the shadow pass that fills the map from the light's view.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "render/renderer_impl.hpp"

namespace magsim::render {

namespace {

void push_rect(std::vector<float>& out, float x0, float y0, float x1, float y1) {
  if (x1 <= x0 || y1 <= y0) return;
  out.insert(out.end(), {x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1});
}

}  // namespace

LightSetup Renderer::Impl::fit_light(const Frame& frame, bool shadows) const {
  LightSetup light;
  // light: unit direction towards it, and an orthonormal frame across it
  Eigen::Vector3f L = frame.light_dir;
  if (L.squaredNorm() < 1e-12f) L = Eigen::Vector3f::UnitZ();
  L.normalize();
  const Eigen::Vector3f helper =
      std::abs(L.z()) < 0.95f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  const Eigen::Vector3f light_right = helper.cross(L).normalized();
  const Eigen::Vector3f light_up = L.cross(light_right);
  light.dir = L;
  light.right = light_right;
  light.up = light_up;

  // ground: a square around the scene; only the part the shadow map covers looks it up
  const float G = view.ground_extent;
  const float gx = view.scene_center.x(), gy = view.scene_center.y();
  float in_x0 = gx, in_y0 = gy, in_x1 = gx, in_y1 = gy;  // shadowed rectangle (empty)
  if (shadows) {
    // shadow map: an orthographic light fitted to the casters' bounding box
    const Bounds b = scene_bounds(frame);
    const Eigen::Vector3f c = b.center();
    const float R = std::max(b.radius(), 1e-4f);
    const Eigen::Matrix4f light_view = look_at(c + 2.0f * R * L, c, light_up);
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e30f), hi = -lo;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3f corner((k & 1) ? b.hi.x() : b.lo.x(), (k & 2) ? b.hi.y() : b.lo.y(),
                                   (k & 4) ? b.hi.z() : b.lo.z());
      const Eigen::Vector3f v = (light_view * corner.homogeneous()).head<3>();
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    const float margin = 0.02f * R;
    const float extent = std::max(hi.x() - lo.x(), hi.y() - lo.y()) + 2.0f * margin;
    const float cx = 0.5f * (lo.x() + hi.x()), cy = 0.5f * (lo.y() + hi.y());
    // square texels; view space looks down −z, so near/far are −hi.z / −lo.z
    const Eigen::Matrix4f light_proj =
        orthographic(cx - 0.5f * extent, cx + 0.5f * extent, cy - 0.5f * extent,
                     cy + 0.5f * extent, -hi.z() - margin, -lo.z() + margin);
    light.view_proj = light_proj * light_view;
    light.shadow_texel = extent / float(shadow_size);
    // window depth per metre towards the light (+z of the light's view space)
    light.depth_per_m = 0.5f * light_proj(2, 2);

    // the map's footprint on the ground: its four side edges, followed along the light
    if (frame.ground && L.z() > 0.05f) {
      const Eigen::Matrix4f to_world = light_view.inverse();
      in_x0 = in_y0 = 1e30f;
      in_x1 = in_y1 = -1e30f;
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector4f v(cx + ((k & 1) ? 0.5f : -0.5f) * extent,
                                cy + ((k & 2) ? 0.5f : -0.5f) * extent, 0.0f, 1.0f);
        const Eigen::Vector3f p = (to_world * v).head<3>();
        const Eigen::Vector3f g = p + (frame.ground_height - p.z()) / L.z() * L;
        in_x0 = std::min(in_x0, g.x());
        in_y0 = std::min(in_y0, g.y());
        in_x1 = std::max(in_x1, g.x());
        in_y1 = std::max(in_y1, g.y());
      }
    } else if (frame.ground) {
      in_x0 = gx - G, in_y0 = gy - G, in_x1 = gx + G, in_y1 = gy + G;
    }
    in_x0 = std::clamp(in_x0, gx - G, gx + G);
    in_x1 = std::clamp(in_x1, gx - G, gx + G);
    in_y0 = std::clamp(in_y0, gy - G, gy + G);
    in_y1 = std::clamp(in_y1, gy - G, gy + G);
  }
  light.x0 = in_x0;
  light.y0 = in_y0;
  light.x1 = in_x1;
  light.y1 = in_y1;
  return light;
}

// The ground's triangles: first the shadowed rectangle (ground_inner vertices), then the
// four strips around it out to the square's edge (ground_outer vertices).
void Renderer::Impl::build_ground(const Frame& frame, const LightSetup& light) {
  const float G = view.ground_extent;
  const float gx = view.scene_center.x(), gy = view.scene_center.y();
  const float in_x0 = light.x0, in_y0 = light.y0, in_x1 = light.x1, in_y1 = light.y1;
  ground.clear();
  ground_inner = 0;
  ground_outer = 0;
  if (frame.ground) {
    push_rect(ground, in_x0, in_y0, in_x1, in_y1);
    ground_inner = GLsizei(ground.size() / 2);
    push_rect(ground, gx - G, gy - G, gx + G, in_y0);  // below, full width
    push_rect(ground, gx - G, in_y1, gx + G, gy + G);  // above, full width
    push_rect(ground, gx - G, in_y0, in_x0, in_y1);    // left
    push_rect(ground, in_x1, in_y0, gx + G, in_y1);    // right
    ground_outer = GLsizei(ground.size() / 2) - ground_inner;
  }
}

// Boxes, cylinders and cones, each one instanced draw with the program in use.
void Renderer::Impl::draw_meshes(const InstanceCounts& n) const {
  const std::pair<const GpuMesh*, GLsizei> meshes[3] = {
      {&box, n.boxes}, {&cylinder, n.cylinders}, {&cone, n.cones}};
  for (const auto& [m, count] : meshes) {
    if (count == 0) continue;
    glBindVertexArray(m->vao);
    glDrawElementsInstanced(GL_TRIANGLES, m->index_count, GL_UNSIGNED_INT, nullptr, count);
  }
}

// Depth from the light into the shadow map (only when the frame has shadows); first sets
// the depth state that every later pass starts from.
void Renderer::Impl::shadow_pass(const LightSetup& light, const InstanceCounts& n) {
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
  if (!n.shadows) return;
  glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
  glViewport(0, 0, shadow_size, shadow_size);
  glClear(GL_DEPTH_BUFFER_BIT);
  if (n.meshes > 0) {
    // the meshes are closed: their back faces cast the same shadow, and lit faces can
    // then not shadow themselves (no acne at grazing light)
    glUseProgram(prog_mesh_shadow);
    set_mat4(prog_mesh_shadow, "u_light_vp", light.view_proj);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_FRONT);
    draw_meshes(n);
    glDisable(GL_CULL_FACE);
  }
  if (n.spheres > 0) {
    glUseProgram(prog_sphere_shadow);
    set_mat4(prog_sphere_shadow, "u_light_vp", light.view_proj);
    set_vec3(prog_sphere_shadow, "u_light_right", light.right);
    set_vec3(prog_sphere_shadow, "u_light_up", light.up);
    glUniform1f(loc(prog_sphere_shadow, "u_depth_per_m"), light.depth_per_m);
    glBindVertexArray(sphere_vao_all);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n.spheres);
  }
  if (sync_profile) glFinish();
}

}  // namespace magsim::render
