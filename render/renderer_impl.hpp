// render/renderer_impl.hpp — Renderer::Impl, shared by the renderer's source files and
// private to render/ (GL stays out of renderer.hpp). Where each part lives:
//   renderer.cpp           context, the frame's order of passes, the public API
//   renderer_gl_setup.cpp  framebuffers, shadow map texture, shader programs
//   renderer_geometry.cpp  unit meshes, impostor quad, instance arrays, sphere order
//   renderer_shadow.cpp    the light's frame, the ground's rectangles, the shadow pass
//   renderer_passes.cpp    the colour passes, down-sampling and read-back
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1  // (CMake defines it too) libOSMesa exports every gl* entry
#endif
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <chrono>
#include <cstdint>
#include <utility>
#include <vector>

#include "render/meshes.hpp"
#include "render/occlusion.hpp"
#include "render/renderer.hpp"
#include "render/sphere_ao.hpp"

namespace magsim::render {

using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

inline constexpr int kMeshInstanceFloats = 13;  // position 3, quaternion 4, scale 3, colour 3
inline constexpr int kSphereInstanceFloats = 8; // centre 3, radius 1, colour 3, ambient factor 1

inline GLint loc(GLuint prog, const char* name) { return glGetUniformLocation(prog, name); }

inline void set_mat4(GLuint prog, const char* name, const Eigen::Matrix4f& m) {
  glUniformMatrix4fv(loc(prog, name), 1, GL_FALSE, m.data());  // Eigen is column-major
}
inline void set_vec3(GLuint prog, const char* name, const Eigen::Vector3f& v) {
  glUniform3f(loc(prog, name), v.x(), v.y(), v.z());
}
inline void set_vec3(GLuint prog, const char* name, const Color& c) {
  glUniform3f(loc(prog, name), c.r, c.g, c.b);
}

// one unit mesh drawn instanced: its own VAO, vertex, index and instance buffers
struct GpuMesh {
  GLuint vao = 0, vbo = 0, ibo = 0, instances = 0;
  GLsizei index_count = 0;
};

// Owns the OSMesa context; the first member of Impl, so it is destroyed last (after
// Impl's destructor has deleted the GL objects) and also when Impl's constructor throws.
struct ContextHandle {
  OSMesaContext ctx = nullptr;
  ContextHandle() = default;
  ContextHandle(const ContextHandle&) = delete;
  ContextHandle& operator=(const ContextHandle&) = delete;
  ~ContextHandle() {
    if (ctx) OSMesaDestroyContext(ctx);
  }
};

// Instances in this frame's buffers, and whether it has a shadow pass.
struct InstanceCounts {
  GLsizei spheres = 0;  // all sphere impostors (shadow pass)
  GLsizei visible = 0;  // those the camera may see (colour passes)
  GLsizei boxes = 0, cylinders = 0, cones = 0;
  GLsizei meshes = 0;   // boxes + cylinders + cones
  bool shadows = false;
};

// The frame's light: a unit direction towards it with an orthonormal frame across it, the
// shadow map's view-projection, and the ground rectangle [x0, x1] × [y0, y1] that the map
// covers (empty without shadows); only that part of the ground looks the map up.
struct LightSetup {
  Eigen::Vector3f dir, right, up;
  Eigen::Matrix4f view_proj = Eigen::Matrix4f::Identity();
  float shadow_texel = 0.0f;  // metres per shadow-map texel
  float depth_per_m = 0.0f;   // window depth per metre towards the light
  float x0 = 0.0f, y0 = 0.0f, x1 = 0.0f, y1 = 0.0f;
};

// What every colour program is given (Impl::use_color_program).
struct ColorPassSetup {
  const Frame& frame;
  const LightSetup& light;
  float clear[3];     // the background, sRGB-encoded as in the image
  int shadows;        // index of the program variant: 1 with shadow lookups
  float pixel_angle;  // radians per render-target pixel, vertically
};

struct Renderer::Impl {
  ContextHandle context;
  OSMesaContext& ctx = context.ctx;
  int width = 0, height = 0;  // output image
  int ss = 1;                 // supersampling factor per axis (1 or 2)
  int rw = 0, rh = 0;         // render target size: ss·width × ss·height
  int shadow_size = 0;        // shadow map side (texels)
  bool sync_profile = false;
  std::vector<std::uint8_t> osmesa_buffer;  // the context's own (unused) colour buffer

  // scene target (colour + depth texture), a copy of its depth for the sphere colour
  // pass, the down-sampled output (when ss > 1) and the shadow map
  GLuint scene_fbo = 0, scene_color = 0, scene_depth = 0;
  GLuint depth_copy_fbo = 0, depth_copy = 0;
  GLuint output_fbo = 0, output_color = 0;
  GLuint shadow_fbo = 0, shadow_tex = 0;

  // colour programs come without [0] and with [1] shadow lookups
  GLuint prog_sphere[2] = {0, 0}, prog_mesh[2] = {0, 0}, prog_ground[2] = {0, 0};
  GLuint prog_sphere_depth = 0, prog_sphere_shadow = 0, prog_mesh_shadow = 0;

  // spheres: all of them (shadow pass) and those the camera may see, back to front
  // (colour passes). (Culling spheres hidden from the light as well was tried: in piles
  // almost every ball shows through some gap when seen along parallel rays.)
  GLuint sphere_vao_all = 0, sphere_instances_all = 0;
  GLuint sphere_vao = 0, quad_vbo = 0, sphere_instances = 0;
  GLuint ground_vao = 0, ground_vbo = 0;
  GpuMesh box, cylinder, cone;

  // per-frame data (kept to reuse its capacity)
  std::vector<float> spheres, sorted_spheres, boxes, cylinders, cones, ground;
  GLsizei ground_inner = 0, ground_outer = 0;  // vertices of the two parts of `ground`
  std::vector<std::pair<float, std::uint32_t>> sphere_order;
  std::vector<std::uint32_t> front_to_back;
  std::vector<std::uint8_t> sphere_visible;
  SphereOcclusion camera_occlusion;
  SphereAmbientOcclusion ambient_occlusion;
  std::vector<std::uint8_t> rgba, pixels;
  ViewSetup view;
  RenderProfile profile;

  Impl(int w, int h, int samples);
  ~Impl();
  void make_current();
  void draw(const Frame& frame);

  // set-up (renderer_gl_setup.cpp, renderer_geometry.cpp)
  void create_targets();
  void create_programs();
  void create_geometry();
  GpuMesh upload_mesh(const Mesh& mesh);

  // per-frame preparation (renderer_geometry.cpp, renderer_shadow.cpp)
  void gather(const Frame& frame);
  void sort_spheres(const Frame& frame);
  InstanceCounts count_instances(const Frame& frame) const;
  LightSetup fit_light(const Frame& frame, bool shadows) const;
  void build_ground(const Frame& frame, const LightSetup& light);
  void upload_instances();

  // the passes, in the order draw() runs them (renderer_shadow.cpp, renderer_passes.cpp)
  void draw_meshes(const InstanceCounts& n) const;
  void shadow_pass(const LightSetup& light, const InstanceCounts& n);
  ColorPassSetup begin_color_pass(const Frame& frame, const LightSetup& light,
                                  const InstanceCounts& n);
  void use_color_program(GLuint prog, const ColorPassSetup& c) const;
  void mesh_pass(const ColorPassSetup& c, const InstanceCounts& n);
  void sphere_depth_pass(const ColorPassSetup& c, const InstanceCounts& n);
  void ground_pass(const ColorPassSetup& c);
  void sphere_color_pass(const ColorPassSetup& c, const InstanceCounts& n);
  void read_back();
};

}  // namespace magsim::render
