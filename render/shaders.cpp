// render/shaders.cpp — the GLSL of the renderer.
//
// Colours arrive linear; every colour pass lights in linear space and writes sRGB-encoded
// values (the framebuffer is plain RGBA8). Spheres are impostors: a quad that covers the
// sphere's silhouette, ray-cast per fragment, with the true depth (in a depth pre-pass
// and in the shadow map) and an analytic edge coverage in alpha, blended back to front.
#include "render/shaders.hpp"

namespace magsim::render::shaders {

const char* const kLightingLib = R"(
uniform vec3 u_eye;            // camera position (m)
uniform vec3 u_light_dir;      // unit, towards the light
uniform mat4 u_view_proj;      // world -> clip
uniform mat4 u_light_vp;       // world -> shadow clip (orthographic)
uniform sampler2DShadow u_shadow_map;
uniform float u_shadow_texel;  // world size of one shadow-map texel (m)
uniform float u_shadow_uv;     // 1 / shadow-map size

#ifndef SHADOWS
#define SHADOWS 1
#endif
// four taps on a rotated grid, each a bilinear 2x2 depth comparison: together they filter
// a ~5x5-texel footprint (each tap costs about 2.5 ms per 720p frame on llvmpipe, so
// softer shadows come from fewer, wider taps rather than many)
const vec2 kTaps[4] = vec2[](vec2(-0.25, -0.75), vec2(0.75, -0.25), vec2(0.25, 0.75),
                             vec2(-0.75, 0.25));

// fraction of the light reaching p (normal n): percentage-closer filtering of the map
// (llvmpipe runs both sides of a branch, so shadows are switched at compile time)
float shadow_factor(vec3 p, vec3 n) {
#if SHADOWS == 0
  return 1.0;
#else
  // normal offset and a small constant bias keep surfaces from shadowing themselves
  vec3 q = p + n * (1.5 * u_shadow_texel) + u_light_dir * u_shadow_texel;
  vec3 c = (u_light_vp * vec4(q, 1.0)).xyz * 0.5 + 0.5;
  c.z = min(c.z, 1.0);  // beyond the far plane: compare as the far plane (lit if empty)
  float radius = 2.0 * u_shadow_uv;
  float sum = 0.0;
  for (int i = 0; i < 4; ++i)
    sum += texture(u_shadow_map, vec3(c.xy + kTaps[i] * radius, c.z));
  return 0.25 * sum;
#endif
}

const vec3 kSun = vec3(0.80, 0.78, 0.74);            // direct light
const vec3 kSkyAmbient = vec3(0.27, 0.29, 0.33);     // ambient light from above
const vec3 kFloorAmbient = vec3(0.09, 0.085, 0.08);  // and from below

// Blinn-Phong + hemispherical ambient + a Fresnel-weighted reflection of a sky gradient.
// metal in [0, 1] (from material_metal in the vertex shader): metals have a dim diffuse,
// a tight highlight and a strong reflection, both tinted by their colour. ao scales the
// ambient and reflected light (sphere_ao.cpp).
vec3 shade(vec3 p, vec3 n, vec3 albedo, float metal, float ao) {
  vec3 V = normalize(u_eye - p);
  vec3 L = u_light_dir;
  float ndl = max(dot(n, L), 0.0);
  float sh = shadow_factor(p, n);
  vec3 ambient = mix(kFloorAmbient, kSkyAmbient, 0.5 + 0.5 * n.z) * ao;
  float nh = max(dot(n, normalize(L + V)), 0.0);
  float spec = pow(nh, mix(48.0, 120.0, metal)) * mix(0.3, 1.6, metal);
  vec3 spec_col = mix(vec3(1.0), albedo * 1.5, metal);
  vec3 col = albedo * (1.0 - 0.6 * metal) * (ambient + kSun * (ndl * sh)) +
             kSun * spec_col * (spec * sh);
  // reflected environment: bright sky, a light horizon, a dark floor below
  float x = 1.0 - max(dot(n, V), 0.0);
  float fresnel = x * x * x * x * x;
  float refl = mix(0.04 + 0.3 * fresnel, 0.55 + 0.35 * fresnel, metal);
  float up = reflect(-V, n).z;
  vec3 env = up >= 0.0 ? mix(vec3(0.85, 0.88, 0.92), vec3(0.42, 0.55, 0.80), min(up * 1.5, 1.0))
                       : mix(vec3(0.40, 0.40, 0.39), vec3(0.12, 0.115, 0.11), min(-up * 4.0, 1.0));
  col += refl * env * ao * (0.6 + 0.4 * sh) * mix(vec3(1.0), albedo * 1.2, metal);
  return col;
}

// linear -> sRGB with three square roots instead of pow (within 0.4/255 of the exact
// curve; llvmpipe's pow is slow)
vec3 encode_srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  vec3 s1 = sqrt(c), s2 = sqrt(s1), s3 = sqrt(s2);
  vec3 curve = 0.585122381 * s1 + 0.783140355 * s2 - 0.368262736 * s3;
  return mix(12.92 * c, curve, step(0.0031308, c));
}
)";

// Material from colour, for the vertex shaders. The frame carries no materials:
// near-grey colours shade as metal (iron), saturated ones as painted surfaces.
const char* const kMaterialLib = R"(
float material_metal(vec3 albedo) {
  float mx = max(albedo.r, max(albedo.g, albedo.b));
  float mn = min(albedo.r, min(albedo.g, albedo.b));
  float sat = (mx - mn) / max(mx, 1e-4);
  return 1.0 - smoothstep(0.06, 0.25, sat);
}
)";

// --- spheres ------------------------------------------------------------------------

// The quad lies in the plane through the sphere's nearest point, perpendicular to the
// direction to the centre. Every ray through the quad meets the sphere (if at all) behind
// the quad, so the quad's rasterized depth is a lower bound of the sphere's depth and the
// colour pass can use the early depth test against the pre-pass (the depth pre-pass
// itself writes gl_FragDepth). The same vertex shader serves both passes; `invariant`
// keeps their fragments identical.
const char* const kSphereVert = R"(
layout(location = 0) in vec2 a_corner;
layout(location = 1) in vec4 i_sphere;  // centre (m), radius (m)
layout(location = 2) in vec4 i_color;  // linear RGB, ambient factor
uniform mat4 u_view_proj;
uniform vec3 u_eye;
uniform float u_pixel_angle;  // 2 tan(fov/2) / height: one pixel's width per metre of depth
invariant gl_Position;
invariant out vec3 v_world;
flat out vec4 v_sphere;
flat out vec3 v_color;
flat out float v_metal;
flat out float v_ao;
void main() {
  vec3 c = i_sphere.xyz;
  float r = i_sphere.w;
  vec3 d = c - u_eye;
  float dist2 = dot(d, d);
  v_sphere = i_sphere;
  v_color = i_color.rgb;
  v_ao = i_color.a;
  v_metal = material_metal(i_color.rgb);
  if (dist2 <= r * r * 1.0001) {  // camera inside the sphere: draw nothing
    v_world = c;
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    return;
  }
  float dist = sqrt(dist2);
  vec3 f = d / dist;
  vec3 up = abs(f.z) < 0.99 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
  vec3 right = normalize(cross(f, up));
  vec3 u = cross(right, f);
  // the tangent cone from the eye has radius t r / sqrt(d^2 - r^2) at distance t along
  // its axis; one pixel more leaves room for the coverage ramp
  float t = dist - r;
  float s = t * (r / sqrt(dist2 - r * r) + u_pixel_angle);
  vec3 p = u_eye + f * t + (right * a_corner.x + u * a_corner.y) * s;
  v_world = p;
  gl_Position = u_view_proj * vec4(p, 1.0);
}
)";

// Ray-sphere intersection shared by the depth and colour passes (u_eye and u_view_proj
// are declared before it): the hit point and normal (at the silhouette just outside the
// sphere for edge pixels), its window depth, and the pixel's coverage from how far the
// ray passes from the centre, measured in pixels.
const char* const kSphereLib = R"(
invariant in vec3 v_world;
flat in vec4 v_sphere;
flat in vec3 v_color;
flat in float v_metal;
flat in float v_ao;
float sphere_hit(out vec3 p, out vec3 n, out float depth) {
  vec3 c = v_sphere.xyz;
  float r = v_sphere.w;
  vec3 rd = normalize(v_world - u_eye);
  vec3 oc = u_eye - c;
  float b = dot(oc, rd);
  float q2 = max(dot(oc, oc) - b * b, 0.0);  // squared distance of the ray from the centre
  float q = sqrt(q2);
  float alpha = clamp((r - q) / max(fwidth(q), 1e-9) + 0.5, 0.0, 1.0);
  if (alpha <= 0.0) discard;
  if (q2 < r * r) n = (oc + (-b - sqrt(r * r - q2)) * rd) / r;
  else n = normalize(oc - b * rd);
  p = c + r * n;
  vec4 clip = u_view_proj * vec4(p, 1.0);
  depth = 0.5 * clip.z / clip.w + 0.5;
  return alpha;
}
)";

// Depth where the sphere covers the whole pixel; edge pixels keep what lies behind them.
const char* const kSphereDepthFrag = R"(
void main() {
  vec3 p, n;
  float depth;
  if (sphere_hit(p, n, depth) < 1.0) discard;
  gl_FragDepth = depth;
}
)";

// Colour, blended by coverage; no depth writes. Fragments behind the depth pre-pass are
// discarded before any lighting.
const char* const kSphereFrag = R"(
uniform sampler2D u_depth;  // copy of the depth after the pre-pass
out vec4 o_color;
void main() {
  vec3 p, n;
  float depth;
  float alpha = sphere_hit(p, n, depth);
  if (depth > texelFetch(u_depth, ivec2(gl_FragCoord.xy), 0).r + 1e-6) discard;
  o_color = vec4(encode_srgb(shade(p, n, v_color, v_metal, v_ao)), alpha);
}
)";

const char* const kSphereShadowVert = R"(
layout(location = 0) in vec2 a_corner;
layout(location = 1) in vec4 i_sphere;
uniform mat4 u_light_vp;
uniform vec3 u_light_dir;
uniform vec3 u_light_right;  // unit, perpendicular to the light
uniform vec3 u_light_up;     // unit, perpendicular to both
out vec2 v_uv;
flat out float v_depth_bulge;  // window-depth change from the centre plane to the cap
uniform float u_depth_per_m;   // window-depth change per metre towards the light
void main() {
  vec3 p = i_sphere.xyz + (u_light_right * a_corner.x + u_light_up * a_corner.y) * i_sphere.w;
  v_uv = a_corner;
  v_depth_bulge = u_depth_per_m * i_sphere.w;
  gl_Position = u_light_vp * vec4(p, 1.0);
}
)";

const char* const kSphereShadowFrag = R"(
in vec2 v_uv;
flat in float v_depth_bulge;
void main() {
  float d2 = dot(v_uv, v_uv);
  if (d2 > 1.0) discard;
  // orthographic light: the quad lies in the centre plane, the surface bulges towards it
  gl_FragDepth = gl_FragCoord.z + v_depth_bulge * sqrt(1.0 - d2);
}
)";

// --- meshes -------------------------------------------------------------------------

const char* const kMeshVert = R"(
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 i_pos;
layout(location = 3) in vec4 i_quat;   // x y z w
layout(location = 4) in vec3 i_scale;
layout(location = 5) in vec3 i_color;
uniform mat4 u_view_proj;
out vec3 v_world;
out vec3 v_normal;
flat out vec3 v_color;
flat out float v_metal;
vec3 qrot(vec4 q, vec3 v) { return v + 2.0 * cross(q.xyz, cross(q.xyz, v) + q.w * v); }
void main() {
  vec3 s = max(i_scale, vec3(1e-9));
  vec3 w = i_pos + qrot(i_quat, a_pos * s);
  v_world = w;
  v_normal = qrot(i_quat, a_normal / s);  // inverse-transpose of R S is R S^-1
  v_color = i_color;
  v_metal = material_metal(i_color);
  gl_Position = u_view_proj * vec4(w, 1.0);
}
)";

const char* const kMeshFrag = R"(
in vec3 v_world;
in vec3 v_normal;
flat in vec3 v_color;
flat in float v_metal;
out vec4 o_color;
void main() {
  vec3 n = normalize(v_normal);
  o_color = vec4(encode_srgb(shade(v_world, n, v_color, v_metal, 1.0)), 1.0);
}
)";

const char* const kMeshShadowVert = R"(
layout(location = 0) in vec3 a_pos;
layout(location = 2) in vec3 i_pos;
layout(location = 3) in vec4 i_quat;
layout(location = 4) in vec3 i_scale;
uniform mat4 u_light_vp;
vec3 qrot(vec4 q, vec3 v) { return v + 2.0 * cross(q.xyz, cross(q.xyz, v) + q.w * v); }
void main() {
  gl_Position = u_light_vp * vec4(i_pos + qrot(i_quat, a_pos * i_scale), 1.0);
}
)";

const char* const kDepthOnlyFrag = R"(
void main() {}
)";

// --- ground -------------------------------------------------------------------------

const char* const kGroundVert = R"(
layout(location = 0) in vec2 a_xy;  // world x, y (m)
uniform mat4 u_view_proj;
uniform float u_ground_height;      // (m)
out vec3 v_world;
void main() {
  vec3 p = vec3(a_xy, u_ground_height);
  v_world = p;
  gl_Position = u_view_proj * vec4(p, 1.0);
}
)";

const char* const kGroundFrag = R"(
in vec3 v_world;
uniform vec3 u_ground_color;     // linear
uniform vec3 u_ground_center;
uniform vec3 u_background_srgb;  // encoded exactly as the clear colour
uniform float u_grid;            // cell size (m)
uniform vec2 u_fade;             // distances from the centre where the fade starts / ends (m)
out vec4 o_color;
void main() {
  vec2 g = v_world.xy / u_grid;
  vec2 w = fwidth(g);
  // faint checker and thin grid lines, both fading out where cells shrink to a few pixels
  float detail = 1.0 - smoothstep(0.15, 0.5, max(w.x, w.y));
  vec2 cell = floor(g);
  float checker = mod(cell.x + cell.y, 2.0);
  vec2 d = abs(fract(g - 0.5) - 0.5) / max(w, vec2(1e-6));
  float line = 1.0 - clamp(min(d.x, d.y) - 0.25, 0.0, 1.0);
  vec3 albedo = u_ground_color * (1.0 - detail * (0.04 * checker + 0.14 * line));
  // matte: sky ambient plus the sun, no highlight
  float sh = shadow_factor(v_world, vec3(0.0, 0.0, 1.0));
  vec3 col = albedo * (kSkyAmbient + kSun * (max(u_light_dir.z, 0.0) * sh));
  float fade = smoothstep(u_fade.x, u_fade.y, length(v_world.xy - u_ground_center.xy));
  o_color = vec4(mix(encode_srgb(col), u_background_srgb, fade), 1.0);
}
)";

}  // namespace magsim::render::shaders
