// tools/python/simulation.cpp — magsim.Simulation: stepping without the GIL, read-only numpy
// views at fixed addresses, forces, fields, energy, metrics and the state.
//
// Views: the engine swaps its state buffers at every commit (engine/step.cpp), so a pointer
// into them moves. The module keeps mirrors instead: arrays it allocated once, refreshed
// after every step and restore (tools/findings/python.md measures the copy), read-only, and
// owned by a capsule so that a view outlives its Simulation.
#include "engine/simulation.hpp"
#include "engine/metrics.hpp"
#include "magnetics/dipole_field.hpp"
#include "tools/cli/cli_common.hpp"
#include "tools/cli/magsim_scene/outputs.hpp"
#include "tools/python/common.hpp"
#include "tools/python/state.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

namespace magsim::python {

namespace {

constexpr double kMu0 = 4e-7 * M_PI;  // vacuum permeability (T·m/A), as magnetics/ uses it

// A read-only (rows, cols) float64 array over memory it owns through a capsule.
struct Mirror {
  double* data = nullptr;
  py::array array;
  Mirror(std::size_t rows, std::size_t cols) {
    auto* block = new std::vector<double>(rows * cols, 0.0);
    data = block->data();
    py::capsule owner(block, [](void* p) { delete static_cast<std::vector<double>*>(p); });
    array = py::array(py::dtype::of<double>(), {rows, cols}, {cols * sizeof(double), sizeof(double)}, data, owner);
    py::detail::array_proxy(array.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  }
};

void copy3(const std::vector<engine::Vec3>& v, double* out) {
  for (const engine::Vec3& x : v) {
    out[0] = x.x();
    out[1] = x.y();
    out[2] = x.z();
    out += 3;
  }
}

py::array_t<double> rows3(const std::vector<engine::Vec3>& v) {
  py::array_t<double> a({v.size(), std::size_t{3}});
  copy3(v, a.mutable_data());
  return a;
}

class Simulation {
 public:
  explicit Simulation(const Scene& scene)
      : pos_(scene.desc.bodies.size(), 3), quat_(scene.desc.bodies.size(), 4), vel_(scene.desc.bodies.size(), 3),
        angvel_(scene.desc.bodies.size(), 3), fingerprint_(scene_fingerprint(scene.desc)) {
    // magsim-scene's checks and words (tools/cli/magsim_scene/main.cpp, run.cpp)
    if (scene.desc.options.threads > tools::max_threads())
      raise_builtin(PyExc_ValueError, scene.origin +
                                          ": options.threads: at most " + std::to_string(tools::max_threads()) +
                                          " (4 x the " + std::to_string(tools::max_threads() / 4) + " cores), got " +
                                          std::to_string(scene.desc.options.threads));
    std::string error;
    {
      py::gil_scoped_release unlocked;
      try {
        sim_ = std::make_unique<engine::Simulation>(scene.desc);
      } catch (const std::invalid_argument& e) {
        error = std::string("scene '") + scene.desc.name + "': " + e.what();
      }
    }
    if (!error.empty()) raise_scene_error(error);
    const std::size_t nm = static_cast<std::size_t>(sim_->model().nmoment);
    M_.emplace(nm, 3);
    mpos_.emplace(nm, 3);
    refresh_views();
  }

  /// n steps with the GIL released for each; signals are checked between steps (Ctrl-C:
  /// KeyboardInterrupt after the step in progress), and a failed step raises SimulationError
  /// with the simulation at its last good state.
  void step(long n) {
    if (n < 0) raise_builtin(PyExc_ValueError, "step: n must be >= 0, got " + std::to_string(n));
    Busy busy(this);
    for (long k = 0; k < n; ++k) {
      std::optional<engine::SimulationError> failed;
      {
        py::gil_scoped_release unlocked;
        try {
          sim_->step();
        } catch (const engine::SimulationError& e) {
          failed = e;
        }
      }
      forces_valid_ = !failed;
      refresh_views();
      if (failed)
        raise_simulation_error(failed->what(), failed->step(), failed->body(), failed->body_name(), failed->quantity());
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }
  /// The steps of `seconds` of simulated time, rounded as magsim-scene's --seconds.
  void run(double seconds) {
    const double dt = sim_->model().options.dt;
    if (!(std::isfinite(seconds) && seconds > 0))
      raise_builtin(PyExc_ValueError, "--seconds: must be a finite number > 0, got " + scene_tool::fmt(seconds));
    if (seconds < dt * (1 - 1e-9))
      raise_builtin(PyExc_ValueError, "--seconds " + scene_tool::fmt(seconds) + " is shorter than one rigid step (dt = " +
                                          scene_tool::fmt(dt) + " s)");
    step(std::max(1L, std::lround(seconds / dt)));
  }

  State get_state() const {
    Busy busy(this);
    return State{sim_->save_state(), fingerprint_};
  }
  void set_state(const State& st) {
    if (st.fingerprint != fingerprint_)
      raise_builtin(PyExc_ValueError, "set_state: the state is of another scene (its bodies differ)");
    Busy busy(this);
    try {
      sim_->restore_state(st.s);
    } catch (const std::invalid_argument& e) {
      raise_builtin(PyExc_ValueError, std::string("set_state: ") + e.what());
    }
    forces_valid_ = false;
    refresh_views();
  }

  /// H = H0 + Σ dipole fields of every moment at each point (A/m): the magnetization of the
  /// current state, the direct sum without softening or the near-field pair term.
  py::array_t<double> field_H(const py::array_t<double, py::array::c_style | py::array::forcecast>& points) const {
    if (points.ndim() != 2 || points.shape(1) != 3) raise_builtin(PyExc_ValueError, "field_H: points must be (n, 3)");
    const std::size_t n = static_cast<std::size_t>(points.shape(0));
    py::array_t<double> out({n, std::size_t{3}});
    const double* p = points.data();
    double* h = out.mutable_data();
    for (std::size_t i = 0; i < 3 * n; ++i)
      if (!std::isfinite(p[i])) raise_builtin(PyExc_ValueError, "field_H: points must be finite");
    Busy busy(this);
    {
      py::gil_scoped_release unlocked;
      const mag::MomentDesc& d = sim_->moments();
      const mag::Magnetization& mz = sim_->state().mag;
      for (std::size_t i = 0; i < n; ++i) {
        const engine::Vec3 x(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
        engine::Vec3 H = d.H0;
        for (std::size_t j = 0; j < d.size(); ++j) H += mag::dipole_field(x - d.position[j], mag::moment(d, mz, j));
        h[3 * i] = H.x();
        h[3 * i + 1] = H.y();
        h[3 * i + 2] = H.z();
      }
    }
    return out;
  }
  py::array_t<double> field_B(const py::array_t<double, py::array::c_style | py::array::forcecast>& points) const {
    py::array_t<double> b = field_H(points);
    double* x = b.mutable_data();
    for (py::ssize_t i = 0; i < b.size(); ++i) x[i] *= kMu0;
    return b;
  }

  py::array_t<double> forces() const {
    Busy busy(this);
    return per_body(sim_->workspace().body_force);
  }
  py::array_t<double> torques() const {
    Busy busy(this);
    return per_body(sim_->workspace().body_torque);
  }
  py::array_t<double> H_at_moments() const {
    Busy busy(this);
    const std::vector<engine::Vec3>& H = sim_->workspace().mag.H;
    if (!forces_valid_ || H.size() != static_cast<std::size_t>(sim_->model().nmoment))
      return rows3(std::vector<engine::Vec3>(sim_->model().nmoment, engine::Vec3::Zero()));
    return rows3(H);
  }

  py::dict metrics() const {
    Busy busy(this);
    const engine::Metrics x = sim_->metrics();
    py::dict d;
    d["time"] = x.time;
    d["steps"] = x.steps;
    d["dynamic_bodies"] = x.dynamic_bodies;
    d["kinetic_energy"] = x.kinetic_energy;
    d["rotational_energy"] = x.rotational_energy;
    d["max_speed"] = x.max_speed;
    d["bounding_radius"] = x.bounding_radius;
    d["magnet_radius"] = x.magnet_radius;
    d["attached"] = x.attached;
    d["held"] = x.held;
    d["escaped"] = x.escaped;
    d["momentum"] = std::vector<double>{x.momentum.x(), x.momentum.y(), x.momentum.z()};
    d["iterations"] = x.iterations;
    d["converged"] = x.converged;
    d["contacts"] = x.contacts;
    return d;
  }
  py::object energy() const {
    Busy busy(this);
    return py::module_::import("json").attr("loads")(scene_tool::energy_json(*sim_).dump());
  }
  std::uint64_t state_hash() const {
    Busy busy(this);
    return sim_->state_hash();
  }
  const engine::Simulation& engine_sim() const { return *sim_; }

  /// Copies the state into the views (the cost tools/findings/python.md quotes).
  void refresh_views() {
    const engine::State& s = sim_->state();
    copy3(s.pos, pos_.data);
    copy3(s.vel, vel_.data);
    copy3(s.angvel, angvel_.data);
    double* q = quat_.data;
    for (const engine::Quat& x : s.quat) {
      q[0] = x.w();
      q[1] = x.x();
      q[2] = x.y();
      q[3] = x.z();
      q += 4;
    }
    copy3(s.mag.M, M_->data);
    copy3(sim_->moments().position, mpos_->data);
  }

  Mirror pos_, quat_, vel_, angvel_;
  std::optional<Mirror> M_, mpos_;

 private:
  // one call at a time into the engine: a second thread gets an error, not a data race
  struct Busy {
    const Simulation* s;
    explicit Busy(const Simulation* sim) : s(sim) {
      if (!s->lock_.try_lock())
        raise_builtin(PyExc_RuntimeError, "Simulation: busy in another thread (one step, run or set_state at a time)");
    }
    ~Busy() { s->lock_.unlock(); }
  };

  py::array_t<double> per_body(const std::vector<engine::Vec3>& v) const {
    if (!forces_valid_ || v.size() != static_cast<std::size_t>(sim_->model().nbody))
      return rows3(std::vector<engine::Vec3>(sim_->model().nbody, engine::Vec3::Zero()));
    return rows3(v);
  }

  std::unique_ptr<engine::Simulation> sim_;
  std::uint64_t fingerprint_;
  bool forces_valid_ = false;
  mutable std::mutex lock_;
};

}  // namespace

const engine::Simulation& engine_of(const py::object& sim) { return sim.cast<const Simulation&>().engine_sim(); }

void bind_simulation(py::module_& m) {
  py::class_<Simulation>(m, "Simulation",
                         "A running scene. Views (positions, ...) are read-only numpy arrays that keep their address "
                         "across steps and restores; forces, fields and metrics are copies.")
      .def(py::init<const Scene&>(), py::arg("scene"))
      .def("step", &Simulation::step, py::arg("n") = 1,
           "n rigid steps (GIL released); SimulationError leaves the last good state; Ctrl-C after a whole step.")
      .def("run", &Simulation::run, py::arg("seconds"), "The steps of `seconds` of simulated time.")
      .def_property_readonly("time", [](const Simulation& s) { return s.engine_sim().time(); })
      .def_property_readonly("steps", [](const Simulation& s) { return s.engine_sim().steps(); })
      .def_property_readonly("nbody", [](const Simulation& s) { return s.engine_sim().model().nbody; })
      .def_property_readonly("nmoment", [](const Simulation& s) { return s.engine_sim().model().nmoment; })
      .def_property_readonly("threads", [](const Simulation& s) { return s.engine_sim().threads(); })
      .def_property_readonly("body_names", [](const Simulation& s) { return s.engine_sim().model().body_name; })
      .def(
          "body_index",
          [](const Simulation& s, const std::string& name) {
            const int i = s.engine_sim().find_body(name);
            if (i < 0) raise_builtin(PyExc_KeyError, name);
            return i;
          },
          py::arg("name"))
      .def_property_readonly("positions", [](const Simulation& s) { return s.pos_.array; },
                             "(nbody, 3) centres of mass (m), a read-only view")
      .def_property_readonly("quaternions", [](const Simulation& s) { return s.quat_.array; },
                             "(nbody, 4) orientations w, x, y, z (body to world), a read-only view")
      .def_property_readonly("velocities", [](const Simulation& s) { return s.vel_.array; },
                             "(nbody, 3) linear velocities (m/s), a read-only view")
      .def_property_readonly("angular_velocities", [](const Simulation& s) { return s.angvel_.array; },
                             "(nbody, 3) angular velocities in the world frame (rad/s), a read-only view")
      .def_property_readonly("M", [](const Simulation& s) { return s.M_->array; },
                             "(nmoment, 3) magnetizations (A/m), a read-only view")
      .def_property_readonly("moment_positions", [](const Simulation& s) { return s.mpos_->array; },
                             "(nmoment, 3) the moments' world positions (m), a read-only view")
      .def("forces", &Simulation::forces, "(nbody, 3) net magnetic force per body of the last step (N); zeros before one")
      .def("torques", &Simulation::torques, "(nbody, 3) net magnetic torque per body about its centre of mass (N m)")
      .def("H", &Simulation::H_at_moments, "(nmoment, 3) the field at each moment of the last step's evaluation (A/m)")
      .def("field_H", &Simulation::field_H, py::arg("points"),
           "H (A/m) at (n, 3) points: H0 and every moment's dipole field (no softening, no near-field term)")
      .def("field_B", &Simulation::field_B, py::arg("points"), "B = mu0 H (T) at (n, 3) points outside the material")
      .def("energy", &Simulation::energy, "The energy audit, as summary.json's \"energy\"")
      .def("metrics", &Simulation::metrics, "Kinetic energy, attached, held, escaped, ... (engine/metrics.hpp)")
      .def("state_hash", &Simulation::state_hash, "magsim-scene's state_hash, as an int")
      .def("get_state", &Simulation::get_state, "A copy of the whole state (picklable)")
      .def("set_state", &Simulation::set_state, py::arg("state"),
           "Restores a state of this scene; ValueError for another scene's or a non-finite one")
      .def("_refresh_views", &Simulation::refresh_views, "the copy into the views alone (to time it)");
}

}  // namespace magsim::python
