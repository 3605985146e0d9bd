// engine/options_table.hpp — every run option (SimOptions with its mag::DynamicsOptions and
// mag::FieldOptions) declared once, in options_table.cpp: its key in a scene file's "options"
// (the member's own path, "magnetics.field.bh_theta"), the key files written before used
// ("bh_theta"), its kind, default, unit, range, magsim-scene flag and one line of doc. The
// structs' in-class initialisers equal the table's defaults, so that a default-constructed
// SimOptions (or mag::DynamicsOptions) is the defaults. The scene-file reader and writer
// (scenes/options_json.cpp), the range checks (compile_model), the option flags of magsim-scene,
// magsolve and bench (tools/cli/option_flags.hpp) and summary.json's "options" all go through the
// table, so that an option is read, written, checked and offered as a flag alike;
// tests/engine/options_table_test.cpp holds the structs and scenes/SCENE_FILE.md to it.
#pragma once

#include "engine/scene_desc.hpp"

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <variant>
#include <vector>

namespace magsim::engine {

/// The values a number option may take: [lo, hi], either end open, integers only when `integer`.
/// lo = -DBL_MAX and hi = DBL_MAX, both closed: any finite number.
struct OptionRange {
  bool integer = false;
  double lo = -DBL_MAX, hi = DBL_MAX;
  bool lo_open = false, hi_open = false;

  bool contains(double x) const {
    if (!std::isfinite(x)) return false;
    if (integer && x != std::floor(x)) return false;
    return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  }
  /// "(0, 1)", "[1, 1000000]", ">= 0 and finite", "> 0 and finite", "finite": bounds in %g
  /// (integers in full).
  std::string text() const {
    auto g = [this](double x) {
      char b[32];
      std::snprintf(b, sizeof b, integer ? "%.0f" : "%g", x);
      return std::string(b);
    };
    if (hi == DBL_MAX && !hi_open) {
      if (lo == -DBL_MAX && !lo_open) return "finite";
      return std::string(lo_open ? "> " : ">= ") + g(lo) + " and finite";
    }
    return std::string(lo_open ? "(" : "[") + g(lo) + ", " + g(hi) + (hi_open ? ")" : "]");
  }
  /// "an integer in [1, 64]", "a number in (0, 1)", "a number >= 0 and finite", "a finite number".
  std::string what() const {
    const std::string t = text();
    if (t == "finite") return "a finite number";
    return std::string(integer ? "an integer " : "a number ") + (t[0] == '(' || t[0] == '[' ? "in " : "") + t;
  }
  /// "" when x is in the range, else "must be in (0, 1) (got 1.5)" (scene files' wording; a
  /// JSON value that is not an integer is refused before, as "must be an integer in ...").
  std::string error(double x) const {
    if (contains(x)) return {};
    const std::string t = text();
    return std::string("must be ") + (t[0] == '(' || t[0] == '[' ? "in " : "") + t +
           " (got " + (integer && std::abs(x) < 1e18 ? std::to_string(static_cast<long long>(x)) : shortest(x)) + ")";
  }
  /// x in %g when that reads back as x, else in %.17g.
  static std::string shortest(double x) {
    char b[40];
    std::snprintf(b, sizeof b, "%g", x);
    if (std::strtod(b, nullptr) == x) return b;
    std::snprintf(b, sizeof b, "%.17g", x);
    return b;
  }
};

enum class OptionKind : std::uint8_t {
  Number,   ///< a double in `range`
  Integer,  ///< an int in `range` (range.integer)
  Bool,
  Name,     ///< an enum, spelled by its mag::NameTable
  Vector    ///< a Vec3 of length at most range.hi
};

/// An option's value: Number and Integer as double, Bool, Name as its name, Vector.
using OptionValue = std::variant<double, bool, std::string, Vec3>;

/// One run option. Built only in options_table.cpp.
struct OptionSpec {
  std::string key;       ///< its path in a scene file's "options" = the member's path in SimOptions
  std::string old_key;   ///< the path files written before the aligned layout used ("" = none)
  OptionKind kind = OptionKind::Number;
  std::string unit;      ///< SI unit ("s", "m", "S/m", "m/s^2"); "" = none
  OptionRange range;     ///< Number, Integer: the values it may take; Vector: hi = largest length
  std::vector<std::string> names;  ///< Name: the valid names, in their table's order
  std::string what;      ///< Name: what a name names, in messages ("unknown force model 'x'")
  std::string flag;      ///< magsim-scene's flag ("" = none)
  bool flag_switch = false;  ///< Bool: the flag takes no value and turns the option on
  std::string doc;       ///< one line: what it does (magsim-scene's --help says it)
  OptionValue def;       ///< its default; the member's in-class initialiser equals it
  std::function<OptionValue(const SimOptions&)> get;
  /// Stores a value that error() accepts (a Name by one of `names`).
  std::function<void(SimOptions&, const OptionValue&)> set;

  /// "" when v is a value of this option (its kind, range, names), else why not, in the scene
  /// file's wording: "must be in (0, 1] (got 1.5)", "unknown method 'x' (ours, ...)".
  std::string error(const OptionValue& v) const;
  /// The value that `text` spells, as a command line gives it: a number, on/off (or true/false)
  /// for a Bool, the name itself for a Name (error() then checks it). Throws
  /// std::invalid_argument with the reason ("expected a number, got 'x'") for anything else,
  /// and for a Vector (no one-word form).
  OptionValue parse(const std::string& text) const;
  /// parse(text), error() and set() in one: "" when `o` now holds the value, else why not
  /// (nothing set), for the caller to prefix with its flag or key.
  std::string assign(SimOptions& o, const std::string& text) const;
  /// Its default, declared in the table; equal to its value in a default-constructed SimOptions.
  const OptionValue& default_value() const { return def; }
  /// The values it takes, for SCENE_FILE.md and --help: "a number in (0, 0.1]", "true or
  /// false", "\"sap\", \"hash\", \"simple\"", "[x, y, z] of length <= 1e+06".
  std::string values_text() const;
};

/// Every run option, in the structs' member order. Keys and old keys are all distinct.
const std::vector<OptionSpec>& options_table();
/// The entry whose key is `key`; throws std::logic_error for none (a typo in the program, not in
/// the input).
const OptionSpec& option_spec(const std::string& key);
/// A value as a scene file spells it, for SCENE_FILE.md's defaults and --help: "0.001", "1e-7",
/// "20", "true", "\"sap\"", "[0, 0, -9.81]".
std::string value_text(const OptionValue& v, OptionKind kind);
/// x as a scene file would best spell it: a whole number below 1e5 in full ("1000"), else the
/// shortest decimal that reads back as x, its exponent without '+' or leading zeros ("0.001",
/// "1e-7", "1e6", "-9.81").
std::string number_text(double x);

}  // namespace magsim::engine
