// render/renderer.cpp — the OSMesa context, the order of a frame's passes (shadow map from
// the light's view, colour, down-sampling and read-back) and the public Renderer API. The
// rest of Renderer::Impl is in the files that render/renderer_impl.hpp lists.
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
#include "render/renderer_impl.hpp"

#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>

namespace magsim::render {

namespace {

// glibc's default malloc hands llvmpipe's multi-MB per-frame buffers back to the kernel
// every frame; raising the thresholds makes it 3–4× faster (TOOLCHAIN.md).
void tune_malloc_once() {
  static std::once_flag once;
  std::call_once(once, [] {
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
  });
}

}  // namespace

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

// One function per pass; each leaves the GL state as the next expects it (depth test on,
// depth writes on, GL_LESS, no blending, no face culling).
void Renderer::Impl::draw(const Frame& frame) {
  const Clock::time_point t0 = Clock::now();
  make_current();
  view = view_setup(frame, float(width) / float(height));
  gather(frame);
  sort_spheres(frame);
  const InstanceCounts n = count_instances(frame);
  const LightSetup light = fit_light(frame, n.shadows);
  build_ground(frame, light);
  upload_instances();
  profile.spheres_total = std::size_t(n.spheres);
  profile.spheres_camera = std::size_t(n.visible);
  profile.prepare = ms_since(t0);

  const Clock::time_point t1 = Clock::now();
  shadow_pass(light, n);
  profile.shadow = ms_since(t1);

  // colour: meshes, sphere depth (and its copy), ground, sphere colour (renderer_passes.cpp)
  Clock::time_point t2 = Clock::now();
  // with profiling on, wait for the GL work queued so far and time it as `stage`
  auto lap = [&](double& stage) {
    if (sync_profile) glFinish();
    stage = ms_since(t2);
    t2 = Clock::now();
  };
  const ColorPassSetup c = begin_color_pass(frame, light, n);
  mesh_pass(c, n);
  lap(profile.meshes);
  sphere_depth_pass(c, n);
  lap(profile.sphere_depth);
  ground_pass(c);
  lap(profile.ground);
  sphere_color_pass(c, n);
  glBindVertexArray(0);
  glUseProgram(0);
  lap(profile.spheres);

  const Clock::time_point t3 = Clock::now();
  read_back();
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
