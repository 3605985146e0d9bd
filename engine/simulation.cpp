// engine/simulation.cpp — construction, state access, save/restore and frames of the
// Simulation facade. The step itself is in step.cpp.
#include "engine/simulation.hpp"

#include "engine/sleep.hpp"

#include "engine/ode_bridge.hpp"
#include "engine/stages.hpp"

#include <omp.h>

#include <algorithm>
#include <stdexcept>

namespace magsim::engine {

namespace {

/// Below this many moments a magnetics sweep is too short to share: OpenMP's fork/join
/// costs more than it saves, and on a busy machine a descheduled thread stalls each of
/// the ~2 parallel regions per iteration by a scheduler slice (measured: 2 moments, 999
/// iterations, 48 ms per step with 2 threads on a loaded 2-core box, 1.5 ms with 1).
constexpr int kParallelMoments = 256;

/// OpenMP's thread count before any Simulation changed it (OMP_NUM_THREADS or all cores).
int default_omp_threads() {
  static const int n = omp_get_max_threads();
  return n;
}

}  // namespace

Simulation::Simulation(const SceneDesc& scene)
    : model_(std::make_unique<const Model>(compile_model(scene))) {
  const Model& m = *model_;
  const int all_threads = default_omp_threads();  // the count at the first Simulation
  state_ = initial_state(m);
  moments_ = make_moment_desc(m);
  place_moments(m, state_, &moments_, nullptr);
  ws_.F.assign(m.nmoment, Vec3::Zero());
  ws_.tau.assign(m.nmoment, Vec3::Zero());
  ws_.body_force.assign(m.nbody, Vec3::Zero());
  ws_.body_torque.assign(m.nbody, Vec3::Zero());
  ws_.body_force_awake.assign(m.nbody, Vec3::Zero());
  ws_.next = state_;
  ode_ = std::make_unique<OdeBridge>(m);
  energy_ = start_energy_audit(m, state_);
  // SimOptions::threads > 0: exactly that many; 0: all, except for small systems (one)
  omp_threads_ = m.options.threads > 0 ? m.options.threads
                 : m.nmoment < kParallelMoments ? 1
                                                : all_threads;
  chosen_threads_ = omp_threads_;
}

void Simulation::limit_default_threads(int n) {
  if (model_->options.threads > 0) return;  // the user's count
  omp_threads_ = std::max(1, std::min(n, chosen_threads_));
}

Simulation::~Simulation() = default;

void Simulation::run(long n) {
  for (long k = 0; k < n; ++k) step();
}

double Simulation::time() const { return static_cast<double>(state_.step) * model_->options.dt; }
long Simulation::steps() const { return state_.step; }

Metrics Simulation::metrics() const { return compute_metrics(*model_, state_, profile_); }

std::uint64_t Simulation::state_hash() const { return engine::state_hash(state_); }

void Simulation::restore_state(const State& s) {
  check_state_shape(*model_, s);
  try {
    check_bodies(*model_, s, s.step);
  } catch (const SimulationError& e) {
    throw std::invalid_argument(std::string("restore_state: ") + e.what());
  }
  state_ = s;
  prepare_sleep(*model_, &state_);  // a state saved without the sleep arrays starts awake
  ws_.next = state_;
  // forget the wake-up reference of auto-disable: it is re-learnt on the next step
  std::fill(ws_.body_force_awake.begin(), ws_.body_force_awake.end(), Vec3::Zero());
  rollback();
  profile_ = StepProfile{};
  energy_ = start_energy_audit(*model_, state_);
}

void Simulation::wake_all() {
  engine::wake_all(*model_, &state_);
  rollback();
}

void Simulation::rollback() {
  // ODE is rewritten from state_ at the start of every step; drop any half-made contacts,
  // or, when ODE itself failed, start over with a fresh world (ODE is a function of State)
  if (ode_->broken()) {
    ode_.reset();
    ode_ = std::make_unique<OdeBridge>(*model_);
  } else {
    ode_->discard_contacts();
  }
  ode_->write_state(state_);
  ws_.forces_ready = false;  // the next step evaluates them from state_'s magnetization
  // the next attempt takes state_'s magnetization and eddy memory afresh (attempt, step.cpp)
  place_moments(*model_, state_, &moments_, nullptr);
}

render::Frame Simulation::frame(const FrameOptions& opt) const {
  return build_frame(*model_, state_, opt);
}

int Simulation::body_count() const { return model_->nbody; }

int Simulation::find_body(const std::string& name) const {
  for (int i = 0; i < model_->nbody; ++i)
    if (model_->body_name[i] == name) return i;
  return -1;
}

void Simulation::check_body_index(int i) const {
  if (i < 0 || i >= model_->nbody)
    throw std::out_of_range("body index " + std::to_string(i) + " out of range [0, " +
                            std::to_string(model_->nbody) + ")");
}

Vec3 Simulation::body_position(int i) const {
  check_body_index(i);
  return state_.pos[i];
}
Quat Simulation::body_orientation(int i) const {
  check_body_index(i);
  return state_.quat[i];
}
Vec3 Simulation::body_velocity(int i) const {
  check_body_index(i);
  return state_.vel[i];
}
Vec3 Simulation::body_angular_velocity(int i) const {
  check_body_index(i);
  return state_.angvel[i];
}
Vec3 Simulation::body_origin(int i) const {
  check_body_index(i);
  return state_.pos[i] - state_.quat[i] * model_->body_com[i];
}

void Simulation::inject_velocity_for_testing(int body, const Vec3& v) {
  check_body_index(body);
  inject_body_ = body;
  inject_velocity_ = v;
}

}  // namespace magsim::engine
