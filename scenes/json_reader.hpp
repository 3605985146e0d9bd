// scenes/json_reader.hpp — the checked JSON reading of scene files, their options and
// magsolve cases: each value read by kind (number, positive, vector, …), every error one line
// "<origin>: <json path>: <what>", unknown keys refused with the allowed list. Header-only,
// so magsolve (magnetics only) and the scene loader share it.
#pragma once

#include "engine/options_table.hpp"
#include "magnetics/names.hpp"
#include "render/frame.hpp"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <cmath>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace magsim::scenes {

/// Throws std::runtime_error("<origin>: <path>: <what>") on the first bad value.
class JsonReader {
 public:
  explicit JsonReader(std::string origin) : origin_(std::move(origin)) {}

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw std::runtime_error(origin_ + ": " + (path.empty() ? "" : path + ": ") + what);
  }

  // objects and their keys
  void object(const nlohmann::json& j, const std::string& path) const {
    if (!j.is_object()) fail(path.empty() ? "(top level)" : path, "must be an object");
  }
  void keys(const nlohmann::json& j, const std::string& path, std::initializer_list<const char*> allowed) const {
    object(j, path);
    for (auto it = j.begin(); it != j.end(); ++it) {
      bool ok = it.key() == "comment";
      for (const char* a : allowed) ok = ok || it.key() == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail(join(path, it.key()), "unknown key (allowed: " + list + ")");
      }
    }
  }
  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  static std::string index(const std::string& path, std::size_t i) {
    return path + "[" + std::to_string(i) + "]";
  }

  // scalars
  double number(const nlohmann::json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, "must be a number");
    const double x = j.get<double>();
    if (!std::isfinite(x)) fail(path, "must be finite");
    return x;
  }
  double positive(const nlohmann::json& j, const std::string& path) const {
    const double x = number(j, path);
    if (!(x > 0)) fail(path, "must be > 0 (got " + fmt(x) + ")");
    return x;
  }
  double non_negative(const nlohmann::json& j, const std::string& path) const {
    const double x = number(j, path);
    if (!(x >= 0)) fail(path, "must be >= 0 (got " + fmt(x) + ")");
    return x;
  }
  double in_range(const nlohmann::json& j, const std::string& path, double lo, double hi) const {
    const double x = number(j, path);
    if (!(x >= lo && x <= hi)) fail(path, "must be in [" + fmt(lo) + ", " + fmt(hi) + "] (got " + fmt(x) + ")");
    return x;
  }
  int integer(const nlohmann::json& j, const std::string& path, int lo, int hi) const {
    if (!j.is_number_integer()) fail(path, "must be an integer");
    const long long x = j.get<long long>();
    if (x < lo || x > hi)
      fail(path, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " + std::to_string(x) + ")");
    return static_cast<int>(x);
  }
  /// A number option in its one range (engine/options_table.hpp): the flags check the same.
  double option(const nlohmann::json& j, const std::string& path, const engine::OptionRange& range) const {
    if (range.integer && !j.is_number_integer()) fail(path, "must be an integer in " + range.text());
    const double x = number(j, path);
    if (const std::string e = range.error(x); !e.empty()) fail(path, e);
    return x;
  }
  bool boolean(const nlohmann::json& j, const std::string& path) const {
    if (!j.is_boolean()) fail(path, "must be true or false");
    return j.get<bool>();
  }
  std::string string(const nlohmann::json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, "must be a string");
    return j.get<std::string>();
  }
  /// A string that names a value in `table`; an unknown name fails with the valid names.
  template <class E, std::size_t N>
  E named(const nlohmann::json& j, const std::string& path, const mag::NameTable<E, N>& table,
          const char* what) const {
    const std::string s = string(j, path);
    E v{};
    if (!table.parse(s, &v)) fail(path, table.unknown(what, s));
    return v;
  }

  // arrays of numbers
  std::vector<double> numbers(const nlohmann::json& j, const std::string& path, const std::string& want) const {
    if (!j.is_array()) fail(path, "must be " + want);
    std::vector<double> v;
    for (const nlohmann::json& x : j) {
      if (!x.is_number()) fail(path, "must be " + want);
      v.push_back(x.get<double>());
      if (!std::isfinite(v.back())) fail(path, "must be " + want + " (non-finite value)");
    }
    return v;
  }
  Eigen::Vector3d vec3(const nlohmann::json& j, const std::string& path) const {
    const std::vector<double> v = numbers(j, path, "3 numbers [x, y, z]");
    if (v.size() != 3) fail(path, "must be 3 numbers [x, y, z]");
    return Eigen::Vector3d(v[0], v[1], v[2]);
  }  // engine/limits.hpp: finite magnitudes beyond what ODE (or the magnetics) can take
  void at_most(const std::string& path, double magnitude, double max, const char* unit) const {
    if (magnitude > max)
      fail(path, "magnitude " + fmt(magnitude) + " " + unit + " exceeds " + fmt(max) + " " + unit +
                     " (engine/limits.hpp: beyond it the rigid-body or magnetics arithmetic overflows)");
  }
  /// vec3 whose length is at most max (unit named in the error).
  Eigen::Vector3d bounded(const nlohmann::json& j, const std::string& path, double max, const char* unit) const {
    const Eigen::Vector3d v = vec3(j, path);
    at_most(path, v.stableNorm(), max, unit);
    return v;
  }

  Eigen::Vector3f vec3f(const nlohmann::json& j, const std::string& path) const { return vec3(j, path).cast<float>(); }
  Eigen::Quaterniond quat(const nlohmann::json& j, const std::string& path) const {
    const std::vector<double> v = numbers(j, path, "4 numbers [w, x, y, z]");
    if (v.size() != 4) fail(path, "must be 4 numbers [w, x, y, z]");
    const Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
    const double n = q.norm();
    // a unit quaternion up to rounding is kept bit for bit: a written scene (--write-scene)
    // then reloads to the same state hash
    if (std::abs(n - 1.0) <= 1e-12) return q;
    if (std::isfinite(n) && n >= 1e-12) return q.normalized();
    // the norm over- or underflowed: scaled by the largest component first, any finite
    // quaternion of norm >= 1e-12 ([1e300, 1e300, 0, 0] too) is normalised
    const Eigen::Vector4d c(v[0], v[1], v[2], v[3]);
    const double big = c.cwiseAbs().maxCoeff();
    if (big == 0.0) fail(path, "must be a non-zero quaternion [w, x, y, z]");
    const Eigen::Vector4d u = c / big;
    if (big * u.norm() < 1e-12)
      fail(path, "must be a quaternion [w, x, y, z] of norm >= 1e-12 (got norm " + fmt(big * u.norm()) + ")");
    const Eigen::Vector4d unit = u / u.norm();
    return Eigen::Quaterniond(unit[0], unit[1], unit[2], unit[3]);
  }
  render::Color color(const nlohmann::json& j, const std::string& path) const {
    const std::vector<double> v = numbers(j, path, "3 numbers [r, g, b] in [0, 1]");
    if (v.size() != 3) fail(path, "must be 3 numbers [r, g, b] in [0, 1]");
    for (double c : v)
      if (!(c >= 0 && c <= 1)) fail(path, "must be 3 numbers [r, g, b] in [0, 1]");
    return render::Color{static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])};
  }

  static std::string fmt(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
  }

 private:
  std::string origin_;
};

// A value of `key` in `obj` when present: f(value, path) is called with it.
template <class F>
void if_present(const nlohmann::json& obj, const char* key, const std::string& path, F&& f) {
  const auto it = obj.find(key);
  if (it != obj.end()) f(*it, JsonReader::join(path, key));
}

}  // namespace magsim::scenes
