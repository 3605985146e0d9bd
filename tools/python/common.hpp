// tools/python/common.hpp — what the files of the Python module _magsim share: the scene it
// holds, and the errors it raises (the classes live in magsim/_errors.py so that Python code
// can subclass and document them; the messages are magsim-scene's one-line texts).
#pragma once

#include "engine/safety.hpp"
#include "engine/scene_desc.hpp"

#include <pybind11/pybind11.h>

#include <string>

namespace magsim::python {

namespace py = pybind11;
namespace engine = magsim::engine;

/// A scene as magsim-scene resolves it: the description and where it came from (summary.json's
/// "source" and "params" when it is run by magsim.run).
struct Scene {
  engine::SceneDesc desc;
  std::string source = "registry";  ///< the file it was read from, or "registry"
  std::string origin;               ///< its name in messages: the registry name, the file, from_json's origin
  int count = 0;
  double strength = 1.0;
};

/// magsim.SceneError(ValueError) with `message`, which names the file and the JSON path.
[[noreturn]] void raise_scene_error(const std::string& message);
/// magsim.SimulationError(RuntimeError) with .step, .body (−1: none), .body_name and .quantity.
[[noreturn]] void raise_simulation_error(const std::string& message, long step, int body,
                                         const std::string& body_name, const std::string& quantity);
/// A Python built-in exception (PyExc_ValueError, PyExc_OSError, …) with `message` on one line.
[[noreturn]] void raise_builtin(PyObject* type, const std::string& message);

void bind_scene(py::module_& m);
void bind_simulation(py::module_& m);
void bind_state(py::module_& m);
void bind_outputs(py::module_& m);

}  // namespace magsim::python
