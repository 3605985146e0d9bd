// scenes/options_json.cpp — SimOptions <-> JSON through the table of options
// (engine/options_table.hpp). The reader refuses unknown keys first (naming the keys it
// takes), then reads each option present by its kind, checked against its range, naming the
// JSON path of the first bad one; the writer writes every option, so the two are each other's
// inverse (tests/engine/options_table_test.cpp).
#include "scenes/options_json.hpp"

#include "engine/options_table.hpp"

#include <algorithm>
#include <utility>
#include <vector>

namespace magsim::scenes {

using engine::OptionKind;
using engine::OptionSpec;
using engine::OptionValue;
using engine::SimOptions;
using engine::Vec3;
using json = nlohmann::json;

namespace {

std::vector<std::string> split(const std::string& path) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t dot; (dot = path.find('.', start)) != std::string::npos; start = dot + 1)
    parts.push_back(path.substr(start, dot - start));
  parts.push_back(path.substr(start));
  return parts;
}

// `key` relative to the object at `scope` ("" = the options object itself): "field.bh_theta"
// for "magnetics.field.bh_theta" in "magnetics"; "" when the key is empty or lies outside it.
std::string relative(const std::string& key, const std::string& scope) {
  if (key.empty() || scope.empty()) return key;
  return key.compare(0, scope.size() + 1, scope + ".") == 0 ? key.substr(scope.size() + 1) : std::string();
}

json value_json(const OptionSpec& s, const OptionValue& v) {
  switch (s.kind) {
    case OptionKind::Number: return std::get<double>(v);
    case OptionKind::Integer: return static_cast<long long>(std::get<double>(v));
    case OptionKind::Bool: return std::get<bool>(v);
    case OptionKind::Name: return std::get<std::string>(v);
    case OptionKind::Vector: return vec3_json(std::get<Vec3>(v));
  }
  return nullptr;
}

// The JSON kind first ("must be a number"), then the option's own check (range, names, length).
OptionValue read_value(const JsonReader& r, const OptionSpec& s, const json& v, const std::string& p) {
  OptionValue x;
  switch (s.kind) {
    case OptionKind::Number:
    case OptionKind::Integer: return r.option(v, p, s.range);
    case OptionKind::Bool: x = r.boolean(v, p); break;
    case OptionKind::Name: x = r.string(v, p); break;
    case OptionKind::Vector: x = r.vec3(v, p); break;
  }
  if (const std::string e = s.error(x); !e.empty()) r.fail(p, e);
  return x;
}

// The value at the relative path `rel` of j, nullptr when absent. The objects on the way were
// checked by check_keys.
const json* find(const json& j, const std::string& rel) {
  const json* at = &j;
  for (const std::string& part : split(rel)) {
    const auto it = at->find(part);
    if (it == at->end()) return nullptr;
    at = &*it;
  }
  return at;
}

// The keys of the options in scope, relative to it: each option's key and its older one.
struct ScopeKeys {
  std::vector<std::string> keys, old_keys;
};

// `obj` (at JSON path `path`, relative path `prefix`) holds only options and the objects on
// the way to them ("magnetics", "field"), and "comment"; else the unknown key is named with
// the keys its object takes.
void check_keys(const JsonReader& r, const json& obj, const std::string& path, const std::string& prefix,
                const ScopeKeys& scope) {
  r.object(obj, path);
  const std::string head = prefix.empty() ? "" : prefix + ".";
  // the names one level below prefix; objects are those with a deeper key under them
  auto children = [&](const std::vector<std::string>& keys, std::vector<std::string>* names,
                      std::vector<std::string>* objects) {
    for (const std::string& k : keys) {
      if (k.compare(0, head.size(), head) != 0) continue;
      const std::string rest = k.substr(head.size());
      const std::size_t dot = rest.find('.');
      const std::string name = rest.substr(0, dot);
      bool seen = false;
      for (const std::string& n : *names) seen = seen || n == name;
      if (!seen) names->push_back(name);
      if (dot != std::string::npos) objects->push_back(name);
    }
  };
  std::vector<std::string> names, old_names, objects;
  children(scope.keys, &names, &objects);
  children(scope.old_keys, &old_names, &objects);
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const std::string& k = it.key();
    if (k == "comment") continue;
    bool known = false, object = false;
    for (const std::string& n : names) known = known || n == k;
    for (const std::string& n : old_names) known = known || n == k;
    for (const std::string& n : objects) object = object || n == k;
    if (!known) {
      std::string list, old_list;
      for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
      for (const std::string& n : old_names)
        if (std::find(names.begin(), names.end(), n) == names.end()) old_list += (old_list.empty() ? "" : ", ") + n;
      r.fail(JsonReader::join(path, k),
             "unknown key (allowed: " + list + (old_list.empty() ? "" : "; older spellings: " + old_list) + ")");
    }
    if (object) check_keys(r, it.value(), JsonReader::join(path, k), head + k, scope);
  }
}

// Reads the options under `scope` ("" = all of them, "magnetics" = options.magnetics) from the
// object j at JSON path `path` into *o.
void read_options(const JsonReader& r, const json& j, const std::string& path, const std::string& scope,
                  SimOptions* o) {
  ScopeKeys keys;
  for (const OptionSpec& s : engine::options_table()) {
    if (const std::string k = relative(s.key, scope); !k.empty()) keys.keys.push_back(k);
    if (const std::string k = relative(s.old_key, scope); !k.empty()) keys.old_keys.push_back(k);
  }
  check_keys(r, j, path, "", keys);
  for (const OptionSpec& s : engine::options_table()) {
    const std::string key = relative(s.key, scope), old_key = relative(s.old_key, scope);
    if (key.empty()) continue;
    const json* now = find(j, key);
    const json* before = old_key.empty() ? nullptr : find(j, old_key);
    // one value per option: with both spellings, which one counts would be a guess
    if (now && before)
      r.fail(JsonReader::join(path, key),
             "given twice: also as " + JsonReader::join(path, old_key) + ", its older spelling; keep one");
    if (now) s.set(*o, read_value(r, s, *now, JsonReader::join(path, key)));
    if (before) s.set(*o, read_value(r, s, *before, JsonReader::join(path, old_key)));
  }
}

}  // namespace

json to_json(const SimOptions& o) {
  json j = json::object();
  for (const OptionSpec& s : engine::options_table()) {
    json* at = &j;
    for (const std::string& part : split(s.key)) at = &(*at)[part];
    *at = value_json(s, s.get(o));
  }
  return j;
}

void from_json(const JsonReader& r, const json& j, const std::string& path, SimOptions* o) {
  read_options(r, j, path, "", o);
}

void from_json(const JsonReader& r, const json& j, const std::string& path, mag::DynamicsOptions* d) {
  SimOptions o;
  o.magnetics = *d;
  read_options(r, j, path, "magnetics", &o);
  *d = o.magnetics;
}

}  // namespace magsim::scenes

namespace magsim::scenes {

json table_json() {
  static const char* const kKinds[] = {"number", "integer", "bool", "name", "vector"};
  json rows = json::array();
  for (const OptionSpec& s : engine::options_table()) {
    json r{{"key", s.key},
           {"old_key", s.old_key.empty() ? json(nullptr) : json(s.old_key)},
           {"kind", kKinds[static_cast<int>(s.kind)]},
           {"unit", s.unit},
           {"default", value_json(s, s.default_value())},
           {"default_text", engine::value_text(s.default_value(), s.kind)},
           {"values", s.values_text()},
           {"flag", s.flag.empty() ? json(nullptr) : json(s.flag)},
           {"flag_switch", s.flag_switch},
           {"doc", s.doc}};
    if (s.kind == OptionKind::Number || s.kind == OptionKind::Integer || s.kind == OptionKind::Vector)
      r["range"] = {{"integer", s.range.integer}, {"lo", s.range.lo}, {"hi", s.range.hi},
                    {"lo_open", s.range.lo_open}, {"hi_open", s.range.hi_open}};
    if (s.kind == OptionKind::Name) r["names"] = s.names;
    rows.push_back(std::move(r));
  }
  return rows;
}

}  // namespace magsim::scenes
