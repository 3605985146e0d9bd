// tests/engine/options_table_test.cpp — the table of run options (engine/options_table.hpp):
// each entry reaches its own member and no other, round-trips through the scene file's JSON
// under its key and under its older one, is checked by compile_model in the range the scene
// file takes (which lies within mag::validate's), its default is the structs' in-class one, and
// scenes/SCENE_FILE.md lists exactly the table's options with their keys, defaults and values.
#include "engine/model.hpp"
#include "engine/options_table.hpp"
#include "scenes/options_json.hpp"
#include "tests/engine/option_probes.hpp"

#include <catch2/catch.hpp>

#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

using namespace magsim;
using engine::OptionKind;
using engine::OptionSpec;
using engine::SimOptions;
using json = nlohmann::json;

namespace {

json value_json(const OptionSpec& s, const engine::OptionValue& v) {
  SimOptions o;
  s.set(o, v);
  json at = scenes::to_json(o);
  for (std::size_t start = 0, dot = 0; dot != std::string::npos; start = dot + 1) {
    dot = s.key.find('.', start);
    at = json(at.at(s.key.substr(start, dot - start)));
  }
  return at;
}

// {"a": {"b": value}} for the path "a.b"
json nested(const std::string& path, const json& value) {
  const std::size_t dot = path.find('.');
  if (dot == std::string::npos) return json{{path, value}};
  return json{{path.substr(0, dot), nested(path.substr(dot + 1), value)}};
}

SimOptions read(const json& j) {
  SimOptions o;
  scenes::from_json(scenes::JsonReader("test"), j, "options", &o);
  return o;
}

// The cells of a Markdown table row, trimmed, backticks dropped ("\|" is a cell's own '|').
std::vector<std::string> cells(const std::string& row) {
  std::vector<std::string> out;
  std::string cell;
  for (std::size_t i = 1; i < row.size(); ++i) {
    if (row[i] == '\\' && i + 1 < row.size() && row[i + 1] == '|') {
      cell += '|';
      ++i;
    } else if (row[i] == '|') {
      const std::size_t a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
      out.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
      cell.clear();
    } else if (row[i] != '`') {
      cell += row[i];
    }
  }
  return out;
}

// The rows below the Markdown table whose header line is `header`.
std::vector<std::vector<std::string>> table_rows(const std::string& text, const std::string& header) {
  std::istringstream in(text);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!inside) {
      inside = line == header;
      if (inside) std::getline(in, line);  // |---|---|
      continue;
    }
    if (line.empty() || line[0] != '|') break;
    rows.push_back(cells(line));
  }
  return rows;
}

}  // namespace

// The one default of each option is the table's; the structs' in-class initialisers must equal
// it, both in a SimOptions and in each struct constructed on its own (so that no owner overrides
// a member's initialiser, and a library caller that builds a mag::DynamicsOptions gets the same).
TEST_CASE("options table: default-constructed structs hold the table's default of every option", "[options_table]") {
  const SimOptions whole;
  SimOptions parts;
  parts.magnetics = mag::DynamicsOptions{};
  parts.magnetics.field = mag::FieldOptions{};
  parts.magnetics.field.near_field = mag::NearFieldOptions{};
  std::size_t checked = 0;
  for (const OptionSpec& s : engine::options_table()) {
    INFO("options." << s.key << ": table default " << engine::value_text(s.default_value(), s.kind)
                    << ", struct " << engine::value_text(s.get(whole), s.kind) << ", on its own "
                    << engine::value_text(s.get(parts), s.kind));
    CHECK(s.get(whole) == s.default_value());
    CHECK(s.get(parts) == s.default_value());
    ++checked;
  }
  CHECK(checked == engine::options_table().size());
}

TEST_CASE("options table: every entry reaches its own member and no other", "[options_table]") {
  const SimOptions defaults;
  std::set<std::string> keys;
  for (const OptionSpec& s : engine::options_table()) {
    INFO("options." << s.key);
    CHECK(keys.insert(s.key).second);
    CHECK(!s.doc.empty());
    CHECK(s.error(s.default_value()).empty());  // the default is a value of the option
    SimOptions o;
    s.set(o, test::probe(s));
    CHECK(s.error(test::probe(s)).empty());
    CHECK(s.get(o) == test::probe(s));
    for (const OptionSpec& t : engine::options_table())
      if (&t != &s) CHECK(t.get(o) == t.get(defaults));
  }
  CHECK(keys.size() == engine::options_table().size());
}

TEST_CASE("options table: every option survives to_json and from_json, under its key and its older one", "[options_table]") {
  const SimOptions all = test::all_changed();
  test::check_equal(read(scenes::to_json(all)), all);
  test::check_equal(read(json::parse(scenes::to_json(all).dump())), all);  // through text, as in a file
  test::check_equal(read(scenes::to_json(SimOptions{})), SimOptions{});
  for (const OptionSpec& s : engine::options_table()) {
    INFO("options." << s.key << " (older: '" << s.old_key << "')");
    const json v = value_json(s, test::probe(s));
    CHECK(s.get(read(nested(s.key, v))) == test::probe(s));
    if (s.old_key.empty()) continue;
    CHECK(s.get(read(nested(s.old_key, v))) == test::probe(s));
    // both spellings at once: refused, naming both
    json both = nested(s.key, v);
    both.merge_patch(nested(s.old_key, v));
    CHECK_THROWS_WITH(read(both), Catch::Matchers::Contains("options." + s.key + ": given twice: also as options." +
                                                            s.old_key));
  }
}

TEST_CASE("options table: magsolve's \"magnetics\" object reads the magnetics options, old keys too", "[options_table]") {
  const SimOptions all = test::all_changed();
  mag::DynamicsOptions d;
  scenes::from_json(scenes::JsonReader("case.json"), scenes::to_json(all)["magnetics"], "magnetics", &d);
  SimOptions back;
  back.magnetics = d;
  test::check_equal(back, [&] {
    SimOptions o = all;  // all but the magnetics at their defaults
    for (const OptionSpec& s : engine::options_table())
      if (s.key.compare(0, 10, "magnetics.") != 0) s.set(o, s.default_value());
    return o;
  }());
  mag::DynamicsOptions old;
  scenes::from_json(scenes::JsonReader("case.json"), json{{"softening", 0.002}, {"bounded_pairs", true}}, "magnetics", &old);
  CHECK(old.field.softening == 0.002);
  CHECK(old.field.bounded_pairs);
  CHECK_THROWS_WITH(scenes::from_json(scenes::JsonReader("case.json"), json{{"bh_theta", 0.5}}, "magnetics", &old),
                    Catch::Matchers::Contains("case.json: magnetics.bh_theta: unknown key"));
}

TEST_CASE("options table: compile_model refuses each number just outside its range, naming options.<key>", "[options_table]") {
  engine::SceneDesc scene;
  REQUIRE_NOTHROW(engine::compile_model(scene));
  for (const OptionSpec& s : engine::options_table()) {
    if (s.kind != OptionKind::Number && s.kind != OptionKind::Integer) continue;
    const engine::OptionRange& r = s.range;
    std::vector<double> outside;
    if (r.lo != -DBL_MAX) outside.push_back(r.integer ? r.lo - 1 : r.lo_open ? r.lo : std::nextafter(r.lo, -DBL_MAX));
    if (r.hi != DBL_MAX) outside.push_back(r.integer ? r.hi + 1 : r.hi_open ? r.hi : std::nextafter(r.hi, DBL_MAX));
    if (!r.integer) outside.push_back(std::nan(""));
    for (const double x : outside) {
      INFO("options." << s.key << " = " << x);
      engine::SceneDesc bad = scene;
      s.set(bad.options, x);
      CHECK_THROWS_WITH(engine::compile_model(bad), Catch::Matchers::StartsWith("options." + s.key + ": must be"));
    }
  }
}

TEST_CASE("options table: the magnetics' ranges lie within the library's own (mag::validate)", "[options_table]") {
  for (const OptionSpec& s : engine::options_table()) {
    if (s.key.compare(0, 10, "magnetics.") != 0 || (s.kind != OptionKind::Number && s.kind != OptionKind::Integer))
      continue;
    const engine::OptionRange& r = s.range;
    for (const double x : {r.lo_open ? std::nextafter(r.lo, DBL_MAX) : r.lo,
                           r.hi == DBL_MAX ? 1e300 : r.hi_open ? std::nextafter(r.hi, -DBL_MAX) : r.hi}) {
      INFO("options." << s.key << " = " << x);
      SimOptions o;
      s.set(o, x);
      CHECK(mag::validate(o.magnetics) == "");
    }
  }
}

TEST_CASE("options table: scenes/SCENE_FILE.md lists every option, its default and values, and no other", "[options_table]") {
  std::ifstream f(std::string(MAGSIM_SOURCE_DIR) + "/scenes/SCENE_FILE.md");
  REQUIRE(f.good());
  std::stringstream text;
  text << f.rdbuf();
  const auto rows = table_rows(text.str(), "| key | default | values | flag | meaning |");
  std::map<std::string, std::vector<std::string>> listed;
  for (const auto& row : rows) {
    INFO("SCENE_FILE.md row: " << (row.empty() ? "" : row[0]));
    REQUIRE(row.size() == 5);
    CHECK(!row[4].empty());  // its meaning
    CHECK(listed.emplace(row[0], row).second);  // once
  }
  std::map<std::string, std::string> old_keys;
  for (const auto& row : table_rows(text.str(), "| older key | key |")) {
    REQUIRE(row.size() == 2);
    CHECK(old_keys.emplace(row[0], row[1]).second);
  }
  std::size_t n = 0, n_old = 0;
  for (const OptionSpec& s : engine::options_table()) {
    INFO("options." << s.key);
    const auto it = listed.find(s.key);
    REQUIRE(it != listed.end());
    CHECK(it->second[1] == engine::value_text(s.default_value(), s.kind));
    CHECK(it->second[2] == s.values_text());
    CHECK(it->second[3] == s.flag);
    ++n;
    if (!s.old_key.empty()) {
      CHECK(old_keys[s.old_key] == s.key);
      ++n_old;
    }
  }
  CHECK(listed.size() == n);  // no option the table lacks
  CHECK(old_keys.size() == n_old);
}

TEST_CASE("options table: parse reads a command line's word for every kind, and names what it is not", "[options_table]") {
  // the one text-to-value reading that magsim-scene's flags and bench_rest's --variant share
  for (const OptionSpec& s : engine::options_table()) {
    INFO(s.key);
    switch (s.kind) {
      case OptionKind::Number:
      case OptionKind::Integer:
        CHECK(std::get<double>(s.parse("0.25")) == 0.25);
        CHECK(std::get<double>(s.parse("1e-3")) == 1e-3);
        CHECK_THROWS_WITH(s.parse("abc"), "expected a number, got 'abc'");
        CHECK_THROWS_WITH(s.parse("2x"), "expected a number, got '2x'");
        CHECK_THROWS_WITH(s.parse(""), "expected a number, got ''");
        break;
      case OptionKind::Bool:
        CHECK(std::get<bool>(s.parse("on")));
        CHECK(std::get<bool>(s.parse("true")));
        CHECK_FALSE(std::get<bool>(s.parse("off")));
        CHECK_FALSE(std::get<bool>(s.parse("false")));
        CHECK_THROWS_WITH(s.parse("maybe"), "expected on or off, got 'maybe'");
        break;
      case OptionKind::Name:
        CHECK(std::get<std::string>(s.parse(s.names.front())) == s.names.front());
        CHECK_FALSE(s.error(s.parse("no-such-name")).empty());  // error() refuses it
        break;
      case OptionKind::Vector: CHECK_THROWS_AS(s.parse("1"), std::invalid_argument); break;
    }
  }
}
