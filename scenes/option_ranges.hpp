// scenes/option_ranges.hpp — one range per run option, shared by magsim-scene's flags
// (tools/cli_common.hpp OptionCheck), magsolve's flags and the scene file's "options"
// (scenes/options_json.cpp), so that what a flag accepts --write-scene can write and a scene
// file read back, and summary.json's "options" rerun as a scene file.
// Header-only: magsolve (magnetics only) uses it too.
#pragma once

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace magsim::scenes {

/// The values an option may take: [lo, hi], either end open, integers only when `integer`.
struct OptionRange {
  const char* key;   ///< its path in a scene file's "options": "dt", "magnetics.tol"
  const char* flag;  ///< magsim-scene's flag for it ("" when it has none)
  bool integer;
  double lo, hi;
  bool lo_open, hi_open;
  const char* note;  ///< why the bound, for the table in SCENE_FILE.md ("" when obvious)

  bool contains(double x) const {
    if (!std::isfinite(x)) return false;
    if (integer && x != std::floor(x)) return false;
    return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  }
  /// "(0, 1)", "[1, 1000000]", ">= 0 and finite", "> 0 and finite": bounds in %g (integers
  /// in full).
  std::string text() const {
    auto g = [this](double x) {
      char b[32];
      std::snprintf(b, sizeof b, integer ? "%.0f" : "%g", x);
      return std::string(b);
    };
    if (hi == DBL_MAX && !hi_open) return std::string(lo_open ? "> " : ">= ") + g(lo) + " and finite";
    return std::string(lo_open ? "(" : "[") + g(lo) + ", " + g(hi) + (hi_open ? ")" : "]");
  }
  /// "an integer in [1, 64]", "a number in (0, 1)", "a number >= 0 and finite".
  std::string what() const {
    const std::string t = text();
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

/// Every run option that has a flag, with its one range. The scene file's reader, the flags
/// of magsim-scene and magsolve, and the test that they agree (tests/tools/reliability_test.cpp,
/// "one range per option") all iterate over this table.
inline constexpr OptionRange kOptionRanges[] = {
    // magnetics: mag::validate's own ranges (magnetics/magnetization.cpp)
    {"magnetics.dt", "--dt-m", false, 1e-9, 1e-6, false, false, "s"},
    {"magnetics.tol", "--tol", false, 0.0, 1.0, true, true, ""},
    // a bound on the work per solve: at ~10 us an iteration (balls_up), 1e6 iterations are
    // about 10 s a step; 1e9 was a silent 2.7-hour step
    {"magnetics.max_iter", "--max-iter", true, 1, 1000000, false, false, "iterations per solve"},
    {"magnetics.softening", "--softening", false, 0.0, 0.1, false, false, "m"},
    {"dt", "--dt", false, 0.0, 0.1, true, false, "s"},
    {"quickstep_iterations", "--quickstep-iterations", true, 1, 100000, false, false, ""},
    {"quickstep_w", "--quickstep-w", false, 0.0, 2.0, true, true, "ODE's over-relaxation"},
    {"max_substeps", "--max-substeps", true, 1, 64, false, false, ""},
    {"substep_reach", "--substep-reach", false, 0.0, DBL_MAX, true, false, ""},
    {"rolling_friction", "--rolling-friction", false, 0.0, DBL_MAX, false, false, "m"},
    {"rolling_friction_bodies", "--rolling-friction-bodies", false, 0.0, DBL_MAX, false, false, "m"},
    {"eddy_conductivity", "--eddy-conductivity", false, 0.0, DBL_MAX, false, false, "S/m"},
    {"energy_guard_tolerance", "--energy-guard-tolerance", false, 0.0, DBL_MAX, false, false, ""},
    {"energy_guard_floor", "--energy-guard-floor", false, 0.0, DBL_MAX, false, false, "J"},
    {"energy_guard_max_substeps", "--energy-guard-max-substeps", true, 1, 64, false, false, ""},
    // and at most 4 x the cores (checked apart: the machine's); 0 = sized to the free cores
    {"threads", "--threads", true, 0, 1000000000, false, false, "and at most 4 x the cores"},
    {"bh_theta", "--bh-theta", false, 0.0, 1.0, true, false, ""},
    {"bh_threshold", "--bh-threshold", true, 0, 1000000000, false, false, ""},
};

/// The range of the option at `key` (a kOptionRanges key); throws std::logic_error for an
/// unknown key (a typo in the program, not in the input).
inline const OptionRange& option_range(const std::string& key) {
  for (const OptionRange& r : kOptionRanges)
    if (key == r.key) return r;
  throw std::logic_error("option_range: no range for '" + key + "'");
}

}  // namespace magsim::scenes
