// render/shaders.hpp — GLSL sources of the renderer (raw string literals in shaders.cpp).
//
// Attribute locations shared by every program:
//   impostor quads: 0 corner (vec2), 1 centre + radius (vec4, per instance), 2 colour (vec3)
//   meshes:         0 position (vec3), 1 normal (vec3), per instance 2 position (vec3),
//                   3 orientation quaternion xyzw (vec4), 4 scale (vec3), 5 colour (vec3)
//   ground:         0 world x, y (vec2)
#pragma once

namespace magsim::render::shaders {

extern const char* const kSphereVert;
extern const char* const kSphereLib;  ///< prepended to the two sphere fragment shaders
extern const char* const kSphereDepthFrag;
extern const char* const kSphereFrag;
extern const char* const kSphereShadowVert;
extern const char* const kSphereShadowFrag;
extern const char* const kMeshVert;
extern const char* const kMeshFrag;
extern const char* const kMeshShadowVert;
extern const char* const kDepthOnlyFrag;
extern const char* const kGroundVert;
extern const char* const kGroundFrag;
/// Lighting and shadow lookup for the colour-pass fragment shaders.
extern const char* const kLightingLib;
/// material_metal(colour) for the colour-pass vertex shaders.
extern const char* const kMaterialLib;
// None of the sources carries a #version line: the renderer compiles
// "#version 330 core" + defines + the library (if any) + the body.

}  // namespace magsim::render::shaders
