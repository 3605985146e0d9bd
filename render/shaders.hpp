// render/shaders.hpp — GLSL sources of the renderer (raw string literals in shaders.cpp).
//
// Attribute locations shared by every program:
//   impostor quads: 0 corner (vec2), 1 centre + radius (vec4, per instance), 2 colour (vec3)
//   meshes:         0 position (vec3), 1 normal (vec3), per instance 2 position (vec3),
//                   3 orientation quaternion xyzw (vec4), 4 scale (vec3), 5 colour (vec3)
//   ground:         0 corner (vec2)
#pragma once

namespace magsim::render::shaders {

extern const char* const kSphereVert;
extern const char* const kSphereFrag;
extern const char* const kSphereShadowVert;
extern const char* const kSphereShadowFrag;
extern const char* const kMeshVert;
extern const char* const kMeshFrag;
extern const char* const kMeshShadowVert;
extern const char* const kDepthOnlyFrag;
extern const char* const kGroundVert;
extern const char* const kGroundFrag;
/// Lighting and shadow lookup. The colour-pass fragment shaders (kSphereFrag, kMeshFrag,
/// kGroundFrag) carry no #version line: they are compiled as
/// "#version 330 core" + kLightingLib + body.
extern const char* const kLightingLib;

}  // namespace magsim::render::shaders
