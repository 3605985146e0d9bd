// scenes/scene_file.cpp — scenes as JSON files (nlohmann::json), mirroring SceneDesc.
//
// Schema (every key optional unless marked; defaults are SceneDesc's; SI units; keys are
// the SceneDesc field names; "comment" is allowed in every object and ignored; // and /* */
// comments are allowed in the text). Full description with an example: SCENE_FILE.md.
//
//   {
//     "name": "two_balls",                      // default: the file name without .json
//     "description": "…", "modelling_level": "…",
//     "default_seconds": 2.0,                   // > 0 (s)
//     "escape_radius": 0,                       // >= 0 (m); 0 = "escaped" not measured
//     "H0": [0, 0, 0],                          // uniform external field (A/m)
//     "camera": {"eye": [x,y,z], "target": [x,y,z], "up": [x,y,z],
//                "fov_y_deg": 40, "z_near": 0, "z_far": 0},
//     "options": {"dt": 1e-3, "magnetics": {"method": "anderson", "field": {…}}, …},
//                  // every run option: engine/options_table.cpp (SCENE_FILE.md lists them)
//     "bodies": [                               // required
//       {"name": "ball_0", "type": "dynamic" | "kinematic" | "static",
//        "position": [x,y,z], "orientation": [w,x,y,z],
//        "velocity": [..], "angular_velocity": [..],
//        "density": 7870, "mass": 0,            // mass > 0 overrides density·volume
//        "color": [r,g,b], "visible": true, "magnet": false,
//        "shapes": [{"kind": "sphere" | "box" | "capsule" | "cylinder",
//                    "offset": [x,y,z], "rotation": [w,x,y,z],
//                    "size": r | [r] | [hx,hy,hz] | [r, half_length]}],
//        "moments": [{"offset": [x,y,z], "permanent": false, "volume": V,   // V > 0 (m³)
//                     "Ms": 1.6e6,               // induced only (A/m)
//                     "moment": [mx,my,mz],      // permanent only (A·m², body frame)
//                     "interaction_radius": -1}]} // bounded pairs (m); < 0 = from the shape
//     ]
//   }
//
// Errors are one line: "<file>: <json path>: <what>", e.g.
//   "scene.json: bodies[3].shapes[0].size: must be 3 positive numbers (half extents)".
#include "scenes/scene_file.hpp"

#include "engine/limits.hpp"
#include "engine/model.hpp"
#include "magnetics/magnetization.hpp"
#include "scenes/json_reader.hpp"
#include "scenes/options_json.hpp"
#include "scenes/json_unique_keys.hpp"
#include "scenes/text_file.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <stdexcept>

namespace magsim::scenes {

using engine::BodyDesc;
using engine::BodyType;
using engine::MomentDesc;
using engine::Quat;
using engine::SceneDesc;
using engine::ShapeDesc;
using engine::ShapeKind;
using engine::SimOptions;
using engine::SpaceKind;
using engine::Vec3;
using json = nlohmann::json;

namespace {

ShapeKind shape_kind(const JsonReader& r, const json& j, const std::string& path) {
  return r.named(j, path, engine::kShapeKindNames, "shape kind");
}

BodyType body_type(const JsonReader& r, const json& j, const std::string& path) {
  return r.named(j, path, engine::kBodyTypeNames, "body type");
}

Vec3 shape_size(const JsonReader& r, ShapeKind kind, const json& j, const std::string& path) {
  switch (kind) {
    case ShapeKind::Sphere: {
      const char* want = "must be a positive radius (a number or [r])";
      if (j.is_number()) {
        const double x = r.number(j, path);
        if (!(x > 0)) r.fail(path, std::string(want) + " (got " + JsonReader::fmt(x) + ")");
        return Vec3(x, x, x);
      }
      const std::vector<double> v = r.numbers(j, path, "a positive radius (a number or [r])");
      if (v.size() != 1 || !(v[0] > 0)) r.fail(path, want);
      return Vec3(v[0], v[0], v[0]);
    }
    case ShapeKind::Box: {
      const char* want = "must be 3 positive numbers (half extents [hx, hy, hz])";
      const std::vector<double> v = r.numbers(j, path, "3 positive numbers (half extents [hx, hy, hz])");
      if (v.size() != 3 || !(v[0] > 0 && v[1] > 0 && v[2] > 0)) r.fail(path, want);
      return Vec3(v[0], v[1], v[2]);
    }
    case ShapeKind::Capsule:
    case ShapeKind::Cylinder: {
      const char* want = "must be 2 positive numbers [radius, half_length]";
      const std::vector<double> v = r.numbers(j, path, "2 positive numbers [radius, half_length]");
      if (v.size() != 2 || !(v[0] > 0 && v[1] > 0)) r.fail(path, want);
      return Vec3(v[0], v[1], 0.0);
    }
  }
  return Vec3::Zero();
}

ShapeDesc read_shape(const JsonReader& r, const json& j, const std::string& path) {
  r.keys(j, path, {"kind", "offset", "rotation", "size"});
  ShapeDesc s;
  if_present(j, "kind", path, [&](const json& v, const std::string& p) { s.kind = shape_kind(r, v, p); });
  if_present(j, "offset", path, [&](const json& v, const std::string& p) { s.offset = r.bounded(v, p, engine::limits::kMaxCoordinate, "m"); });
  if_present(j, "rotation", path, [&](const json& v, const std::string& p) { s.rotation = r.quat(v, p); });
  if (!j.contains("size")) r.fail(JsonReader::join(path, "size"), "required");
  s.size = shape_size(r, s.kind, j.at("size"), JsonReader::join(path, "size"));
  r.at_most(JsonReader::join(path, "size"), s.size.cwiseAbs().maxCoeff(), engine::limits::kMaxSize, "m");
  return s;
}

MomentDesc read_moment(const JsonReader& r, const json& j, const std::string& path) {
  r.keys(j, path, {"offset", "permanent", "volume", "Ms", "moment", "interaction_radius"});
  MomentDesc m;
  if_present(j, "offset", path, [&](const json& v, const std::string& p) { m.offset = r.bounded(v, p, engine::limits::kMaxCoordinate, "m"); });
  if_present(j, "permanent", path, [&](const json& v, const std::string& p) { m.permanent = r.boolean(v, p); });
  if (!j.contains("volume")) r.fail(JsonReader::join(path, "volume"), "required (> 0, m³)");
  m.volume = r.positive(j.at("volume"), JsonReader::join(path, "volume"));
  r.at_most(JsonReader::join(path, "volume"), m.volume, engine::limits::kMaxVolume, "m^3");
  if_present(j, "Ms", path, [&](const json& v, const std::string& p) {
    if (m.permanent) r.fail(p, "only for induced moments (\"permanent\": false)");
    m.Ms = r.positive(v, p);
    r.at_most(p, m.Ms, engine::limits::kMaxMs, "A/m");
  });
  if_present(j, "moment", path, [&](const json& v, const std::string& p) {
    if (!m.permanent) r.fail(p, "only for permanent moments (\"permanent\": true)");
    m.moment = r.bounded(v, p, engine::limits::kMaxMoment, "A·m^2");
  });
  if_present(j, "interaction_radius", path, [&](const json& v, const std::string& p) { m.interaction_radius = r.number(v, p); });
  // a permanent moment without "moment" used to load as a zero magnet
  if (m.permanent && !j.contains("moment"))
    r.fail(JsonReader::join(path, "moment"), "required for a permanent moment ([mx, my, mz], A·m², body frame)");
  return m;
}

// `s` for an error line: control bytes as \n, \t, \xNN; cut after about 60 bytes (at a
// UTF-8 character boundary)
std::string escaped(const std::string& s) {
  std::string e;
  std::size_t i = 0;
  for (; i < s.size() && (e.size() < 60 || (static_cast<unsigned char>(s[i]) & 0xc0) == 0x80); ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    char hex[5];
    std::snprintf(hex, sizeof hex, "\\x%02x", c);
    if (c == '\n') e += "\\n";
    else if (c == '\r') e += "\\r";
    else if (c == '\t') e += "\\t";
    else if (c < 0x20 || c == 0x7f) e += hex;
    else e += s[i];
  }
  return i < s.size() ? e + "..." : e;
}

// A body name is written into states.csv (quoted when it holds a comma, quote or line break)
// and error lines: tab and line breaks are allowed, other control bytes (NUL cut the name in
// states.csv) are refused.
void check_body_name(const JsonReader& r, const std::string& name, const std::string& path) {
  for (const char ch : name) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f)
      r.fail(path, "must not contain control characters other than tab and line breaks (got \"" + escaped(name) + "\")");
  }
}

BodyDesc read_body(const JsonReader& r, const json& j, const std::string& path, std::size_t i) {
  r.keys(j, path, {"name", "type", "position", "orientation", "velocity", "angular_velocity",
                   "density", "mass", "shapes", "moments", "color", "visible", "magnet"});
  BodyDesc b;
  b.name = "body_" + std::to_string(i);
  if_present(j, "name", path, [&](const json& v, const std::string& p) {
    b.name = r.string(v, p);
    check_body_name(r, b.name, p);
  });
  if_present(j, "type", path, [&](const json& v, const std::string& p) { b.type = body_type(r, v, p); });
  if_present(j, "position", path, [&](const json& v, const std::string& p) { b.position = r.bounded(v, p, engine::limits::kMaxCoordinate, "m"); });
  if_present(j, "orientation", path, [&](const json& v, const std::string& p) { b.orientation = r.quat(v, p); });
  if_present(j, "velocity", path, [&](const json& v, const std::string& p) { b.velocity = r.bounded(v, p, engine::limits::kMaxSpeed, "m/s"); });
  if_present(j, "angular_velocity", path, [&](const json& v, const std::string& p) {
    b.angular_velocity = r.bounded(v, p, engine::limits::kMaxAngularSpeed, "rad/s");
  });
  if_present(j, "density", path, [&](const json& v, const std::string& p) { b.density = r.positive(v, p); });
  if_present(j, "mass", path, [&](const json& v, const std::string& p) {
    b.mass = r.non_negative(v, p);
    if (b.mass > 0 && (b.mass < engine::limits::kMinMass || b.mass > engine::limits::kMaxMass))
      r.fail(p, "must be 0 (density x volume) or in [" + JsonReader::fmt(engine::limits::kMinMass) + ", " +
                    JsonReader::fmt(engine::limits::kMaxMass) + "] kg (got " + JsonReader::fmt(b.mass) +
                    "; engine/limits.hpp: beyond it ODE's arithmetic overflows)");
  });
  if_present(j, "color", path, [&](const json& v, const std::string& p) { b.color = r.color(v, p); });
  if_present(j, "visible", path, [&](const json& v, const std::string& p) { b.visible = r.boolean(v, p); });
  if_present(j, "magnet", path, [&](const json& v, const std::string& p) { b.magnet = r.boolean(v, p); });
  if_present(j, "shapes", path, [&](const json& v, const std::string& p) {
    if (!v.is_array()) r.fail(p, "must be an array of shapes");
    for (std::size_t k = 0; k < v.size(); ++k) b.shapes.push_back(read_shape(r, v[k], JsonReader::index(p, k)));
  });
  if_present(j, "moments", path, [&](const json& v, const std::string& p) {
    if (!v.is_array()) r.fail(p, "must be an array of moments");
    for (std::size_t k = 0; k < v.size(); ++k) b.moments.push_back(read_moment(r, v[k], JsonReader::index(p, k)));
  });
  if (b.type == BodyType::Dynamic && b.shapes.empty())
    r.fail(JsonReader::join(path, "shapes"), "a dynamic body needs at least one shape");
  return b;
}

void read_camera(const JsonReader& r, const json& j, const std::string& path, render::Camera* c) {
  r.keys(j, path, {"eye", "target", "up", "fov_y_deg", "z_near", "z_far"});
  if_present(j, "eye", path, [&](const json& v, const std::string& p) { c->eye = r.vec3f(v, p); });
  if_present(j, "target", path, [&](const json& v, const std::string& p) { c->target = r.vec3f(v, p); });
  if_present(j, "up", path, [&](const json& v, const std::string& p) { c->up = r.vec3f(v, p); });
  if_present(j, "fov_y_deg", path, [&](const json& v, const std::string& p) {
    c->fov_y_deg = static_cast<float>(r.in_range(v, p, 1.0, 179.0));
  });
  if_present(j, "z_near", path, [&](const json& v, const std::string& p) { c->z_near = static_cast<float>(r.non_negative(v, p)); });
  if_present(j, "z_far", path, [&](const json& v, const std::string& p) { c->z_far = static_cast<float>(r.non_negative(v, p)); });
  // a degenerate view rendered blank (eye = target) or a guessed orientation (up ∥ view)
  if (const std::string e = engine::camera_error(*c); !e.empty()) r.fail(path, e);
}

// The scene name becomes the output folder out/<name>_<method>: no path separators, no "."
// or ".." component, no control bytes, valid UTF-8 (the JSON parser checks the UTF-8 of
// strings, but not of the file name a default name comes from).
std::string bad_name_reason(const std::string& name) {
  if (name.empty()) return "must not be empty";
  if (name == "." || name == "..") return "must not be '.' or '..'";
  std::size_t i = 0;
  while (i < name.size()) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (c == '/' || c == '\\') return "must not contain '/' or '\\' (it names the output folder)";
    if (c < 0x20 || c == 0x7f) return "must not contain control characters";
    int extra = c < 0x80 ? 0 : (c & 0xe0) == 0xc0 ? 1 : (c & 0xf0) == 0xe0 ? 2 : (c & 0xf8) == 0xf0 ? 3 : -1;
    if (extra < 0 || (extra == 1 && c < 0xc2) || i + extra >= name.size())
      return "must be valid UTF-8";
    for (int k = 1; k <= extra; ++k)
      if ((static_cast<unsigned char>(name[i + k]) & 0xc0) != 0x80) return "must be valid UTF-8";
    i += 1 + extra;
  }
  return {};
}

std::string stem(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  std::string s = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = s.rfind('.');
  return dot == std::string::npos ? s : s.substr(0, dot);
}

}  // namespace

SceneDesc parse_scene_json(const std::string& text, const std::string& origin) {
  const JsonReader r(origin);
  json doc;
  try {
    doc = parse_unique_keys(text, /*ignore_comments=*/true);
  } catch (const JsonStructureError& e) {  // "bodies[0].position: duplicate key", too deep, a NUL
    r.fail("", e.what());
  } catch (const json::exception& e) {  // parse_error, or out_of_range for 1e999
    std::string what = e.what();
    const std::size_t close = what.find("] ");  // drop "[json.exception.parse_error.101] "
    if (what.rfind("[json.exception", 0) == 0 && close != std::string::npos) what = what.substr(close + 2);
    r.fail("", "malformed JSON: " + what);
  }

  r.keys(doc, "", {"name", "description", "modelling_level", "default_seconds", "escape_radius",
                   "H0", "camera", "options", "bodies"});
  SceneDesc s;
  s.name = stem(origin);
  if_present(doc, "name", "", [&](const json& v, const std::string& p) { s.name = r.string(v, p); });
  if (const std::string why = bad_name_reason(s.name); !why.empty())
    r.fail(doc.contains("name") ? "name" : "(file name)", "the scene name " + why);
  if_present(doc, "description", "", [&](const json& v, const std::string& p) { s.description = r.string(v, p); });
  if_present(doc, "modelling_level", "", [&](const json& v, const std::string& p) { s.modelling_level = r.string(v, p); });
  if_present(doc, "default_seconds", "", [&](const json& v, const std::string& p) { s.default_seconds = r.positive(v, p); });
  if_present(doc, "escape_radius", "", [&](const json& v, const std::string& p) { s.escape_radius = r.non_negative(v, p); });
  if_present(doc, "H0", "", [&](const json& v, const std::string& p) { s.H0 = r.bounded(v, p, engine::limits::kMaxField, "A/m"); });
  if_present(doc, "camera", "", [&](const json& v, const std::string& p) { read_camera(r, v, p, &s.camera); });
  if_present(doc, "options", "", [&](const json& v, const std::string& p) { from_json(r, v, p, &s.options); });
  if (!doc.contains("bodies")) r.fail("bodies", "required (an array of bodies)");
  const json& bodies = doc.at("bodies");
  if (!bodies.is_array()) r.fail("bodies", "must be an array of bodies");
  for (std::size_t i = 0; i < bodies.size(); ++i)
    s.bodies.push_back(read_body(r, bodies[i], JsonReader::index("bodies", i), i));
  return s;
}

SceneDesc load_scene_file(const std::string& path) {
  std::string text;
  try {
    text = read_text_file(path);  // regular files only, at most kMaxInputBytes
  } catch (const InputFileError& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  return parse_scene_json(text, path);
}

// ---- writing (the inverse of the reader above: every field, so a scene reloads as it was) ----
namespace {

json vec3f(const Eigen::Vector3f& v) { return json::array({v.x(), v.y(), v.z()}); }
json quat(const Quat& q) { return json::array({q.w(), q.x(), q.y(), q.z()}); }

json shape_json(const ShapeDesc& sh) {
  json size;
  switch (sh.kind) {
    case ShapeKind::Sphere: size = json::array({sh.size.x()}); break;
    case ShapeKind::Box: size = vec3_json(sh.size); break;
    case ShapeKind::Capsule:
    case ShapeKind::Cylinder: size = json::array({sh.size.x(), sh.size.y()}); break;
  }
  return json{{"kind", engine::kShapeKindNames.name(sh.kind)}, {"offset", vec3_json(sh.offset)}, {"rotation", quat(sh.rotation)},
              {"size", size}};
}

json moment_json(const MomentDesc& m) {
  json j{{"offset", vec3_json(m.offset)}, {"permanent", m.permanent}, {"volume", m.volume},
         {"interaction_radius", m.interaction_radius}};
  if (m.permanent) j["moment"] = vec3_json(m.moment);
  else j["Ms"] = m.Ms;
  return j;
}

json body_json(const BodyDesc& b) {
  json shapes = json::array(), moments = json::array();
  for (const ShapeDesc& sh : b.shapes) shapes.push_back(shape_json(sh));
  for (const MomentDesc& m : b.moments) moments.push_back(moment_json(m));
  return json{{"name", b.name},
              {"type", engine::kBodyTypeNames.name(b.type)},
              {"position", vec3_json(b.position)},
              {"orientation", quat(b.orientation)},
              {"velocity", vec3_json(b.velocity)},
              {"angular_velocity", vec3_json(b.angular_velocity)},
              {"density", b.density},
              {"mass", b.mass},
              {"color", json::array({b.color.r, b.color.g, b.color.b})},
              {"visible", b.visible},
              {"magnet", b.magnet},
              {"shapes", shapes},
              {"moments", moments}};
}

}  // namespace

json scene_to_json(const SceneDesc& s) {
  json bodies = json::array();
  for (const BodyDesc& b : s.bodies) bodies.push_back(body_json(b));
  const render::Camera& c = s.camera;
  return json{{"name", s.name},
              {"description", s.description},
              {"modelling_level", s.modelling_level},
              {"default_seconds", s.default_seconds},
              {"escape_radius", s.escape_radius},
              {"H0", vec3_json(s.H0)},
              {"camera",
               {{"eye", vec3f(c.eye)}, {"target", vec3f(c.target)}, {"up", vec3f(c.up)},
                {"fov_y_deg", c.fov_y_deg}, {"z_near", c.z_near}, {"z_far", c.z_far}}},
              {"options", to_json(s.options)},
              {"bodies", bodies}};
}

}  // namespace magsim::scenes
