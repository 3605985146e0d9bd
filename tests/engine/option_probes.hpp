// tests/engine/option_probes.hpp — options away from their defaults, through the table of
// options (engine/options_table.hpp): a valid value of each option other than its default,
// SimOptions with every option so changed, and a comparison option by option. A new option
// in the table is covered without touching these.
#pragma once

#include "engine/options_table.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

namespace magsim::test {

/// A value of `spec` that its checks accept and that differs from its default.
inline engine::OptionValue probe(const engine::OptionSpec& spec) {
  using engine::OptionKind;
  const engine::OptionValue def = spec.default_value();
  switch (spec.kind) {
    case OptionKind::Number:
    case OptionKind::Integer: {
      const engine::OptionRange& r = spec.range;
      // a point 37 % into the range, 0.37 past its lower end when it has no upper one
      double x = r.lo == -DBL_MAX ? 0.37 : r.hi == DBL_MAX ? r.lo + 0.37 : r.lo + 0.37 * (r.hi - r.lo);
      if (r.integer) x = std::floor(x);
      if (x == std::get<double>(def)) x += r.integer ? 1.0 : 0.01 * (r.hi == DBL_MAX ? 1.0 : r.hi - r.lo);
      return x;
    }
    case OptionKind::Bool: return !std::get<bool>(def);
    case OptionKind::Name:
      for (const std::string& n : spec.names)
        if (n != std::get<std::string>(def)) return n;
      break;
    case OptionKind::Vector: return engine::Vec3(0.1, -0.2, -3.7);
  }
  FAIL("no probe for " << spec.key);
  return def;
}

/// Every option of the table at its probe.
inline engine::SimOptions all_changed() {
  engine::SimOptions o;
  for (const engine::OptionSpec& s : engine::options_table()) s.set(o, probe(s));
  return o;
}

/// Option by option: a and b hold the same values.
inline void check_equal(const engine::SimOptions& a, const engine::SimOptions& b) {
  for (const engine::OptionSpec& s : engine::options_table()) {
    INFO("options." << s.key << ": " << engine::value_text(s.get(a), s.kind) << " vs "
                    << engine::value_text(s.get(b), s.kind));
    CHECK(s.get(a) == s.get(b));
  }
}

}  // namespace magsim::test
