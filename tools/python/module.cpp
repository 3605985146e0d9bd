// tools/python/module.cpp — the extension _magsim behind the package magsim: the errors,
// magsim.run (magsim-scene's run and writers, the library magsim_scene_run) and the renderer.
#include "engine/simulation.hpp"
#include "tools/cli/cli_common.hpp"
#include "tools/cli/magsim_scene/magsim_scene.hpp"
#include "tools/python/common.hpp"
#ifdef MAGSIM_HAVE_RENDER
#include "render/renderer.hpp"
#endif

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <csignal>
#include <cstring>
#include <memory>
#include <optional>

namespace magsim::python {

const engine::Simulation& engine_of(const py::object& sim);  // simulation.cpp

namespace {

py::object error_class(const char* name) { return py::module_::import("magsim._errors").attr(name); }

}  // namespace

void raise_scene_error(const std::string& message) {
  PyErr_SetObject(error_class("SceneError").ptr(), py::str(tools::one_line(message)).ptr());
  throw py::error_already_set();
}

void raise_simulation_error(const std::string& message, long step, int body, const std::string& body_name,
                            const std::string& quantity) {
  const py::object e = error_class("SimulationError")(tools::one_line(message), step, body, body_name, quantity);
  PyErr_SetObject(e.get_type().ptr(), e.ptr());
  throw py::error_already_set();
}

void raise_builtin(PyObject* type, const std::string& message) {
  PyErr_SetString(type, tools::one_line(message).c_str());
  throw py::error_already_set();
}

void bind_outputs(py::module_& m) {
  m.def(
      "_run",
      [](const Scene& scene, const std::string& out, long steps, double seconds, double fps, bool render, int width,
         int height, int samples, bool arrows, const std::string& gltf, const std::string& gltf_channels) {
        scene_tool::RunPlan plan;
        plan.source = scene.source;
        plan.count = scene.count;
        plan.strength = scene.strength;
        plan.steps = steps;
        plan.seconds = seconds;
        plan.out = out;
        plan.fps = fps;
        plan.render = render;
        plan.arrows = arrows;
        plan.width = width;
        plan.height = height;
        plan.samples = samples;
        plan.gltf = gltf;
        plan.gltf_channels = gltf_channels;
        std::string error;
        plan.error = &error;
        // Ctrl-C: the run stops after the step in progress with its outputs whole, and the
        // KeyboardInterrupt (or what a Python signal handler raised) follows
        std::optional<py::error_already_set> pending;
        plan.stop = [&pending]() -> int {
          if (pending) return SIGINT;
          py::gil_scoped_acquire locked;
          if (PyErr_CheckSignals() == 0) return 0;
          pending.emplace();
          return SIGINT;
        };
        int code = 0;
        std::string usage, io;
        {
          py::gil_scoped_release unlocked;
          try {
            code = scene_tool::run_scene(scene.desc, plan);
          } catch (const scene_tool::UsageError& e) {
            usage = e.what();
          } catch (const scene_tool::IoError& e) {
            io = e.what();
          } catch (const std::exception& e) {  // magsim-scene's exit 2 for anything else
            error = e.what();
            code = tools::kRunFailed;
          }
        }
        if (pending) throw *pending;
        if (!usage.empty()) raise_builtin(PyExc_ValueError, usage);
        if (!io.empty()) raise_builtin(PyExc_OSError, io);
        if (code == tools::kIoError) raise_builtin(PyExc_OSError, error);
        if (code == tools::kRunFailed) raise_simulation_error(error, -1, -1, "", "");
        return code;
      },
      py::arg("scene"), py::arg("out"), py::arg("steps"), py::arg("seconds"), py::arg("fps"), py::arg("render"),
      py::arg("width"), py::arg("height"), py::arg("samples"), py::arg("arrows"), py::arg("gltf") = "",
      py::arg("gltf_channels") = "");

#ifdef MAGSIM_HAVE_RENDER
  py::class_<render::Renderer>(m, "Renderer", "The offscreen OSMesa renderer of magsim-scene's frames.")
      .def(py::init([](int w, int h, int samples) {
             if (w < 16 || w > 8192 || h < 16 || h > 8192)
               raise_builtin(PyExc_ValueError, "Renderer: width and height must be in [16, 8192]");
             if (samples < 1 || samples > 4) raise_builtin(PyExc_ValueError, "Renderer: samples must be in [1, 4]");
             return std::make_unique<render::Renderer>(w, h, samples);
           }),
           py::arg("width"), py::arg("height"), py::arg("samples") = 1)
      .def(
          "render",
          [](render::Renderer& r, const py::object& sim, bool arrows) {
            engine::FrameOptions opts;
            opts.magnetization_arrows = arrows;
            opts.arrow_scale = 2.2;  // as magsim-scene draws them
            const engine::Simulation& s = engine_of(sim);
            py::array_t<std::uint8_t> img({static_cast<std::size_t>(r.height()), static_cast<std::size_t>(r.width()),
                                           std::size_t{3}});
            const render::Frame frame = s.frame(opts);  // with the GIL: no step can run meanwhile
            {
              py::gil_scoped_release unlocked;
              r.draw(frame);
            }
            std::memcpy(img.mutable_data(), r.pixels().data(), r.pixels().size());
            return img;
          },
          py::arg("sim"), py::arg("arrows") = false, "The frame of sim's state: an (H, W, 3) uint8 RGB image, top row first.")
      .def_property_readonly("width", &render::Renderer::width)
      .def_property_readonly("height", &render::Renderer::height);
  m.attr("HAVE_RENDER") = true;
#else
  m.attr("HAVE_RENDER") = false;
#endif
}

}  // namespace magsim::python

PYBIND11_MODULE(_magsim, m) {
  m.doc() = "magsim's engine (the package magsim wraps it)";
  magsim::python::bind_scene(m);
  magsim::python::bind_state(m);
  magsim::python::bind_simulation(m);
  magsim::python::bind_outputs(m);
}
