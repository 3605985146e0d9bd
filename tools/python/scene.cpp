// tools/python/scene.cpp — magsim.Scene: a registry scene or a scene file, its JSON as
// --write-scene writes it, and its options in the scene file's spelling, set through the
// table of options (engine/options_table.hpp) with its ranges and messages.
#include "engine/options_table.hpp"
#include "scenes/options_json.hpp"
#include "scenes/registry.hpp"
#include "scenes/scene_file.hpp"
#include "tools/cli/magsim_scene/magsim_scene.hpp"
#include "tools/python/common.hpp"

#include <pybind11/stl.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <unistd.h>

namespace magsim::python {

namespace {

// Sets one option through the scene file's reader (scenes/options_json.hpp), so that a value
// is checked and worded as in a file: "set_option: options.magnetics.tol: must be in (0, 1)
// (got 1.5)". `key` is a dotted path ("magnetics.field.bh_theta") or an older key.
void set_option(engine::SimOptions* o, const std::string& key, const py::handle& value) {
  if (py::isinstance<py::float_>(value) && !std::isfinite(py::cast<double>(value)))
    raise_builtin(PyExc_ValueError, "set_option: options." + key + ": must be a finite number");
  std::string text;
  try {
    text = py::cast<std::string>(py::module_::import("json").attr("dumps")(value, py::arg("allow_nan") = false));
  } catch (const py::error_already_set&) {
    raise_builtin(PyExc_ValueError, "set_option: options." + key + ": not a JSON value: " +
                                        py::cast<std::string>(py::repr(value)));
  }
  nlohmann::json j = nlohmann::json::parse(text);
  // nest it: "magnetics.field.bh_theta" -> {"magnetics": {"field": {"bh_theta": v}}}
  std::vector<std::string> parts(1);
  for (const char c : key) {
    if (c == '.') parts.emplace_back();
    else parts.back() += c;
  }
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) j = nlohmann::json{{*it, j}};
  engine::SimOptions next = *o;
  try {
    scenes::from_json(scenes::JsonReader("set_option"), j, "options", &next);
  } catch (const std::runtime_error& e) {
    raise_builtin(PyExc_ValueError, e.what());
  }
  *o = next;
}

// Parsing releases the GIL; the loader's one-line message becomes SceneError, or OSError when
// the file cannot be read at all (missing, unreadable).
Scene parse(const std::string* path, const std::string& text, const std::string& origin) {
  Scene s;
  std::string error;
  {
    py::gil_scoped_release unlocked;
    try {
      s.desc = path ? scenes::load_scene_file(*path) : scenes::parse_scene_json(text, origin);
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  if (!error.empty()) {
    if (path && ::access(path->c_str(), R_OK) != 0) {
      const int err = errno;
      PyErr_SetObject(PyExc_OSError, py::make_tuple(err, error, *path).ptr());
      throw py::error_already_set();
    }
    raise_scene_error(error);
  }
  if (path) s.source = *path;
  s.origin = origin;
  return s;
}

// The name of every entry of a table (the registry, the options), in the table's order.
template <class Table, class Name>
std::vector<std::string> names_of(const Table& table, Name name) {
  std::vector<std::string> names;
  for (const auto& e : table) names.emplace_back(name(e));
  return names;
}

}  // namespace

void bind_scene(py::module_& m) {
  m.def(
      "scene_names", [] { return names_of(scenes::registry(), [](const scenes::SceneEntry& e) { return e.name; }); },
      "The registry's scenes (magsim-scene --list).");
  m.def(
      "option_keys",
      [] { return names_of(engine::options_table(), [](const engine::OptionSpec& s) { return s.key; }); },
      "Every option's key in the scene file's spelling (\"magnetics.field.bh_theta\"), in the table's order.");
  m.def(
      "options_table",
      [] { return py::module_::import("json").attr("loads")(scenes::table_json().dump()); },
      "The table of options as magsim-scene --options-json prints it: one dict per option (key, kind, unit, "
      "default, values, range or names, flag, doc).");

  py::class_<Scene>(m, "Scene", "A scene: bodies, magnets and options, as a scene file holds them.")
      .def_static(
          "from_registry",
          [](const std::string& name, int count, double strength) {
            const scenes::SceneEntry* e = scenes::find_scene(name);
            if (!e)
              raise_builtin(PyExc_ValueError, "unknown scene '" + name + "'; known: " + scene_tool::registry_names() +
                                                  " (or a FILE.json)");
            if (count < 0 || count > 1000000000)
              raise_builtin(PyExc_ValueError, "--count: must be in [1, 1000000000] (0: the scene's own), got " +
                                                  std::to_string(count));
            if (!(std::isfinite(strength) && strength > 0))
              raise_builtin(PyExc_ValueError, "--strength: must be a positive number, got " + scene_tool::fmt(strength));
            Scene s;
            s.origin = name;
            s.count = count;
            s.strength = strength;
            scenes::SceneParams p;
            p.count = count;
            p.strength = strength;
            std::string error;
            {
              py::gil_scoped_release unlocked;
              try {
                // magsim-scene's refusal of a count that would not fit in memory
                scene_tool::check_registry_memory(*e, p, name + " --count " + std::to_string(count));
                s.desc = e->build(p);
              } catch (const scene_tool::UsageError& x) {
                error = x.what();
              }
            }
            if (!error.empty()) raise_builtin(PyExc_ValueError, error);  // magsim-scene: exit 1
            return s;
          },
          py::arg("name"), py::arg("count") = 0, py::arg("strength") = 1.0,
          "A registry scene (magsim-scene NAME --count --strength; 0 and 1.0 keep its own).")
      .def_static(
          "from_file", [](const std::string& path) { return parse(&path, {}, path); }, py::arg("path"),
          "A scene file (scenes/SCENE_FILE.md). SceneError names the file and the JSON path; OSError when it "
          "cannot be read.")
      .def_static(
          "from_json", [](const std::string& text, const std::string& origin) { return parse(nullptr, text, origin); },
          py::arg("text"), py::arg("origin") = "<json>",
          "A scene file's text; `origin` names it in messages. SceneError names the JSON path.")
      .def("to_json", [](const Scene& s) { return scene_tool::scene_file_text(s.desc); },
           "The scene file that magsim-scene --write-scene writes, byte for byte.")
      .def_property_readonly(
          "options",
          [](const Scene& s) {
            return py::module_::import("json").attr("loads")(scenes::to_json(s.desc.options).dump());
          },
          "Every option, nested as a scene file's \"options\" (a copy: set_option changes them).")
      .def(
          "set_option",
          [](Scene& s, const std::string& key, const py::handle& value) { set_option(&s.desc.options, key, value); },
          py::arg("key"), py::arg("value"),
          "Sets one option by its scene-file key (\"dt\", \"magnetics.method\"; older keys too), with its range: "
          "ValueError in the scene file's words otherwise.")
      .def_property_readonly("name", [](const Scene& s) { return s.desc.name; })
      .def_property_readonly("description", [](const Scene& s) { return s.desc.description; })
      .def_property_readonly("default_seconds", [](const Scene& s) { return s.desc.default_seconds; })
      .def_property_readonly("nbody", [](const Scene& s) { return s.desc.bodies.size(); })
      .def_property_readonly("source", [](const Scene& s) { return s.source; })
      .def("__repr__", [](const Scene& s) {
        return "<magsim.Scene '" + s.desc.name + "', " + std::to_string(s.desc.bodies.size()) + " bodies>";
      });
}

}  // namespace magsim::python
