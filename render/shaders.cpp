// render/shaders.cpp — the GLSL of the renderer.
//
// Colours arrive linear; every colour pass lights in linear space and writes sRGB-encoded
// values (the framebuffer is plain RGBA8). Spheres are impostors: a quad that covers the
// sphere's silhouette, ray-cast per fragment, writing the true depth (also into the
// shadow map), with an analytic coverage in alpha for MSAA alpha-to-coverage.
#include "render/shaders.hpp"

namespace magsim::render::shaders {

const char* const kLightingLib = R"(
uniform vec3 u_eye;            // camera position (m)
uniform vec3 u_light_dir;      // unit, towards the light
uniform mat4 u_view_proj;      // world -> clip
uniform mat4 u_light_vp;       // world -> shadow clip (orthographic)
uniform sampler2DShadow u_shadow_map;
uniform int u_shadows;         // 0: everything lit
uniform float u_shadow_texel;  // world size of one shadow-map texel (m)
uniform float u_shadow_uv;     // 1 / shadow-map size
uniform vec3 u_background;     // linear

// 12 taps on a spiral inside the unit disk; each tap is a bilinear 2x2 comparison
const vec2 kTaps[12] = vec2[](
  vec2( 0.191,  0.000), vec2(-0.186,  0.267), vec2(-0.214, -0.369), vec2( 0.516, -0.150),
  vec2(-0.052,  0.598), vec2(-0.580, -0.282), vec2( 0.590,  0.440), vec2(-0.637,  0.498),
  vec2( 0.088, -0.864), vec2( 0.736,  0.445), vec2(-0.960, -0.057), vec2( 0.522, -0.830));

float shadow_factor(vec3 p, vec3 n) {
  if (u_shadows == 0) return 1.0;
  // normal offset and a small constant bias keep surfaces from shadowing themselves
  vec3 q = p + n * (1.5 * u_shadow_texel) + u_light_dir * (1.0 * u_shadow_texel);
  vec4 s = u_light_vp * vec4(q, 1.0);
  vec3 c = s.xyz * 0.5 + 0.5;
  c.z = min(c.z, 1.0);
  float radius = 2.5 * u_shadow_uv;
  float sum = 0.0;
  for (int i = 0; i < 12; ++i)
    sum += texture(u_shadow_map, vec3(c.xy + kTaps[i] * radius, c.z));
  return sum * (1.0 / 12.0);
}

vec3 sky_light(vec3 d) {
  // environment seen in a reflection: bright sky above, dim warm ground below
  float up = clamp(d.z, -1.0, 1.0);
  vec3 sky = mix(vec3(0.80, 0.84, 0.90), vec3(0.45, 0.58, 0.82), smoothstep(0.0, 0.8, up));
  vec3 floor_col = vec3(0.22, 0.21, 0.20);
  return up >= 0.0 ? sky : mix(vec3(0.45, 0.45, 0.44), floor_col, smoothstep(0.0, 0.3, -up));
}

// Blinn-Phong + hemispherical ambient + a Fresnel-weighted environment reflection.
// The frame carries no materials: near-grey colours shade as metal (iron),
// saturated ones as painted surfaces. metal_hint < 0: decide from the colour.
vec3 shade(vec3 p, vec3 n, vec3 albedo, float metal_hint) {
  vec3 V = normalize(u_eye - p);
  vec3 L = u_light_dir;
  float ndl = dot(n, L);
  float sh = ndl > 0.0 ? shadow_factor(p, n) : 0.0;
  float metal = metal_hint;
  if (metal < 0.0) {
    float mx = max(albedo.r, max(albedo.g, albedo.b));
    float mn = min(albedo.r, min(albedo.g, albedo.b));
    float sat = (mx - mn) / max(mx, 1e-4);
    metal = 1.0 - smoothstep(0.06, 0.25, sat);
  }
  float hemi = 0.5 + 0.5 * n.z;
  vec3 ambient = mix(vec3(0.10, 0.095, 0.09), vec3(0.26, 0.28, 0.32), hemi);
  vec3 H = normalize(L + V);
  float nh = max(dot(n, H), 0.0);
  float shininess = mix(40.0, 90.0, metal);
  float spec = pow(nh, shininess) * mix(0.35, 1.4, metal);
  vec3 spec_col = mix(vec3(1.0), 0.3 + 0.7 * albedo, metal);
  vec3 diffuse = albedo * mix(1.0, 0.55, metal);
  float light = 1.0;
  vec3 col = diffuse * (ambient + light * max(ndl, 0.0) * sh) + spec_col * spec * sh * light;
  float nv = max(dot(n, V), 0.0);
  float fresnel = pow(1.0 - nv, 5.0);
  float refl = mix(0.03 + 0.25 * fresnel, 0.30 + 0.30 * fresnel, metal);
  vec3 env = sky_light(reflect(-V, n));
  // reflections of the sky are dimmer on the shadowed side
  col += refl * env * mix(0.55, 1.0, sh) * mix(vec3(1.0), 0.4 + 0.6 * albedo, metal);
  return col;
}

vec3 encode_srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
)";

// --- spheres ------------------------------------------------------------------------

const char* const kSphereVert = R"(#version 330 core
layout(location = 0) in vec2 a_corner;
layout(location = 1) in vec4 i_sphere;  // centre (m), radius (m)
layout(location = 2) in vec3 i_color;
uniform mat4 u_view_proj;
uniform vec3 u_eye;
uniform float u_pixel_angle;  // 2 tan(fov/2) / height: one pixel's width per metre of depth
out vec3 v_world;
flat out vec4 v_sphere;
flat out vec3 v_color;
void main() {
  vec3 c = i_sphere.xyz;
  float r = i_sphere.w;
  vec3 d = c - u_eye;
  float dist2 = dot(d, d);
  v_sphere = i_sphere;
  v_color = i_color;
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
  // the tangent cone from the eye cuts the plane through the centre in a circle of
  // radius r d / sqrt(d^2 - r^2); one pixel more leaves room for the coverage ramp
  float s = r * dist / sqrt(dist2 - r * r) + dist * u_pixel_angle;
  vec3 p = c + (right * a_corner.x + u * a_corner.y) * s;
  v_world = p;
  gl_Position = u_view_proj * vec4(p, 1.0);
}
)";

const char* const kSphereFrag = R"(
in vec3 v_world;
flat in vec4 v_sphere;
flat in vec3 v_color;
uniform int u_coverage;  // 1: alpha carries the silhouette coverage (MSAA)
out vec4 o_color;
void main() {
  vec3 c = v_sphere.xyz;
  float r = v_sphere.w;
  vec3 rd = normalize(v_world - u_eye);
  vec3 oc = u_eye - c;
  float b = dot(oc, rd);
  // squared distance of the ray from the centre, and the silhouette coverage from it
  float q2 = max(dot(oc, oc) - b * b, 0.0);
  float q = sqrt(q2);
  float alpha = clamp((r - q) / max(fwidth(q), 1e-9) + 0.5, 0.0, 1.0);
  if (alpha <= (u_coverage == 1 ? 0.0 : 0.5)) discard;
  vec3 n;
  if (q2 < r * r) {
    float t = -b - sqrt(r * r - q2);
    n = (oc + t * rd) / r;
  } else {
    n = normalize(oc - b * rd);  // just outside: use the silhouette point
  }
  vec3 p = c + r * n;
  vec4 clip = u_view_proj * vec4(p, 1.0);
  gl_FragDepth = 0.5 * clip.z / clip.w + 0.5;
  o_color = vec4(encode_srgb(shade(p, n, v_color, -1.0)), alpha);
}
)";

const char* const kSphereShadowVert = R"(#version 330 core
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

const char* const kSphereShadowFrag = R"(#version 330 core
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

const char* const kMeshVert = R"(#version 330 core
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
vec3 qrot(vec4 q, vec3 v) { return v + 2.0 * cross(q.xyz, cross(q.xyz, v) + q.w * v); }
void main() {
  vec3 s = max(i_scale, vec3(1e-9));
  vec3 w = i_pos + qrot(i_quat, a_pos * s);
  v_world = w;
  v_normal = qrot(i_quat, a_normal / s);  // inverse-transpose of R S is R S^-1
  v_color = i_color;
  gl_Position = u_view_proj * vec4(w, 1.0);
}
)";

const char* const kMeshFrag = R"(
in vec3 v_world;
in vec3 v_normal;
flat in vec3 v_color;
out vec4 o_color;
void main() {
  vec3 n = normalize(v_normal);
  o_color = vec4(encode_srgb(shade(v_world, n, v_color, -1.0)), 1.0);
}
)";

const char* const kMeshShadowVert = R"(#version 330 core
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

const char* const kDepthOnlyFrag = R"(#version 330 core
void main() {}
)";

// --- ground -------------------------------------------------------------------------

const char* const kGroundVert = R"(#version 330 core
layout(location = 0) in vec2 a_corner;
uniform mat4 u_view_proj;
uniform vec3 u_ground_center;  // scene centre projected on the ground (m)
uniform float u_ground_extent; // half side (m)
out vec3 v_world;
void main() {
  vec3 p = u_ground_center + vec3(a_corner * u_ground_extent, 0.0);
  v_world = p;
  gl_Position = u_view_proj * vec4(p, 1.0);
}
)";

const char* const kGroundFrag = R"(
in vec3 v_world;
uniform vec3 u_ground_color;   // linear
uniform vec3 u_ground_center;
uniform float u_grid;          // cell size (m)
uniform vec2 u_fade;           // distance from the centre where the ground starts / ends fading (m)
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
  vec3 albedo = u_ground_color * (1.0 - detail * (0.05 * checker + 0.18 * line));
  vec3 col = shade(v_world, vec3(0.0, 0.0, 1.0), albedo, 0.0);
  float fade = smoothstep(u_fade.x, u_fade.y, length(v_world.xy - u_ground_center.xy));
  col = mix(col, u_background, fade);
  o_color = vec4(encode_srgb(col), 1.0);
}
)";

}  // namespace magsim::render::shaders
