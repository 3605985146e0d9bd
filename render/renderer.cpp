// render/renderer.cpp — the OSMesa context, framebuffers, instance buffers and the three
// passes of a frame: shadow map (light's view), colour (MSAA), resolve + read-back.
//
// llvmpipe is vertex-bound for real meshes, so spheres are impostors and everything is
// instanced: a frame is at most seven draw calls whatever the number of shapes.
#define GL_GLEXT_PROTOTYPES 1
#include "render/renderer.hpp"

#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

#include "render/meshes.hpp"
#include "render/shaders.hpp"

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

constexpr int kShadowMapSize = 2048;
constexpr int kCylinderSegments = 40;
constexpr int kConeSegments = 32;
constexpr int kMeshInstanceFloats = 13;  // position 3, quaternion 4, scale 3, colour 3
constexpr int kSphereInstanceFloats = 7; // centre 3, radius 1, colour 3

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

std::string colour_frag(const char* body) {
  return std::string("#version 330 core\n") + shaders::kLightingLib + body;
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
  out.insert(out.end(), {p.x(), p.y(), p.z(), r, c.r, c.g, c.b});
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
  int width = 0, height = 0, samples = 0;
  std::vector<std::uint8_t> osmesa_buffer;  // the context's own (unused) colour buffer

  // colour pass target (multisampled when samples > 1) and the single-sample resolve
  GLuint msaa_fbo = 0, msaa_color = 0, msaa_depth = 0;
  GLuint resolve_fbo = 0, resolve_color = 0, resolve_depth = 0;
  GLuint shadow_fbo = 0, shadow_tex = 0;

  GLuint prog_sphere = 0, prog_sphere_shadow = 0, prog_mesh = 0, prog_mesh_shadow = 0,
         prog_ground = 0;

  GLuint sphere_vao = 0, quad_vbo = 0, sphere_instances = 0;
  GLuint ground_vao = 0;
  GpuMesh box, cylinder, cone;

  // per-frame instance data (kept to reuse its capacity)
  std::vector<float> spheres, boxes, cylinders, cones;
  std::vector<std::uint8_t> rgba, pixels;
  ViewSetup view;
  RenderProfile profile;

  Impl(int w, int h, int s);
  ~Impl();
  void make_current();
  void create_targets();
  void create_programs();
  void create_geometry();
  GpuMesh upload_mesh(const Mesh& mesh);
  void gather(const Frame& frame);
  void upload_instances();
  void draw(const Frame& frame);
};

Renderer::Impl::Impl(int w, int h, int s) : width(w), height(h), samples(s) {
  if (w <= 0 || h <= 0)
    throw std::runtime_error("magsim render: image size must be positive, got " +
                             std::to_string(w) + "x" + std::to_string(h));
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

  GLint max_samples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  samples = samples <= 1 ? 1 : std::min(samples, int(max_samples));

  create_targets();
  create_programs();
  create_geometry();
}

Renderer::Impl::~Impl() {
  if (!ctx || !OSMesaMakeCurrent(ctx, osmesa_buffer.data(), GL_UNSIGNED_BYTE, 16, 16)) return;
  const GLuint fbos[] = {msaa_fbo, resolve_fbo, shadow_fbo};
  glDeleteFramebuffers(3, fbos);
  const GLuint rbs[] = {msaa_color, msaa_depth, resolve_color, resolve_depth};
  glDeleteRenderbuffers(4, rbs);
  glDeleteTextures(1, &shadow_tex);
  for (GLuint p : {prog_sphere, prog_sphere_shadow, prog_mesh, prog_mesh_shadow, prog_ground})
    glDeleteProgram(p);
  for (GpuMesh* m : {&box, &cylinder, &cone}) {
    glDeleteVertexArrays(1, &m->vao);
    const GLuint bufs[] = {m->vbo, m->ibo, m->instances};
    glDeleteBuffers(3, bufs);
  }
  glDeleteVertexArrays(1, &sphere_vao);
  glDeleteVertexArrays(1, &ground_vao);
  const GLuint bufs[] = {quad_vbo, sphere_instances};
  glDeleteBuffers(2, bufs);
}

void Renderer::Impl::make_current() {
  if (!OSMesaMakeCurrent(ctx, osmesa_buffer.data(), GL_UNSIGNED_BYTE, 16, 16))
    throw std::runtime_error("magsim render: OSMesaMakeCurrent failed");
}

void Renderer::Impl::create_targets() {
  // single-sample target: the resolve destination, or the colour target without MSAA
  glGenFramebuffers(1, &resolve_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo);
  glGenRenderbuffers(1, &resolve_color);
  glBindRenderbuffer(GL_RENDERBUFFER, resolve_color);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_color);
  if (samples == 1) {
    glGenRenderbuffers(1, &resolve_depth);
    glBindRenderbuffer(GL_RENDERBUFFER, resolve_depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              resolve_depth);
  }
  check_framebuffer("resolve");

  if (samples > 1) {
    glGenFramebuffers(1, &msaa_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, msaa_fbo);
    glGenRenderbuffers(1, &msaa_color);
    glBindRenderbuffer(GL_RENDERBUFFER, msaa_color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msaa_color);
    glGenRenderbuffers(1, &msaa_depth);
    glBindRenderbuffer(GL_RENDERBUFFER, msaa_depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT32F, width,
                                     height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, msaa_depth);
    check_framebuffer("msaa");
  }

  // shadow map: depth texture sampled with hardware comparison (bilinear 2×2 PCF);
  // outside the map (border depth 1) everything is lit
  glGenTextures(1, &shadow_tex);
  glBindTexture(GL_TEXTURE_2D, shadow_tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, kShadowMapSize, kShadowMapSize, 0,
               GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
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
}

void Renderer::Impl::create_programs() {
  using namespace shaders;
  prog_sphere = link_program(kSphereVert, colour_frag(kSphereFrag), "sphere");
  prog_sphere_shadow = link_program(kSphereShadowVert, kSphereShadowFrag, "sphere shadow");
  prog_mesh = link_program(kMeshVert, colour_frag(kMeshFrag), "mesh");
  prog_mesh_shadow = link_program(kMeshShadowVert, kDepthOnlyFrag, "mesh shadow");
  prog_ground = link_program(kGroundVert, colour_frag(kGroundFrag), "ground");
  for (GLuint p : {prog_sphere, prog_mesh, prog_ground}) {
    glUseProgram(p);
    glUniform1i(loc(p, "u_shadow_map"), 0);
  }
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

  // impostor quad (triangle strip) + per-sphere instance data
  const float quad[8] = {-1, -1, 1, -1, -1, 1, 1, 1};
  glGenVertexArrays(1, &sphere_vao);
  glBindVertexArray(sphere_vao);
  glGenBuffers(1, &quad_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, quad_vbo);
  glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  glGenBuffers(1, &sphere_instances);
  glBindBuffer(GL_ARRAY_BUFFER, sphere_instances);
  const GLsizei stride = kSphereInstanceFloats * sizeof(float);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, stride, nullptr);
  glVertexAttribDivisor(1, 1);
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<const void*>(4 * sizeof(float)));
  glVertexAttribDivisor(2, 1);

  // the ground reuses the quad's corners
  glGenVertexArrays(1, &ground_vao);
  glBindVertexArray(ground_vao);
  glBindBuffer(GL_ARRAY_BUFFER, quad_vbo);
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

void Renderer::Impl::upload_instances() {
  auto upload = [](GLuint buffer, const std::vector<float>& data) {
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    // orphan the old storage so the driver need not wait for the last frame
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)),
                 data.empty() ? nullptr : data.data(), GL_STREAM_DRAW);
  };
  upload(sphere_instances, spheres);
  upload(box.instances, boxes);
  upload(cylinder.instances, cylinders);
  upload(cone.instances, cones);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void Renderer::Impl::draw(const Frame& frame) {
  const Clock::time_point t0 = Clock::now();
  make_current();
  gather(frame);
  upload_instances();
  view = view_setup(frame, float(width) / float(height));

  const GLsizei n_spheres = GLsizei(spheres.size() / kSphereInstanceFloats);
  const GLsizei n_boxes = GLsizei(boxes.size() / kMeshInstanceFloats);
  const GLsizei n_cyl = GLsizei(cylinders.size() / kMeshInstanceFloats);
  const GLsizei n_cones = GLsizei(cones.size() / kMeshInstanceFloats);
  const bool any_caster = n_spheres + n_boxes + n_cyl + n_cones > 0;

  auto draw_meshes = [&](bool with_boxes) {
    const std::pair<const GpuMesh*, GLsizei> meshes[3] = {
        {&box, with_boxes ? n_boxes : 0}, {&cylinder, n_cyl}, {&cone, n_cones}};
    for (const auto& [m, n] : meshes) {
      if (n == 0) continue;
      glBindVertexArray(m->vao);
      glDrawElementsInstanced(GL_TRIANGLES, m->index_count, GL_UNSIGNED_INT, nullptr, n);
    }
  };

  // light: unit direction towards it, and an orthonormal frame across it
  Eigen::Vector3f L = frame.light_dir;
  if (L.squaredNorm() < 1e-12f) L = Eigen::Vector3f::UnitZ();
  L.normalize();
  const Eigen::Vector3f helper =
      std::abs(L.z()) < 0.95f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  const Eigen::Vector3f light_right = helper.cross(L).normalized();
  const Eigen::Vector3f light_up = L.cross(light_right);
  profile.prepare = ms_since(t0);

  // --- shadow pass: orthographic light fitted to the casters' bounding box ---------
  const Clock::time_point t1 = Clock::now();
  const bool shadows = frame.shadows && any_caster && !getenv("X_NOSHADOW");
  Eigen::Matrix4f light_vp = Eigen::Matrix4f::Identity();
  float shadow_texel = 0.0f;
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
    shadow_texel = extent / float(kShadowMapSize);
    // window depth per metre towards the light: clip z changes by light_proj(2,2) per
    // metre of view z, and moving towards the light is +z in the light's view space
    const float depth_per_m = 0.5f * light_proj(2, 2);

    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
    glViewport(0, 0, kShadowMapSize, kShadowMapSize);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glClear(GL_DEPTH_BUFFER_BIT);
    if (n_boxes + n_cyl + n_cones > 0) {
      glUseProgram(prog_mesh_shadow);
      set_mat4(prog_mesh_shadow, "u_light_vp", light_vp);
      draw_meshes(true);
    }
    if (n_spheres > 0) {
      glUseProgram(prog_sphere_shadow);
      set_mat4(prog_sphere_shadow, "u_light_vp", light_vp);
      set_vec3(prog_sphere_shadow, "u_light_dir", L);
      set_vec3(prog_sphere_shadow, "u_light_right", light_right);
      set_vec3(prog_sphere_shadow, "u_light_up", light_up);
      glUniform1f(loc(prog_sphere_shadow, "u_depth_per_m"), depth_per_m);
      glBindVertexArray(sphere_vao);
      glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n_spheres);
    }
  }
  if (getenv("MAGSIM_RENDER_SYNC")) glFinish();
  profile.shadow = ms_since(t1);

  // --- colour pass ---------------------------------------------------------------------
  const Clock::time_point t2 = Clock::now();
  glBindFramebuffer(GL_FRAMEBUFFER, samples > 1 ? msaa_fbo : resolve_fbo);
  glViewport(0, 0, width, height);
  glClearColor(Renderer::to_srgb8(frame.background.r) / 255.0f,
               Renderer::to_srgb8(frame.background.g) / 255.0f,
               Renderer::to_srgb8(frame.background.b) / 255.0f, 1.0f);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, shadow_tex);

  auto set_common = [&](GLuint p) {
    glUseProgram(p);
    set_mat4(p, "u_view_proj", view.view_proj);
    set_vec3(p, "u_eye", frame.camera.eye);
    set_vec3(p, "u_light_dir", L);
    set_mat4(p, "u_light_vp", light_vp);
    glUniform1i(loc(p, "u_shadows"), shadows ? 1 : 0);
    glUniform1f(loc(p, "u_shadow_texel"), shadow_texel);
    glUniform1f(loc(p, "u_shadow_uv"), 1.0f / float(kShadowMapSize));
    set_vec3(p, "u_background", frame.background);
  };

  // meshes first (they keep early depth testing), then impostors, then the large ground
  if (n_boxes + n_cyl + n_cones > 0) {
    set_common(prog_mesh);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    draw_meshes(true);
    glDisable(GL_CULL_FACE);
  }
  if (n_spheres > 0 && !getenv("X_NOSPH")) {
    set_common(prog_sphere);
    const float pixel_angle =
        2.0f * std::tan(0.5f * frame.camera.fov_y_deg * 3.14159265f / 180.0f) / float(height);
    glUniform1f(loc(prog_sphere, "u_pixel_angle"), pixel_angle);
    glUniform1i(loc(prog_sphere, "u_coverage"), samples > 1 ? 1 : 0);
    if (samples > 1) glEnable(GL_SAMPLE_ALPHA_TO_COVERAGE);
    glBindVertexArray(sphere_vao);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n_spheres);
    glDisable(GL_SAMPLE_ALPHA_TO_COVERAGE);
  }
  if (frame.ground && !getenv("X_NOGROUND")) {
    set_common(prog_ground);
    const Eigen::Vector3f gc(view.scene_center.x(), view.scene_center.y(), frame.ground_height);
    set_vec3(prog_ground, "u_ground_center", gc);
    glUniform1f(loc(prog_ground, "u_ground_extent"), view.ground_extent);
    set_vec3(prog_ground, "u_ground_color", frame.ground_color);
    // grid cell: the power of ten just below the scene's diameter, split in ten
    const float cell = std::pow(10.0f, std::floor(std::log10(2.0f * view.scene_radius)));
    glUniform1f(loc(prog_ground, "u_grid"), cell * 0.1f * 2.0f);
    glUniform2f(loc(prog_ground, "u_fade"), 0.35f * view.ground_extent,
                0.9f * view.ground_extent);
    glBindVertexArray(ground_vao);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  }
  glBindVertexArray(0);
  glUseProgram(0);
  if (getenv("MAGSIM_RENDER_SYNC")) glFinish();
  profile.main = ms_since(t2);

  // --- resolve and read back (bottom row first → flip) ---------------------------------
  const Clock::time_point t3 = Clock::now();
  if (samples > 1) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo);
    glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo);
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
int Renderer::samples() const { return impl_->samples; }
const ViewSetup& Renderer::last_view() const { return impl_->view; }
const RenderProfile& Renderer::profile() const { return impl_->profile; }

std::uint8_t Renderer::to_srgb8(float linear) {
  const float c = std::clamp(linear, 0.0f, 1.0f);
  const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return std::uint8_t(std::lround(s * 255.0f));
}

}  // namespace magsim::render
