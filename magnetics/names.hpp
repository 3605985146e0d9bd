// magnetics/names.hpp — the names of an enum's values, one table per enum, kept beside the
// enum. The scene file, the command-line flags, summary.json and the help texts all spell a
// value from its table, so a name is written once.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace magsim::mag {

/// One value of an enum and its name.
template <class E>
struct Named {
  E value;
  const char* name;
};

/// Every value of an enum E once, with its name, in the order lists and help texts give them.
template <class E, std::size_t N>
struct NameTable {
  Named<E> entries[N];

  /// The name of `v`; "?" for a value outside the table.
  constexpr const char* name(E v) const {
    for (const Named<E>& e : entries)
      if (e.value == v) return e.name;
    return "?";
  }
  /// The value named `s`; false (and *out left alone) for an unknown name.
  bool parse(const std::string& s, E* out) const {
    for (const Named<E>& e : entries)
      if (s == e.name) {
        *out = e.value;
        return true;
      }
    return false;
  }
  /// Every name, in the table's order.
  std::vector<std::string> names() const {
    std::vector<std::string> v;
    for (const Named<E>& e : entries) v.emplace_back(e.name);
    return v;
  }
  /// The names joined by `sep`: "a, b, c".
  std::string list(const char* sep = ", ") const {
    std::string s;
    for (const Named<E>& e : entries) s += (s.empty() ? "" : sep) + std::string(e.name);
    return s;
  }
  /// "unknown <what> '<s>' (a, b, c)": the message for a name that parse() refuses.
  std::string unknown(const char* what, const std::string& s) const {
    return "unknown " + std::string(what) + " '" + s + "' (" + list() + ")";
  }
};

}  // namespace magsim::mag
