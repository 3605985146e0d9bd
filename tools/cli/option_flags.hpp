// tools/cli/option_flags.hpp — the option flags of magsim-scene, magsolve and bench: one per entry
// of the table of run options that names a flag (engine/options_table.hpp), with the entry's
// spelling, range and a help made of its doc, unit, the key it overrides and its default, applied
// to a SimOptions when given. A program takes every flagged entry or a list of them, and may keep
// an older spelling of its own working beside the table's (its --help names it). A number takes
// its range (OptionCheck, as the scene file does); a bool takes on | off, or nothing when it is a
// switch; a name one of its table's names.
#pragma once

#include "engine/options_table.hpp"
#include "tools/cli/cli_common.hpp"

#include <CLI/CLI.hpp>

#include <cstdlib>
#include <deque>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace magsim::tools {

class OptionFlags {
 public:
  /// How a program offers the table's flags.
  struct Offer {
    /// the table keys whose flags to add, in this order; empty = every entry with a flag
    std::vector<std::string> keys;
    /// key -> older spellings of its flag that still work ("--mu-r"), named in --help
    std::map<std::string, std::vector<std::string>> older;
    /// the options a flag not given leaves in force, for --help's default (a program whose
    /// starting point is not the table's defaults says so here)
    engine::SimOptions defaults;
    /// where an option not given comes from, before its key in --help: "the scene's options."
    std::string source = "the scene's options.";
  };

  /// Adds the flag of every table entry that has one to app, in `group` (magsim-scene).
  void add(CLI::App* app, const std::string& group) { add(app, group, Offer{}); }
  /// Adds the flags of `offer` to app, in `group`.
  void add(CLI::App* app, const std::string& group, const Offer& offer) {
    std::vector<const engine::OptionSpec*> specs;
    if (offer.keys.empty()) {
      for (const engine::OptionSpec& s : engine::options_table())
        if (!s.flag.empty()) specs.push_back(&s);
    } else {
      for (const std::string& k : offer.keys) {
        const engine::OptionSpec& s = engine::option_spec(k);
        if (s.flag.empty()) throw std::logic_error("OptionFlags: option '" + k + "' has no flag in the table");
        specs.push_back(&s);
      }
    }
    for (const engine::OptionSpec* sp : specs) {
      const engine::OptionSpec& s = *sp;
      std::string names = s.flag, note;
      if (const auto it = offer.older.find(s.key); it != offer.older.end())
        for (const std::string& o : it->second) {
          names += "," + o;
          note += (note.empty() ? " (also " : ", ") + o;
        }
      if (!note.empty()) note += ": the older spelling)";
      Flag& f = flags_.emplace_back(Flag{&s, {}, nullptr});
      if (s.flag_switch) {
        f.option = app->add_flag(names)->description(s.doc + note);
      } else {
        f.option = app->add_option(names, f.text, help(s, offer) + note);
        if (s.kind == engine::OptionKind::Number || s.kind == engine::OptionKind::Integer)
          f.option->check(OptionCheck(s.range))->type_name(s.kind == engine::OptionKind::Integer ? "INT" : "FLOAT");
      }
      f.option->group(group);
    }
  }

  /// Whether the flag of `key` was given.
  bool given(const std::string& key) const {
    const Flag* f = find(key);
    return f && f->option->count() > 0;
  }
  /// The text given to the flag of `key` ("" when not given).
  const std::string& text(const std::string& key) const {
    static const std::string none;
    const Flag* f = find(key);
    return f ? f->text : none;
  }

  /// Sets each option whose flag was given (OptionSpec::assign). Throws
  /// std::invalid_argument "<flag>: <why>" for a bool that is neither on nor off and a name
  /// its table lacks (the numbers were checked by their validators already).
  void apply(engine::SimOptions* o) const {
    for (const Flag& f : flags_) {
      if (f.option->count() == 0) continue;
      const engine::OptionSpec& s = *f.spec;
      if (s.kind == engine::OptionKind::Vector) throw std::logic_error(s.flag + ": no flag for a vector option");
      if (s.kind == engine::OptionKind::Bool && s.flag_switch) {
        s.set(*o, true);
        continue;
      }
      if (const std::string e = s.assign(*o, f.text); !e.empty()) throw std::invalid_argument(s.flag + ": " + e);
    }
  }
  /// apply() to the magnetics alone (magsolve's options are a mag::DynamicsOptions).
  void apply(mag::DynamicsOptions* d) const {
    engine::SimOptions o;
    o.magnetics = *d;
    apply(&o);
    *d = o.magnetics;
  }

 private:
  struct Flag {
    const engine::OptionSpec* spec;
    std::string text;  ///< the value as given
    CLI::Option* option;
  };
  std::deque<Flag> flags_;  // CLI11 holds a reference to each text: a deque never moves them

  const Flag* find(const std::string& key) const {
    for (const Flag& f : flags_)
      if (f.spec->key == key) return &f;
    return nullptr;
  }

  // "<names | on | off: ><doc> (<unit>; default: <source><key>, else <default>)"
  static std::string help(const engine::OptionSpec& s, const Offer& offer) {
    std::string lead, def = engine::value_text(s.get(offer.defaults), s.kind);
    if (s.kind == engine::OptionKind::Bool) {
      lead = "on | off: ";
      def = def == "true" ? "on" : "off";
    } else if (s.kind == engine::OptionKind::Name) {
      for (const std::string& n : s.names) lead += (lead.empty() ? "" : " | ") + n;
      lead += ": ";
      def = def.substr(1, def.size() - 2);  // without its quotes
    }
    return lead + s.doc + " (" + (s.unit.empty() ? "" : s.unit + "; ") + "default: " + offer.source + s.key +
           ", else " + def + ")";
  }
};

}  // namespace magsim::tools
