// render/renderer.cpp — the OSMesa context, framebuffers, instance buffers and the passes
// of a frame: shadow map (light's view), colour, down-sampling and read-back.
//
// Written for llvmpipe, where the costs are unusual:
//  * vertices are expensive, so spheres are impostors and everything is instanced (a
//    frame is about ten draw calls whatever the number of shapes);
//  * fragment shading dominates, and shading is skipped only when an early depth test
//    rejects a whole SIMD group before the shader runs — a `discard` saves nothing, and
//    with MSAA llvmpipe skips nothing at all (4× MSAA cost 2.3× a plain frame in our
//    first version, 2×2 supersampling 2.7×). So there is no MSAA: sphere edges get an
//    analytic coverage blended back to front, grid lines are filtered analytically, and
//    `samples` ≥ 2 adds 2×2 supersampling on top. Hidden spheres are culled on the CPU
//    (occlusion.cpp) and the rest are depth-tested early against a depth pre-pass;
//  * branches do not skip work, so shadow lookups are compiled out where not needed
//    (program variants) and the ground outside the shadow map is a separate draw.
#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1  // (CMake defines it too) libOSMesa exports every gl* entry
#endif
#include "render/renderer.hpp"

#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

#include "render/meshes.hpp"
#include "render/occlusion.hpp"
#include "render/shaders.hpp"
#include "render/sphere_ao.hpp"

namespace magsim::render {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// glibc's default malloc hands llvmpipe's multi-MB per-frame buffers back to the kernel
// every frame; raising the thresholds makes it 3–4× faster (TOOLCHAIN.md).
void tune_malloc_once() {
  static std::once_flag once;
  std::call_once(once, [] {
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
  });
}

constexpr int kCylinderSegments = 40;
constexpr int kConeSegments = 32;
constexpr int kMeshInstanceFloats = 13;  // position 3, quaternion 4, scale 3, colour 3
constexpr int kSphereInstanceFloats = 8; // centre 3, radius 1, colour 3, ambient factor 1

GLuint compile_shader(GLenum type, const std::string& source, const char* name) {
  const GLuint sh = glCreateShader(type);
  const char* src = source.c_str();
  glShaderSource(sh, 1, &src, nullptr);
  glCompileShader(sh);
  GLint ok = 0;
  glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetShaderiv(sh, GL_INFO_LOG_LENGTH, &len);
    std::string log(std::size_t(std::max(len, 1)), '\0');
    glGetShaderInfoLog(sh, len, nullptr, log.data());
    glDeleteShader(sh);
    throw std::runtime_error(std::string("magsim render: shader '") + name +
                             "' failed to compile:\n" + log.c_str());
  }
  return sh;
}

GLuint link_program(const std::string& vert, const std::string& frag, const char* name) {
  const GLuint vs = compile_shader(GL_VERTEX_SHADER, vert, name);
  GLuint fs = 0;
  try {
    fs = compile_shader(GL_FRAGMENT_SHADER, frag, name);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint prog = glCreateProgram();
  glAttachShader(prog, vs);
  glAttachShader(prog, fs);
  glLinkProgram(prog);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(prog, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(prog, GL_INFO_LOG_LENGTH, &len);
    std::string log(std::size_t(std::max(len, 1)), '\0');
    glGetProgramInfoLog(prog, len, nullptr, log.data());
    glDeleteProgram(prog);
    throw std::runtime_error(std::string("magsim render: program '") + name +
                             "' failed to link:\n" + log.c_str());
  }
  return prog;
}

void check_framebuffer(const char* name) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "' incomplete (status 0x%04x)", unsigned(status));
    throw std::runtime_error(std::string("magsim render: framebuffer '") + name + buf);
  }
}

GLint loc(GLuint prog, const char* name) { return glGetUniformLocation(prog, name); }

void set_mat4(GLuint prog, const char* name, const Eigen::Matrix4f& m) {
  glUniformMatrix4fv(loc(prog, name), 1, GL_FALSE, m.data());  // Eigen is column-major
}
void set_vec3(GLuint prog, const char* name, const Eigen::Vector3f& v) {
  glUniform3f(loc(prog, name), v.x(), v.y(), v.z());
}
void set_vec3(GLuint prog, const char* name, const Color& c) {
  glUniform3f(loc(prog, name), c.r, c.g, c.b);
}

// one unit mesh drawn instanced: its own VAO, vertex, index and instance buffers
struct GpuMesh {
  GLuint vao = 0, vbo = 0, ibo = 0, instances = 0;
  GLsizei index_count = 0;
};

void push_mesh_instance(std::vector<float>& out, const Eigen::Vector3f& p,
                        const Eigen::Quaternionf& q, const Eigen::Vector3f& s, const Color& c) {
  out.insert(out.end(), {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w(), s.x(), s.y(), s.z(),
                         c.r, c.g, c.b});
}

void push_sphere_instance(std::vector<float>& out, const Eigen::Vector3f& p, float r,
                          const Color& c) {
  out.insert(out.end(), {p.x(), p.y(), p.z(), r, c.r, c.g, c.b, 1.0f});
}

}  // namespace

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
  void create_targets();
  void create_programs();
  void create_geometry();
  GpuMesh upload_mesh(const Mesh& mesh);
  void gather(const Frame& frame);
  void sort_spheres(const Frame& frame);
  void upload_instances();
  void draw(const Frame& frame);
};

Renderer::Impl::Impl(int w, int h, int samples) : width(w), height(h) {
  if (w <= 0 || h <= 0)
    throw std::runtime_error("magsim render: image size must be positive, got " +
                             std::to_string(w) + "x" + std::to_string(h));
  ss = samples >= 2 ? 2 : 1;
  rw = ss * w;
  rh = ss * h;
  // shadow texels about as fine as the pixels over the scene: the smallest power of two
  // ≥ the render height, within [512, 2048] (1024 for 720 rows)
  shadow_size = 512;
  while (shadow_size < 2048 && shadow_size < rh) shadow_size *= 2;
  tune_malloc_once();
  const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA,
                         OSMESA_DEPTH_BITS, 0,
                         OSMESA_STENCIL_BITS, 0,
                         OSMESA_ACCUM_BITS, 0,
                         OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION, 3,
                         OSMESA_CONTEXT_MINOR_VERSION, 3,
                         0};
  ctx = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!ctx)
    throw std::runtime_error(
        "magsim render: OSMesaCreateContextAttribs failed to create a GL 3.3 core context "
        "(is libosmesa6 with llvmpipe installed, and is the program linked against "
        "libOSMesa only, not libGL?)");
  // rendering goes to our own framebuffer objects; the context's buffer stays tiny
  osmesa_buffer.assign(16 * 16 * 4, 0);
  make_current();

  const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  if (major * 10 + minor < 33)
    throw std::runtime_error(std::string("magsim render: need OpenGL 3.3, context is ") +
                             (version ? version : "unknown"));
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
  if (rw > max_size || rh > max_size)
    throw std::runtime_error("magsim render: " + std::to_string(rw) + "x" + std::to_string(rh) +
                             " exceeds GL_MAX_RENDERBUFFER_SIZE " + std::to_string(max_size));

  create_targets();
  create_programs();
  create_geometry();
}

Renderer::Impl::~Impl() {
  if (!ctx || !OSMesaMakeCurrent(ctx, osmesa_buffer.data(), GL_UNSIGNED_BYTE, 16, 16)) return;
  const GLuint fbos[] = {scene_fbo, depth_copy_fbo, output_fbo, shadow_fbo};
  glDeleteFramebuffers(4, fbos);
  const GLuint rbs[] = {scene_color, output_color};
  glDeleteRenderbuffers(2, rbs);
  const GLuint texs[] = {scene_depth, depth_copy, shadow_tex};
  glDeleteTextures(3, texs);
  for (GLuint p : {prog_sphere[0], prog_sphere[1], prog_mesh[0], prog_mesh[1], prog_ground[0],
                   prog_ground[1], prog_sphere_depth, prog_sphere_shadow, prog_mesh_shadow})
    glDeleteProgram(p);
  for (GpuMesh* m : {&box, &cylinder, &cone}) {
    glDeleteVertexArrays(1, &m->vao);
    const GLuint bufs[] = {m->vbo, m->ibo, m->instances};
    glDeleteBuffers(3, bufs);
  }
  const GLuint vaos[] = {sphere_vao, sphere_vao_all, ground_vao};
  glDeleteVertexArrays(3, vaos);
  const GLuint bufs[] = {quad_vbo, sphere_instances, sphere_instances_all, ground_vbo};
  glDeleteBuffers(4, bufs);
}

void Renderer::Impl::make_current() {
  if (!OSMesaMakeCurrent(ctx, osmesa_buffer.data(), GL_UNSIGNED_BYTE, 16, 16))
    throw std::runtime_error("magsim render: OSMesaMakeCurrent failed");
}

namespace {

GLuint make_depth_texture(int w, int h, GLenum filter) {
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, w, h, 0, GL_DEPTH_COMPONENT, GL_FLOAT,
               nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GLint(filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GLint(filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return tex;
}

GLuint make_color_renderbuffer(int w, int h) {
  GLuint rb = 0;
  glGenRenderbuffers(1, &rb);
  glBindRenderbuffer(GL_RENDERBUFFER, rb);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
  return rb;
}

}  // namespace

void Renderer::Impl::create_targets() {
  glGenFramebuffers(1, &scene_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  scene_color = make_color_renderbuffer(rw, rh);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, scene_color);
  scene_depth = make_depth_texture(rw, rh, GL_NEAREST);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, scene_depth, 0);
  check_framebuffer("scene");

  glGenFramebuffers(1, &depth_copy_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, depth_copy_fbo);
  depth_copy = make_depth_texture(rw, rh, GL_NEAREST);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth_copy, 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  check_framebuffer("depth copy");

  if (ss > 1) {
    glGenFramebuffers(1, &output_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, output_fbo);
    output_color = make_color_renderbuffer(width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              output_color);
    check_framebuffer("output");
  }

  // shadow map: depth texture sampled with hardware comparison (bilinear 2×2 PCF);
  // outside the map (border depth 1) everything is lit
  shadow_tex = make_depth_texture(shadow_size, shadow_size, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
  const float border[4] = {1.0f, 1.0f, 1.0f, 1.0f};
  glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glGenFramebuffers(1, &shadow_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow_tex, 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  check_framebuffer("shadow");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glBindTexture(GL_TEXTURE_2D, 0);
}

void Renderer::Impl::create_programs() {
  using namespace shaders;
  auto src = [&](int shadows, std::initializer_list<const char*> parts) {
    std::string s = "#version 330 core\n#define SHADOWS " + std::to_string(shadows) + "\n";
    for (const char* p : parts) s += p;
    return s;
  };
  for (int sh = 0; sh < 2; ++sh) {
    prog_sphere[sh] = link_program(src(sh, {kMaterialLib, kSphereVert}),
                                   src(sh, {kLightingLib, kSphereLib, kSphereFrag}), "sphere");
    prog_mesh[sh] = link_program(src(sh, {kMaterialLib, kMeshVert}),
                                 src(sh, {kLightingLib, kMeshFrag}), "mesh");
    prog_ground[sh] = link_program(src(sh, {kGroundVert}), src(sh, {kLightingLib, kGroundFrag}),
                                   "ground");
    for (GLuint p : {prog_sphere[sh], prog_mesh[sh], prog_ground[sh]}) {
      glUseProgram(p);
      glUniform1i(loc(p, "u_shadow_map"), 0);
    }
    glUseProgram(prog_sphere[sh]);
    glUniform1i(loc(prog_sphere[sh], "u_depth"), 1);
  }
  prog_sphere_depth = link_program(
      src(0, {kMaterialLib, kSphereVert}),
      src(0, {"uniform vec3 u_eye;\nuniform mat4 u_view_proj;\n", kSphereLib, kSphereDepthFrag}),
      "sphere depth");
  prog_sphere_shadow =
      link_program(src(0, {kSphereShadowVert}), src(0, {kSphereShadowFrag}), "sphere shadow");
  prog_mesh_shadow =
      link_program(src(0, {kMeshShadowVert}), src(0, {kDepthOnlyFrag}), "mesh shadow");
  glUseProgram(0);
}

GpuMesh Renderer::Impl::upload_mesh(const Mesh& mesh) {
  GpuMesh g;
  g.index_count = GLsizei(mesh.indices.size());
  glGenVertexArrays(1, &g.vao);
  glBindVertexArray(g.vao);
  glGenBuffers(1, &g.vbo);
  glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.vertices.size() * sizeof(float)),
               mesh.vertices.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                        reinterpret_cast<const void*>(3 * sizeof(float)));
  glGenBuffers(1, &g.ibo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ibo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.indices.size() * sizeof(std::uint32_t)),
               mesh.indices.data(), GL_STATIC_DRAW);
  glGenBuffers(1, &g.instances);
  glBindBuffer(GL_ARRAY_BUFFER, g.instances);
  const GLsizei stride = kMeshInstanceFloats * sizeof(float);
  const int sizes[4] = {3, 4, 3, 3};
  std::size_t offset = 0;
  for (int a = 0; a < 4; ++a) {
    glEnableVertexAttribArray(GLuint(2 + a));
    glVertexAttribPointer(GLuint(2 + a), sizes[a], GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(offset * sizeof(float)));
    glVertexAttribDivisor(GLuint(2 + a), 1);
    offset += std::size_t(sizes[a]);
  }
  glBindVertexArray(0);
  return g;
}

void Renderer::Impl::create_geometry() {
  box = upload_mesh(unit_box());
  cylinder = upload_mesh(unit_cylinder(kCylinderSegments));
  cone = upload_mesh(unit_cone(kConeSegments));

  // impostor quad (triangle strip) + per-sphere instance data, in two VAOs. (An octagon
  // would shade a fifth fewer fragments but made 10k-ball frames 25 % slower: llvmpipe's
  // per-triangle set-up costs more than the discarded corners.)
  const float quad[8] = {-1, -1, 1, -1, -1, 1, 1, 1};
  glGenBuffers(1, &quad_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, quad_vbo);
  glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
  glGenBuffers(1, &sphere_instances);
  glGenBuffers(1, &sphere_instances_all);
  for (auto [vao, instances] : {std::pair<GLuint*, GLuint>{&sphere_vao, sphere_instances},
                                std::pair<GLuint*, GLuint>{&sphere_vao_all, sphere_instances_all}}) {
    glGenVertexArrays(1, vao);
    glBindVertexArray(*vao);
    glBindBuffer(GL_ARRAY_BUFFER, quad_vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
    glBindBuffer(GL_ARRAY_BUFFER, instances);
    const GLsizei stride = kSphereInstanceFloats * sizeof(float);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, stride, nullptr);
    glVertexAttribDivisor(1, 1);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(4 * sizeof(float)));
    glVertexAttribDivisor(2, 1);
  }

  // the ground: world x, y of its triangles, rebuilt every frame
  glGenVertexArrays(1, &ground_vao);
  glBindVertexArray(ground_vao);
  glGenBuffers(1, &ground_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, ground_vbo);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  glBindVertexArray(0);
}

// Frame → instance arrays. Capsules are a cylinder plus two sphere impostors (exact round
// caps); arrows are a cylinder shaft plus a cone head.
void Renderer::Impl::gather(const Frame& frame) {
  spheres.clear();
  boxes.clear();
  cylinders.clear();
  cones.clear();
  for (const Shape& s : frame.shapes) {
    const Eigen::Quaternionf q = s.orientation.normalized();
    switch (s.type) {
      case ShapeType::Sphere:
        push_sphere_instance(spheres, s.position, s.size.x(), s.color);
        break;
      case ShapeType::Box:
        push_mesh_instance(boxes, s.position, q, s.size, s.color);
        break;
      case ShapeType::Cylinder:
        push_mesh_instance(cylinders, s.position, q,
                           Eigen::Vector3f(s.size.x(), s.size.x(), s.size.y()), s.color);
        break;
      case ShapeType::Capsule: {
        const Eigen::Vector3f axis = q * Eigen::Vector3f(0.0f, 0.0f, s.size.y());
        push_mesh_instance(cylinders, s.position, q,
                           Eigen::Vector3f(s.size.x(), s.size.x(), s.size.y()), s.color);
        push_sphere_instance(spheres, s.position + axis, s.size.x(), s.color);
        push_sphere_instance(spheres, s.position - axis, s.size.x(), s.color);
        break;
      }
    }
  }
  for (const Arrow& a : frame.arrows) {
    const float len = a.vec.norm();
    if (len <= 0.0f) continue;
    const Eigen::Vector3f dir = a.vec / len;
    const float r = a.radius > 0.0f ? a.radius : 0.04f * len;
    const float head_r = 2.2f * r;
    const float head_len = std::min(0.45f * len, 5.0f * r);
    const float shaft_len = len - head_len;
    const Eigen::Quaternionf q = Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), dir);
    push_mesh_instance(cylinders, a.origin + 0.5f * shaft_len * dir, q,
                       Eigen::Vector3f(r, r, 0.5f * shaft_len), a.color);
    push_mesh_instance(cones, a.origin + shaft_len * dir, q,
                       Eigen::Vector3f(head_r, head_r, head_len), a.color);
  }
}

// Back to front by the power of the eye with respect to each sphere, |c − e|² − r²: for
// disjoint spheres this is a valid visibility order, so blending the edges in this order
// composites them correctly. Spheres certainly hidden behind others are left out; the
// others get their ambient-occlusion factor.
void Renderer::Impl::sort_spheres(const Frame& frame) {
  const Eigen::Vector3f& eye = frame.camera.eye;
  const std::size_t n = spheres.size() / kSphereInstanceFloats;
  sphere_order.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float* s = &spheres[i * kSphereInstanceFloats];
    const float dx = s[0] - eye.x(), dy = s[1] - eye.y(), dz = s[2] - eye.z();
    sphere_order[i] = {dx * dx + dy * dy + dz * dz - s[3] * s[3], std::uint32_t(i)};
  }
  std::sort(sphere_order.begin(), sphere_order.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  front_to_back.resize(n);
  for (std::size_t k = 0; k < n; ++k) front_to_back[k] = sphere_order[n - 1 - k].second;
  camera_occlusion.run_perspective(spheres.data(), kSphereInstanceFloats, front_to_back, eye,
                                   view, frame.camera.fov_y_deg, rw, rh, 4, &sphere_visible);
  ambient_occlusion.run(spheres.data(), kSphereInstanceFloats, n, 7, sphere_visible.data());
  sorted_spheres.clear();
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t i = sphere_order[k].second;
    if (!sphere_visible[i]) continue;
    const float* s = &spheres[std::size_t(i) * kSphereInstanceFloats];
    sorted_spheres.insert(sorted_spheres.end(), s, s + kSphereInstanceFloats);
  }
}

void Renderer::Impl::upload_instances() {
  auto upload = [](GLuint buffer, const std::vector<float>& data) {
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    // orphan the old storage so the driver need not wait for the last frame
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)),
                 data.empty() ? nullptr : data.data(), GL_STREAM_DRAW);
  };
  upload(sphere_instances, sorted_spheres);
  upload(sphere_instances_all, spheres);
  upload(box.instances, boxes);
  upload(cylinder.instances, cylinders);
  upload(cone.instances, cones);
  upload(ground_vbo, ground);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

namespace {

void push_rect(std::vector<float>& out, float x0, float y0, float x1, float y1) {
  if (x1 <= x0 || y1 <= y0) return;
  out.insert(out.end(), {x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1});
}

}  // namespace

void Renderer::Impl::draw(const Frame& frame) {
  const Clock::time_point t0 = Clock::now();
  make_current();
  view = view_setup(frame, float(width) / float(height));
  gather(frame);
  sort_spheres(frame);

  const GLsizei n_spheres = GLsizei(spheres.size() / kSphereInstanceFloats);
  const GLsizei n_visible = GLsizei(sorted_spheres.size() / kSphereInstanceFloats);
  const GLsizei n_boxes = GLsizei(boxes.size() / kMeshInstanceFloats);
  const GLsizei n_cyl = GLsizei(cylinders.size() / kMeshInstanceFloats);
  const GLsizei n_cones = GLsizei(cones.size() / kMeshInstanceFloats);
  const GLsizei n_meshes = n_boxes + n_cyl + n_cones;
  const bool shadows = frame.shadows && n_spheres + n_meshes > 0;

  // light: unit direction towards it, and an orthonormal frame across it
  Eigen::Vector3f L = frame.light_dir;
  if (L.squaredNorm() < 1e-12f) L = Eigen::Vector3f::UnitZ();
  L.normalize();
  const Eigen::Vector3f helper =
      std::abs(L.z()) < 0.95f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  const Eigen::Vector3f light_right = helper.cross(L).normalized();
  const Eigen::Vector3f light_up = L.cross(light_right);

  // shadow map: an orthographic light fitted to the casters' bounding box
  Eigen::Matrix4f light_vp = Eigen::Matrix4f::Identity();
  float shadow_texel = 0.0f, depth_per_m = 0.0f;
  // ground: a square around the scene; only the part the shadow map covers looks it up
  const float G = view.ground_extent;
  const float gx = view.scene_center.x(), gy = view.scene_center.y();
  float in_x0 = gx, in_y0 = gy, in_x1 = gx, in_y1 = gy;  // shadowed rectangle (empty)
  if (shadows) {
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
    light_vp = light_proj * light_view;
    shadow_texel = extent / float(shadow_size);
    // window depth per metre towards the light (+z of the light's view space)
    depth_per_m = 0.5f * light_proj(2, 2);

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
  ground.clear();
  GLsizei ground_inner = 0, ground_outer = 0;
  if (frame.ground) {
    push_rect(ground, in_x0, in_y0, in_x1, in_y1);
    ground_inner = GLsizei(ground.size() / 2);
    push_rect(ground, gx - G, gy - G, gx + G, in_y0);  // below, full width
    push_rect(ground, gx - G, in_y1, gx + G, gy + G);  // above, full width
    push_rect(ground, gx - G, in_y0, in_x0, in_y1);    // left
    push_rect(ground, in_x1, in_y0, gx + G, in_y1);    // right
    ground_outer = GLsizei(ground.size() / 2) - ground_inner;
  }
  upload_instances();
  profile.spheres_total = std::size_t(n_spheres);
  profile.spheres_camera = std::size_t(n_visible);
  profile.prepare = ms_since(t0);

  auto draw_meshes = [&] {
    const std::pair<const GpuMesh*, GLsizei> meshes[3] = {
        {&box, n_boxes}, {&cylinder, n_cyl}, {&cone, n_cones}};
    for (const auto& [m, n] : meshes) {
      if (n == 0) continue;
      glBindVertexArray(m->vao);
      glDrawElementsInstanced(GL_TRIANGLES, m->index_count, GL_UNSIGNED_INT, nullptr, n);
    }
  };

  // --- shadow pass -------------------------------------------------------------------
  const Clock::time_point t1 = Clock::now();
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
  if (shadows) {
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
    glViewport(0, 0, shadow_size, shadow_size);
    glClear(GL_DEPTH_BUFFER_BIT);
    if (n_meshes > 0) {
      // the meshes are closed: their back faces cast the same shadow, and lit faces can
      // then not shadow themselves (no acne at grazing light)
      glUseProgram(prog_mesh_shadow);
      set_mat4(prog_mesh_shadow, "u_light_vp", light_vp);
      glEnable(GL_CULL_FACE);
      glCullFace(GL_FRONT);
      draw_meshes();
      glDisable(GL_CULL_FACE);
    }
    if (n_spheres > 0) {
      glUseProgram(prog_sphere_shadow);
      set_mat4(prog_sphere_shadow, "u_light_vp", light_vp);
      set_vec3(prog_sphere_shadow, "u_light_right", light_right);
      set_vec3(prog_sphere_shadow, "u_light_up", light_up);
      glUniform1f(loc(prog_sphere_shadow, "u_depth_per_m"), depth_per_m);
      glBindVertexArray(sphere_vao_all);
      glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n_spheres);
    }
    if (sync_profile) glFinish();
  }
  profile.shadow = ms_since(t1);

  // --- colour pass -------------------------------------------------------------------
  // 1. meshes;
  // 2. sphere depth where a sphere covers the whole pixel (no colour; cheap);
  // 3. a copy of that depth, for step 5 to read;
  // 4. ground, shaded only where the early depth test lets it through;
  // 5. sphere colour, back to front: the quads' early depth test skips most hidden
  //    fragments, an exact test against the copy discards the rest before shading, and
  //    partly covered edge pixels blend over whatever lies behind.
  Clock::time_point t2 = Clock::now();
  // with profiling on, wait for the GL work queued so far and time it as `stage`
  auto lap = [&](double& stage) {
    if (sync_profile) glFinish();
    stage = ms_since(t2);
    t2 = Clock::now();
  };
  glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  glViewport(0, 0, rw, rh);
  const float clear[3] = {Renderer::to_srgb8(frame.background.r) / 255.0f,
                          Renderer::to_srgb8(frame.background.g) / 255.0f,
                          Renderer::to_srgb8(frame.background.b) / 255.0f};
  glClearColor(clear[0], clear[1], clear[2], 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, shadow_tex);
  const int sh = shadows ? 1 : 0;
  const float pixel_angle =
      2.0f * std::tan(0.5f * frame.camera.fov_y_deg * 3.14159265f / 180.0f) / float(rh);

  auto set_common = [&](GLuint p) {
    glUseProgram(p);
    set_mat4(p, "u_view_proj", view.view_proj);
    set_vec3(p, "u_eye", frame.camera.eye);
    set_vec3(p, "u_light_dir", L);
    set_mat4(p, "u_light_vp", light_vp);
    glUniform1f(loc(p, "u_shadow_texel"), shadow_texel);
    glUniform1f(loc(p, "u_shadow_uv"), 1.0f / float(shadow_size));
    glUniform1f(loc(p, "u_pixel_angle"), pixel_angle);
  };

  if (n_meshes > 0) {
    set_common(prog_mesh[sh]);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    draw_meshes();
    glDisable(GL_CULL_FACE);
  }
  lap(profile.meshes);
  if (n_visible > 0) {
    set_common(prog_sphere_depth);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glBindVertexArray(sphere_vao);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n_visible);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, depth_copy_fbo);
    glBlitFramebuffer(0, 0, rw, rh, 0, 0, rw, rh, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo);
  }
  lap(profile.sphere_depth);
  if (frame.ground) {
    glBindVertexArray(ground_vao);
    // grid cell and fade: from the camera (view_setup), the same in every frame of a run
    const float cell = view.ground_cell;
    for (int part = 0; part < 2; ++part) {
      const GLsizei first = part == 0 ? 0 : ground_inner;
      const GLsizei count = part == 0 ? ground_inner : ground_outer;
      if (count == 0) continue;
      const GLuint p = prog_ground[part == 0 ? sh : 0];
      set_common(p);
      glUniform1f(loc(p, "u_ground_height"), frame.ground_height);
      set_vec3(p, "u_ground_color", frame.ground_color);
      glUniform3f(loc(p, "u_background_srgb"), clear[0], clear[1], clear[2]);
      glUniform3f(loc(p, "u_ground_center"), view.fade_center.x(), view.fade_center.y(), frame.ground_height);
      glUniform1f(loc(p, "u_grid"), cell);
      glUniform2f(loc(p, "u_fade"), view.fade_start, view.fade_end);
      glDrawArrays(GL_TRIANGLES, first, count);
    }
  }
  lap(profile.ground);
  if (n_visible > 0) {
    set_common(prog_sphere[sh]);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, depth_copy);
    glActiveTexture(GL_TEXTURE0);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glBindVertexArray(sphere_vao);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n_visible);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE0);
  }
  glBindVertexArray(0);
  glUseProgram(0);
  lap(profile.spheres);

  // --- down-sample and read back (bottom row first → flip) ---------------------------
  const Clock::time_point t3 = Clock::now();
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
  profile.readback = ms_since(t3);
  profile.total = ms_since(t0);
}

Renderer::Renderer(int width, int height, int samples)
    : impl_(std::make_unique<Impl>(width, height, samples)) {}
Renderer::~Renderer() = default;

void Renderer::draw(const Frame& frame) { impl_->draw(frame); }
const std::vector<std::uint8_t>& Renderer::pixels() const { return impl_->pixels; }
int Renderer::width() const { return impl_->width; }
int Renderer::height() const { return impl_->height; }
int Renderer::samples() const { return impl_->ss * impl_->ss; }
const ViewSetup& Renderer::last_view() const { return impl_->view; }
const RenderProfile& Renderer::profile() const { return impl_->profile; }
void Renderer::set_profiling(bool on) { impl_->sync_profile = on; }

std::uint8_t Renderer::to_srgb8(float linear) {
  const float c = std::clamp(linear, 0.0f, 1.0f);
  const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return std::uint8_t(std::lround(s * 255.0f));
}

}  // namespace magsim::render
