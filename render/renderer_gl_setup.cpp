// render/renderer_gl_setup.cpp — the renderer's GL objects made once per context: the
// scene, depth-copy, output and shadow-map framebuffers, and the shader programs (each
// colour program in two variants, without and with shadow lookups). Failures throw
// std::runtime_error with GL's status or info log.
#include <algorithm>
#include <cstdio>
#include <initializer_list>
#include <stdexcept>
#include <string>

#include "render/renderer_impl.hpp"
#include "render/shaders.hpp"

namespace magsim::render {

namespace {

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

}  // namespace magsim::render
