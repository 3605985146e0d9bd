// tools/cli/option_flags.hpp — magsim-scene's option flags: one per entry of the table of run
// options that names a flag (engine/options_table.hpp), with the entry's range and a help
// made of its doc, unit, scene-file key and default, applied to the scene's options when
// given. A number takes its range (OptionCheck, as the scene file does); a bool takes on | off,
// or nothing when it is a switch; a name one of its table's names.
#pragma once

#include "engine/options_table.hpp"
#include "tools/cli/cli_common.hpp"

#include <CLI/CLI.hpp>

#include <cstdlib>
#include <deque>
#include <stdexcept>
#include <string>

namespace magsim::tools {

class OptionFlags {
 public:
  /// Adds the flag of every table entry that has one to app, in `group`.
  void add(CLI::App* app, const std::string& group) {
    for (const engine::OptionSpec& s : engine::options_table()) {
      if (s.flag.empty()) continue;
      Flag& f = flags_.emplace_back(Flag{&s, {}, nullptr});
      if (s.flag_switch) {
        f.option = app->add_flag(s.flag, s.doc);
      } else {
        f.option = app->add_option(s.flag, f.text, help(s));
        if (s.kind == engine::OptionKind::Number || s.kind == engine::OptionKind::Integer)
          f.option->check(OptionCheck(s.range))->type_name(s.kind == engine::OptionKind::Integer ? "INT" : "FLOAT");
      }
      f.option->group(group);
    }
  }

  /// Sets each option whose flag was given. Throws std::invalid_argument "<flag>: <why>" for a
  /// bool that is neither on nor off and a name its table lacks (the numbers were checked by
  /// their validators).
  void apply(engine::SimOptions* o) const {
    for (const Flag& f : flags_) {
      if (f.option->count() == 0) continue;
      const engine::OptionSpec& s = *f.spec;
      switch (s.kind) {
        case engine::OptionKind::Number:
        case engine::OptionKind::Integer: s.set(*o, std::strtod(f.text.c_str(), nullptr)); break;
        case engine::OptionKind::Bool:
          if (s.flag_switch) s.set(*o, true);
          else if (f.text == "on" || f.text == "off") s.set(*o, f.text == "on");
          else throw std::invalid_argument(s.flag + ": expected on or off, got '" + f.text + "'");
          break;
        case engine::OptionKind::Name:
          if (const std::string e = s.error(f.text); !e.empty()) throw std::invalid_argument(s.flag + ": " + e);
          s.set(*o, f.text);
          break;
        case engine::OptionKind::Vector: throw std::logic_error(s.flag + ": no flag for a vector option");
      }
    }
  }

 private:
  struct Flag {
    const engine::OptionSpec* spec;
    std::string text;  ///< the value as given
    CLI::Option* option;
  };
  std::deque<Flag> flags_;  // CLI11 holds a reference to each text: a deque never moves them

  // "<names | on | off: ><doc> (<unit>; default: the scene's options.<key>, else <default>)"
  static std::string help(const engine::OptionSpec& s) {
    std::string lead, def = engine::value_text(s.default_value(), s.kind);
    if (s.kind == engine::OptionKind::Bool) {
      lead = "on | off: ";
      def = def == "true" ? "on" : "off";
    } else if (s.kind == engine::OptionKind::Name) {
      for (const std::string& n : s.names) lead += (lead.empty() ? "" : " | ") + n;
      lead += ": ";
      def = def.substr(1, def.size() - 2);  // without its quotes
    }
    return lead + s.doc + " (" + (s.unit.empty() ? "" : s.unit + "; ") + "default: the scene's options." + s.key +
           ", else " + def + ")";
  }
};

}  // namespace magsim::tools
