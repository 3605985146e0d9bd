// tools/magsim_scene.cpp — runs one scene (from the registry or a JSON file) with one
// method and writes what happened: summary.json (options, timings T_i/T_f/T_r, iteration
// statistics, final metrics — attached, held, escaped beyond escape_radius, … —, the
// energy audit, per-frame series, state hash, error), states.csv (body poses per frame) and
// moments.csv (magnetizations per frame).
//
//   magsim-scene balls_up --method kim2018 --seconds 2
//   magsim-scene scenes/examples/two_balls.json --steps 500 --out out/two
//
// Exit codes (the same in magsolve): 0 done, 1 bad usage, flags or scene, 2 the simulation
// failed (SimulationError; summary.json holds the error and the last good state), 3 I/O
// error (an output file could not be written).
#include "engine/cpu_share.hpp"
#include "engine/simulation.hpp"
#ifdef MAGSIM_HAVE_RENDER
#include "render/frame_writer.hpp"
#include "render/renderer.hpp"
#endif
#include "scenes/registry.hpp"
#include "scenes/scene_file.hpp"
#include "tools/field_flags.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
namespace engine = magsim::engine;
namespace mag = magsim::mag;
namespace scenes = magsim::scenes;
using nlohmann::json;

namespace {

enum Exit { kOk = 0, kBadInput = 1, kRunFailed = 2, kIoError = 3 };

// Runs above this many rigid steps are refused up front: the per-step timings alone take
// 56 bytes a step (560 MB here), and at ~1 ms a step it is hours of wall time; a typo such
// as --seconds 1e8 or "dt": 1e-12 would otherwise end in bad_alloc.
constexpr double kMaxSteps = 1e7;

// --threads above 4x the cores only slows the run down, and 1e5 makes libgomp crash
int max_threads() {
  const unsigned cores = std::thread::hardware_concurrency();
  return 4 * static_cast<int>(cores > 0 ? cores : 1);
}

std::string fmt(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", x);
  return b;
}

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// an output file could not be written (exit 3)
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string errno_text() { return errno ? std::strerror(errno) : "write error"; }

// The names this program writes into --out; a run deletes its own old outputs first (so a
// shorter rerun leaves no stale frame_*.png for make_video.sh) and never anything else.
const char* const kOutputNames[] = {"summary.json", "summary.json.tmp", "states.csv", "moments.csv"};
bool is_output_name(const std::string& f) {
  for (const char* n : kOutputNames)
    if (f == n) return true;
  // frame_%06d.png (six or more digits)
  const std::size_t digits = f.size() >= 10 ? f.size() - 10 : 0;
  if (f.size() < 16 || f.compare(0, 6, "frame_") != 0 || f.compare(f.size() - 4, 4, ".png") != 0) return false;
  for (std::size_t i = 6; i < 6 + digits; ++i)
    if (f[i] < '0' || f[i] > '9') return false;
  return true;
}

// RFC 4180: a field with a comma, quote or line break is quoted, quotes doubled; other
// fields are written as they are (so ordinary output does not change)
std::string csv_field(const std::string& v) {
  if (v.find_first_of(",\"\r\n") == std::string::npos) return v;
  std::string q = "\"";
  for (char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

struct Args {
  std::string scene;
  std::string method;
  double seconds = 0.0;
  long steps = 0;
  std::string out;
  double fps = 60.0;
  bool no_render = false;
  bool arrows = false;
  int width = 1280, height = 720, samples = 1;
  int threads = 0;
  int count = 0;
  double strength = 0.0;
  double dt_m = 0.0;
  double tol = 0.0;
  int max_iter = 0;
  int quickstep_iterations = 0;
  std::string space;
  bool auto_disable = false;
  std::string force_model;
  int max_substeps = 0;
  double substep_reach = 0.0;
  double rolling_friction = 0.0;
  double quickstep_w = 0.0;
  double dt = 0.0;
  std::string bounded_pairs;
  magsim::tools::FieldFlags field;
  bool list = false;
};

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string registry_names() {
  std::string names;
  for (const scenes::SceneEntry& e : scenes::registry()) names += (names.empty() ? "" : ", ") + std::string(e.name);
  return names;
}

// The scene named on the command line, with the command line's overrides applied.
engine::SceneDesc resolve_scene(const Args& a, const CLI::App& app) {
  engine::SceneDesc s;
  if (ends_with(a.scene, ".json")) {
    if (app.count("--count")) throw UsageError("--count applies to registry scenes only, not to " + a.scene);
    try {
      s = scenes::load_scene_file(a.scene);
    } catch (const std::runtime_error& e) {
      throw UsageError(e.what());
    }
    if (app.count("--strength"))
      for (engine::BodyDesc& b : s.bodies)
        for (engine::MomentDesc& m : b.moments)
          if (m.permanent) m.moment *= a.strength;
  } else {
    const scenes::SceneEntry* e = scenes::find_scene(a.scene);
    if (!e) throw UsageError("unknown scene '" + a.scene + "'; known: " + registry_names() + " (or a FILE.json)");
    scenes::SceneParams p;
    if (app.count("--count")) p.count = a.count;
    if (app.count("--strength")) p.strength = a.strength;
    s = e->build(p);
  }
  if (app.count("--method") && !mag::parse_method(a.method, &s.options.method))
    throw UsageError("unknown method '" + a.method + "'");
  if (app.count("--threads")) {
    if (a.threads > max_threads())
      throw UsageError("--threads: at most " + std::to_string(max_threads()) + " (4 x the " +
                       std::to_string(max_threads() / 4) + " cores), got " + std::to_string(a.threads));
    s.options.threads = a.threads;
  }
  if (app.count("--dt-m")) s.options.magnetics.dt = a.dt_m;
  if (app.count("--tol")) s.options.magnetics.tol = a.tol;
  if (app.count("--max-iter")) s.options.magnetics.max_iter = a.max_iter;
  if (app.count("--quickstep-iterations")) s.options.quickstep_iterations = a.quickstep_iterations;
  if (app.count("--auto-disable")) s.options.auto_disable = true;
  if (app.count("--force-model") && !engine::parse_force_choice(a.force_model, &s.options.force_model))
    throw UsageError("--force-model: unknown force model '" + a.force_model + "' (method, zeeman or classic)");
  if (app.count("--max-substeps")) s.options.max_substeps = a.max_substeps;
  if (app.count("--substep-reach")) s.options.substep_reach = a.substep_reach;
  if (app.count("--rolling-friction")) s.options.rolling_friction = a.rolling_friction;
  if (app.count("--quickstep-w")) s.options.quickstep_w = a.quickstep_w;
  if (app.count("--dt")) s.options.dt = a.dt;
  if (app.count("--bounded-pairs")) {
    if (a.bounded_pairs != "on" && a.bounded_pairs != "off")
      throw UsageError("--bounded-pairs: expected on or off, got '" + a.bounded_pairs + "'");
    s.options.magnetics.field.bounded_pairs = a.bounded_pairs == "on";
  }
  if (app.count("--space")) {
    if (!engine::parse_space(a.space, &s.options.space))
      throw UsageError("--space: unknown broad phase '" + a.space + "' (hash, sap or simple)");
  }
  mag::FieldOptions& f = s.options.magnetics.field;
  try {
    a.field.apply(&f);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (const std::string e = mag::validate(f); !e.empty()) throw UsageError("field options: " + e);
  s.options.magnetics.method = s.options.method;
  return s;
}

// Creates DIR (and parents), checks that files can be written into it and deletes the
// outputs of an earlier run there (only this program's own names, see is_output_name).
// Any failure here is an I/O error (exit 3).
void prepare_out_dir(const std::string& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw IoError("--out " + dir + ": exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec) throw IoError("--out " + dir + ": cannot create the directory (" + ec.message() + ")");
  const fs::path probe = fs::path(dir) / ".magsim_write_test";
  {
    std::ofstream f(probe);
    if (!f || !(f << "ok") || !f.flush()) throw IoError("--out " + dir + ": directory is not writable");
  }
  fs::remove(probe, ec);
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    if (!is_output_name(e.path().filename().string()) || e.is_directory(ec)) continue;
    if (!fs::remove(e.path(), ec) && ec)
      throw IoError("--out " + dir + ": cannot delete the old " + e.path().filename().string() + " (" + ec.message() + ")");
  }
  if (ec) throw IoError("--out " + dir + ": cannot list the directory (" + ec.message() + ")");
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + h, v.end());
  const double hi = v[h];
  if (v.size() % 2) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + h));
}

double sum(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s;
}

json vec3(const engine::Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

// Per-frame output: states.csv and moments.csv rows, and the series of summary.json.
class Recorder {
 public:
  Recorder(const std::string& dir, const engine::Simulation& sim)
      : sim_(sim), states_path_((fs::path(dir) / "states.csv").string()),
        moments_path_((fs::path(dir) / "moments.csv").string()) {
    states_ = std::fopen(states_path_.c_str(), "w");
    if (!states_) throw IoError("cannot create " + states_path_ + " (" + errno_text() + ")");
    moments_ = std::fopen(moments_path_.c_str(), "w");
    if (!moments_) throw IoError("cannot create " + moments_path_ + " (" + errno_text() + ")");
    std::fprintf(states_, "frame,time,body,name,x,y,z,qw,qx,qy,qz\n");
    std::fprintf(moments_, "frame,time,moment,body,x,y,z,Mx,My,Mz,M1x,M1y,M1z,M2x,M2y,M2z\n");
    check();
  }
  /// Flushes and closes both files; throws IoError naming the file that failed.
  void close() {
    std::FILE* s = states_;
    std::FILE* m = moments_;
    states_ = moments_ = nullptr;
    errno = 0;
    const bool s_ok = std::fflush(s) == 0 && !std::ferror(s);
    const std::string s_err = errno_text();
    const bool s_closed = std::fclose(s) == 0;
    if (!s_ok || !s_closed) {
      std::fclose(m);
      throw IoError("writing " + states_path_ + " failed (" + s_err + ")");
    }
    errno = 0;
    const bool m_ok = std::fflush(m) == 0 && !std::ferror(m);
    const std::string m_err = errno_text();
    if (std::fclose(m) != 0 || !m_ok) throw IoError("writing " + moments_path_ + " failed (" + m_err + ")");
  }
  ~Recorder() {
    if (states_) std::fclose(states_);
    if (moments_) std::fclose(moments_);
  }
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Writes the current state as the next frame (x, y, z: centre of mass); false when this
  /// step was already written.
  bool frame() {
    if (sim_.steps() == last_step_) return false;
    last_step_ = sim_.steps();
    const int f = frames_++;
    const double t = sim_.time();
    const engine::Model& m = sim_.model();
    const engine::State& s = sim_.state();
    for (int b = 0; b < m.nbody; ++b) {
      const engine::Vec3& p = s.pos[b];
      const engine::Quat& q = s.quat[b];
      std::fprintf(states_, "%d,%.9g,%d,%s,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", f, t, b,
                   csv_field(m.body_name[b]).c_str(), p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
    }
    const mag::MomentSet& ms = sim_.moments();
    for (int j = 0; j < m.nmoment; ++j) {
      const engine::Vec3& p = ms.position[j];
      std::fprintf(moments_, "%d,%.9g,%d,%d,%.10g,%.10g,%.10g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
                   f, t, j, m.moment_body[j], p.x(), p.y(), p.z(), s.M[j].x(), s.M[j].y(), s.M[j].z(),
                   s.M1[j].x(), s.M1[j].y(), s.M1[j].z(), s.M2[j].x(), s.M2[j].y(), s.M2[j].z());
    }
    const engine::Metrics x = sim_.metrics();
    series_["time"].push_back(t);
    series_["kinetic_energy"].push_back(x.kinetic_energy);
    series_["max_speed"].push_back(x.max_speed);
    series_["bounding_radius"].push_back(x.bounding_radius);
    series_["magnet_radius"].push_back(x.magnet_radius);
    series_["attached"].push_back(x.attached);
    series_["held"].push_back(x.held);
    series_["escaped"].push_back(x.escaped);
    series_["iterations"].push_back(x.iterations);
    series_["momentum_norm"].push_back(x.momentum.norm());
    series_["contacts"].push_back(x.contacts);
    series_["substeps"].push_back(sim_.last_profile().substeps);
    series_["threads"].push_back(sim_.threads());
    check();
    // the energy audit (engine/energy.hpp): state functions and cumulative work (J), and the
    // last step's magnetic and contact work (J per step)
    const engine::EnergyAudit& e = sim_.energy();
    series_["energy_kinetic"].push_back(e.kinetic);
    series_["energy_gravitational"].push_back(e.gravitational);
    series_["energy_magnetic"].push_back(e.magnetic_energy);
    series_["energy_magnetic_work"].push_back(e.total.magnetic_work);
    series_["energy_contact_work"].push_back(e.total.contact_work);
    series_["energy_gravity_work"].push_back(e.total.gravity_work);
    series_["energy_gravity_drift"].push_back(e.total.gravity_drift);
    series_["energy_step_magnetic_work"].push_back(e.last.magnetic_work);
    series_["energy_step_contact_work"].push_back(e.last.contact_work);
    return true;
  }
  int frames() const { return frames_; }
  const json& series() const { return series_; }

 private:
  // a failed write (full disk …) sets the stream's error flag; stop at the first
  void check() const {
    if (std::ferror(states_)) throw IoError("writing " + states_path_ + " failed (" + errno_text() + ")");
    if (std::ferror(moments_)) throw IoError("writing " + moments_path_ + " failed (" + errno_text() + ")");
  }

  const engine::Simulation& sim_;
  std::string states_path_, moments_path_;
  std::FILE* states_ = nullptr;
  std::FILE* moments_ = nullptr;
  long last_step_ = -1;
  int frames_ = 0;
  json series_ = json::object();
};

json energy_flow_json(const engine::EnergyFlow& f) {
  return json{{"kinetic_change", f.kinetic_change},
              {"gravitational_change", f.gravitational_change},
              {"magnetic_work", f.magnetic_work},
              {"gravity_work", f.gravity_work},
              {"contact_work", f.contact_work},
              {"gravity_drift", f.gravity_drift},
              {"contact_work_in", f.contact_work_in}};
}

// summary.json "energy": the audit at the end of the run (J); "last_step" = the increments
// of the final step; "escaped_bodies" = the escaped bodies' kinetic energy now and the
// magnetic and contact work done on them since t = 0 (net, and "_in": the positive steps).
// ΔK + ΔU_g = magnetic_work + contact_work − gravity_drift.
json energy_json(const engine::Simulation& sim) {
  const engine::EnergyAudit& e = sim.energy();
  json j = energy_flow_json(e.total);
  double k = 0.0, w_mag = 0.0, w_c = 0.0, w_mag_in = 0.0, w_c_in = 0.0;
  const std::vector<int> escaped = engine::escaped_bodies(sim.model(), sim.state());
  for (int b : escaped) {
    k += engine::kinetic_energy(sim.model(), sim.state(), b);
    w_mag += e.body_magnetic_work[b];
    w_c += e.body_contact_work[b];
    w_mag_in += e.body_magnetic_work_in[b];
    w_c_in += e.body_contact_work_in[b];
  }
  j["escaped_bodies"] = {{"count", escaped.size()}, {"kinetic", k},
                         {"magnetic_work", w_mag}, {"contact_work", w_c},
                         {"magnetic_work_in", w_mag_in}, {"contact_work_in", w_c_in}};
  j["kinetic"] = e.kinetic;
  j["gravitational"] = e.gravitational;
  j["initial_kinetic"] = e.initial_kinetic;
  j["initial_gravitational"] = e.initial_gravitational;
  j["magnetic_energy"] = e.magnetic_energy;
  j["substeps"] = e.substeps;
  j["last_step"] = energy_flow_json(e.last);
  return j;
}

json options_json(const engine::Model& m) {
  const engine::SimOptions& o = m.options;
  const mag::DynamicsOptions& d = o.magnetics;
  return json{{"dt", o.dt},
              {"dt_m", d.dt},
              {"beta", d.beta},
              {"alpha", d.alpha},
              {"gamma_c_max", d.gamma_c_max},
              {"adaptive_gamma_bound", d.adaptive_gamma_bound},
              {"adaptive_gamma_cap", d.adaptive_gamma_cap},
              {"tol", d.tol},
              {"max_iter", d.max_iter},
              {"min_pair_angle", d.min_pair_angle},
              {"theta_integrator", d.theta_integrator == mag::ThetaIntegrator::Exact ? "exact" : "euler"},
              {"softening", d.field.softening},
              {"field_solver", mag::field_solver_name(d.field.solver)},
              {"field_solver_used", mag::field_solver_name(mag::resolve_solver(d.field, static_cast<std::size_t>(m.nmoment)))},
              {"bh_theta", d.field.bh_theta},
              {"bh_threshold", d.field.auto_threshold},
              {"threads", o.threads},
              {"max_body_speed", o.max_body_speed},
              {"gravity", vec3(o.gravity)},
              {"ground", o.ground},
              {"friction", o.friction},
              {"restitution", o.restitution},
              {"erp", o.erp},
              {"cfm", o.cfm},
              {"quickstep_iterations", o.quickstep_iterations},
              {"max_contacts", o.max_contacts},
              {"space", engine::space_name(o.space)},
              {"auto_disable", o.auto_disable},
              {"force_model", engine::force_choice_name(o.force_model)},
              {"max_substeps", o.max_substeps},
              {"substep_reach", o.substep_reach},
              {"rolling_friction", o.rolling_friction},
              {"quickstep_w", o.quickstep_w},
              {"bounded_pairs", d.field.bounded_pairs},
              {"linear_damping", o.linear_damping},
              {"angular_damping", o.angular_damping},
              {"surface_layer", o.surface_layer},
              {"max_correcting_velocity", o.max_correcting_velocity},
              {"contact_margin", m.contact_margin},
              {"H0", vec3(m.H0)}};
}

// ---- rendering ----------------------------------------------------------------------
// With the renderer built in (MAGSIM_HAVE_RENDER) and without --no-render, every recorded
// frame is drawn: sim.frame(opts) → magsim::render::Renderer → DIR/frame_%06d.png, PNGs written by a
// background thread. crystal_balls (or --arrows) draws M1 (red) and M2 (blue) on every ball.
class FrameRenderer {
 public:
  FrameRenderer(const Args& a, const std::string& dir, bool arrows)
      : dir_(dir), enabled_(!a.no_render) {
    if (!enabled_) return;
#ifdef MAGSIM_HAVE_RENDER
    renderer_ = std::make_unique<magsim::render::Renderer>(a.width, a.height, a.samples);
    writer_ = std::make_unique<magsim::render::FrameWriter>(4, 1);
    opts_.magnetization_arrows = arrows;
    opts_.arrow_scale = 2.2;  // reach out of the ball to be seen
#else
    (void)arrows;
    std::fprintf(stderr, "note: built without the renderer (MAGSIM_RENDER=OFF); continuing as --no-render\n");
    enabled_ = false;
#endif
  }
  void draw(const engine::Simulation& sim) {
    if (!enabled_) return;
#ifdef MAGSIM_HAVE_RENDER
    const auto t0 = std::chrono::steady_clock::now();
    renderer_->draw(sim.frame(opts_));
    ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    writer_->push(magsim::render::frame_path(dir_, index_++), renderer_->width(), renderer_->height(),
                  renderer_->pixels());
#else
    (void)sim;
#endif
  }
  /// Waits for the PNG writer; throws its first error.
  void finish() {
#ifdef MAGSIM_HAVE_RENDER
    if (writer_) writer_->finish();
#endif
  }
  bool enabled() const { return enabled_; }
  int frames() const { return index_; }
  const std::vector<double>& ms() const { return ms_; }

 private:
  std::string dir_;
  bool enabled_;
  int index_ = 0;
  std::vector<double> ms_;
  engine::FrameOptions opts_;
#ifdef MAGSIM_HAVE_RENDER
  std::unique_ptr<magsim::render::Renderer> renderer_;
  std::unique_ptr<magsim::render::FrameWriter> writer_;
#endif
};

int run(const Args& a, const CLI::App& app) {
  // busy machines (cpu_share.hpp): unless the user fixed the thread count (--threads, the scene
  // file's options.threads or OMP_NUM_THREADS), the magnetics use as many threads as the other
  // processes leave cores free; the first window of the estimate is the scene's set-up
  engine::ThreadGovernor governor(max_threads() / 4);  // the cores; Simulation caps it at its own count
  engine::SceneDesc scene = resolve_scene(a, app);
  const std::string method = mag::method_name(scene.options.method);
  std::unique_ptr<engine::Simulation> sim_ptr;
  try {
    sim_ptr = std::make_unique<engine::Simulation>(scene);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("scene '") + scene.name + "': " + e.what());
  }
  engine::Simulation& sim = *sim_ptr;
  const engine::Model& model = sim.model();
  const bool adaptive = scene.options.threads == 0 && std::getenv("OMP_NUM_THREADS") == nullptr;
  const double dt = model.options.dt;

  // the run's length, checked in double before any conversion to long
  long n_steps = a.steps;
  if (!app.count("--steps")) {
    const bool flag = app.count("--seconds") > 0;
    const double seconds = flag ? a.seconds : scene.default_seconds;
    const std::string what = flag ? "--seconds " + fmt(seconds) : "the scene's default_seconds " + fmt(seconds);
    if (seconds < dt * (1 - 1e-9))
      throw UsageError(what + " is shorter than one rigid step (dt = " + fmt(dt) + " s)");
    const double want = seconds / dt;
    if (want > kMaxSteps)
      throw UsageError(what + " at dt = " + fmt(dt) + " s is " + fmt(want) + " steps, more than the bound of " +
                       fmt(kMaxSteps) + " steps");
    n_steps = std::max(1L, std::lround(want));
  }
  if (static_cast<double>(n_steps) > kMaxSteps)
    throw UsageError("--steps " + std::to_string(n_steps) + ": more than the bound of " + fmt(kMaxSteps) + " steps");
  // a frame every per_frame steps; below one frame per run only the first and last are kept
  const double frame_steps = 1.0 / (a.fps * dt);
  const long per_frame = frame_steps >= static_cast<double>(n_steps) ? n_steps : std::max(1L, std::lround(frame_steps));
  const std::string dir = app.count("--out") ? a.out : "out/" + scene.name + "_" + method;
  // summary.json must not overwrite the scene file it was made from (--out = its folder)
  if (ends_with(a.scene, ".json"))
    for (const char* n : kOutputNames) {
      std::error_code ec;
      if (fs::equivalent(fs::path(dir) / n, a.scene, ec))
        throw UsageError("--out " + dir + ": the output " + n + " would overwrite the input scene file " + a.scene);
    }
  prepare_out_dir(dir);
  FrameRenderer painter(a, dir, a.arrows || scene.name == "crystal_balls");

  Recorder rec(dir, sim);
  std::vector<double> Ti, Tf, Tr, collide, quickstep, total, iters, threads;
  Ti.reserve(n_steps);
  Tf.reserve(n_steps);
  Tr.reserve(n_steps);
  collide.reserve(n_steps);
  quickstep.reserve(n_steps);
  total.reserve(n_steps);
  iters.reserve(n_steps);
  threads.reserve(n_steps);
  long cap_hits = 0;
  std::vector<double> substeps;  // rigid sub-steps per frame
  substeps.reserve(n_steps);
  std::string error;

  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  auto last_report = t0;
  std::string io_error;  // the first failed write; the run stops there
  try {
    if (rec.frame()) painter.draw(sim);
    for (long k = 0; k < n_steps; ++k) {
      if (adaptive) sim.limit_default_threads(governor.threads());
      threads.push_back(sim.threads());
      try {
        sim.step();
      } catch (const engine::SimulationError& e) {
        error = e.what();
        break;
      }
      const engine::StepProfile& p = sim.last_profile();
      Ti.push_back(p.T_i);
      Tf.push_back(p.T_f);
      Tr.push_back(p.T_r);
      collide.push_back(p.collide_ms);
      quickstep.push_back(p.quickstep_ms);
      total.push_back(p.total_ms);
      iters.push_back(p.iterations);
      cap_hits += p.cap_hit ? 1 : 0;
      substeps.push_back(p.substeps);
      if (sim.steps() % per_frame == 0 && rec.frame()) painter.draw(sim);
      const auto now = clock::now();
      if (now - last_report >= std::chrono::seconds(2)) {
        last_report = now;
        std::fprintf(stderr,
                     "%s %s: step %ld/%ld  t = %.4f s  wall %.1f s  T_i %.3f  T_f %.3f  T_r %.3f ms  "
                     "iterations %d%s  threads %d\n",
                     scene.name.c_str(), method.c_str(), sim.steps(), n_steps, sim.time(),
                     std::chrono::duration<double>(now - t0).count(), p.T_i, p.T_f, p.T_r, p.iterations,
                     p.cap_hit ? " (cap)" : "", sim.threads());
      }
    }
    if (rec.frame()) painter.draw(sim);  // the final (or last good) state, if not yet drawn
  } catch (const IoError& e) {
    io_error = e.what();
  }
  try {
    painter.finish();
  } catch (const std::exception& e) {
    if (io_error.empty()) io_error = std::string("writing frames: ") + e.what();
  }
  try {
    rec.close();
  } catch (const IoError& e) {
    if (io_error.empty()) io_error = e.what();
  }
  const double wall = std::chrono::duration<double>(clock::now() - t0).count();

  const engine::Metrics fin = sim.metrics();
  char hash[19];
  std::snprintf(hash, sizeof hash, "%016" PRIx64, sim.state_hash());
  auto stats = [](const std::vector<double>& v) { return json{{"median", median(v)}, {"total", sum(v)}}; };
  json summary{
      {"scene", scene.name},
      {"source", ends_with(a.scene, ".json") ? a.scene : "registry"},
      {"description", scene.description},
      {"modelling_level", scene.modelling_level},
      {"method", method},
      {"options", options_json(model)},
      {"params", {{"count", a.count}, {"strength", app.count("--strength") ? a.strength : 1.0}}},
      {"escape_radius", model.escape_radius},
      {"bodies", model.nbody},
      {"dynamic_bodies", model.dynamic_bodies.size()},
      {"moments", model.nmoment},
      {"induced_moments", model.induced_count},
      {"steps", sim.steps()},
      {"steps_requested", n_steps},
      {"seconds", sim.time()},
      {"fps", a.fps},
      {"frames", rec.frames()},
      {"rendered_frames", painter.frames()},
      {"render_ms_median", median(painter.ms())},
      {"wall_seconds", wall},
      {"timing_ms",
       {{"T_i", stats(Ti)},
        {"T_f", stats(Tf)},
        {"T_r", stats(Tr)},
        {"collide", stats(collide)},
        {"quickstep", stats(quickstep)},
        {"step", stats(total)}}},
      // OpenMP threads of the magnetics per step: adaptive = chosen from the other processes'
      // load (cpu_share.hpp), else the fixed count of --threads / options.threads / OMP_NUM_THREADS
      {"threads",
       {{"adaptive", adaptive},
        {"median", median(threads)},
        {"min", threads.empty() ? 0.0 : *std::min_element(threads.begin(), threads.end())},
        {"max", threads.empty() ? 0.0 : *std::max_element(threads.begin(), threads.end())},
        {"others_load", governor.others()}}},
      {"iterations",
       {{"median", median(iters)},
        {"max", iters.empty() ? 0.0 : *std::max_element(iters.begin(), iters.end())},
        {"mean", iters.empty() ? 0.0 : sum(iters) / static_cast<double>(iters.size())},
        {"cap_hits", cap_hits}}},
      // rigid sub-steps per 1 frame step (SimOptions::max_substeps); T_i/T_f/T_r above are
      // per frame, all of its sub-steps included
      {"substeps",
       {{"median", median(substeps)},
        {"max", substeps.empty() ? 0.0 : *std::max_element(substeps.begin(), substeps.end())},
        {"mean", substeps.empty() ? 0.0 : sum(substeps) / static_cast<double>(substeps.size())}}},
      {"final",
       {{"kinetic_energy", fin.kinetic_energy},
        {"max_speed", fin.max_speed},
        {"bounding_radius", fin.bounding_radius},
        {"magnet_radius", fin.magnet_radius},
        {"attached", fin.attached},
        {"held", fin.held},
        {"escaped", fin.escaped},
        {"momentum", vec3(fin.momentum)},
        {"contacts", fin.contacts}}},
      {"energy", energy_json(sim)},
      {"series", rec.series()},
      {"state_hash", hash},
      {"error", !error.empty() ? json(error) : !io_error.empty() ? json(io_error) : json(nullptr)}};

  // written to a temporary name and renamed when complete: a full disk leaves no
  // summary.json that looks valid
  const fs::path path = fs::path(dir) / "summary.json";
  const fs::path tmp = fs::path(dir) / "summary.json.tmp";
  {
    std::ofstream out(tmp);
    out << summary.dump(1) << '\n';
    out.close();
    std::error_code ec;
    if (!out || (fs::rename(tmp, path, ec), ec)) {
      const std::string why = ec ? ec.message() : errno_text();
      fs::remove(tmp, ec);
      std::fprintf(stderr, "error: cannot write %s (%s)%s%s\n", path.c_str(), why.c_str(),
                   io_error.empty() ? "" : "; before that: ", io_error.c_str());
      return kIoError;
    }
  }
  if (!io_error.empty()) {
    std::fprintf(stderr, "error: %s\n(summary with the error in %s)\n", io_error.c_str(), path.c_str());
    return kIoError;
  }
  if (!error.empty()) {
    std::fprintf(stderr, "error: %s\n(summary with the last good state in %s)\n", error.c_str(), path.c_str());
    return kRunFailed;
  }
  const mag::FieldOptions& fo = model.options.magnetics.field;
  std::fprintf(stderr,
               "%s %s: %ld steps, t = %.4f s, wall %.2f s, median T_i %.3f T_f %.3f T_r %.3f step %.3f ms; "
               "field solver %s (%s, %d moments); %s\n",
               scene.name.c_str(), method.c_str(), sim.steps(), sim.time(), wall, median(Ti), median(Tf),
               median(Tr), median(total), mag::field_solver_name(mag::resolve_solver(fo, static_cast<std::size_t>(model.nmoment))),
               mag::field_solver_name(fo.solver), model.nmoment, path.c_str());
  return kOk;
}

// --seconds / --fps: CLI::PositiveNumber lets nan and inf through
const auto kFinitePositive = CLI::Validator(
    [](std::string& v) -> std::string {
      try {
        const double x = std::stod(v);
        if (std::isfinite(x) && x > 0) return {};
      } catch (const std::exception&) {
      }
      return "must be a finite number > 0, got " + v;
    },
    "POSITIVE");

// --width / --height: H.264 (tools/make_video.sh) needs even frame sizes
const auto kEven = CLI::Validator(
    [](std::string& v) -> std::string {
      try {
        if (std::stol(v) % 2 == 0) return {};
      } catch (const std::exception&) {
        return {};  // the Range check names it
      }
      return "must be even (H.264), got " + v;
    },
    "EVEN");

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"magsim-scene: run one scene with one method and write summary.json, states.csv and "
               "moments.csv"};
  Args a;
  app.add_option("scene", a.scene, "a registry scene name (see --list) or a scene FILE.json");
  app.add_option("--method", a.method, "ours-realigned | ours | kim2018 | damping-llg | anderson | exact (default: the scene's, ours-realigned)")
      ->check(CLI::IsMember({"ours", "ours-realigned", "kim2018", "damping-llg", "anderson", "exact"}));
  auto* seconds = app.add_option("--seconds", a.seconds, "simulated time (s); default: the scene's")
                      ->check(kFinitePositive);
  auto* steps = app.add_option("--steps", a.steps, "number of rigid steps")->check(CLI::Range(1L, static_cast<long>(kMaxSteps)));
  seconds->excludes(steps);
  steps->excludes(seconds);
  app.add_option("--out", a.out, "output directory (default: out/<scene>_<method>)");
  app.add_option("--fps", a.fps, "frames of simulated time per second to record (default 60), in [0.001, 1e9]")
      ->check(kFinitePositive & CLI::Range(1e-3, 1e9));
  app.add_flag("--no-render", a.no_render, "do not render frames");
  app.add_option("--width", a.width, "frame width in pixels (even, for H.264)")->check(CLI::Range(16, 8192) & kEven)->capture_default_str();
  app.add_option("--height", a.height, "frame height in pixels (even, for H.264)")->check(CLI::Range(16, 8192) & kEven)->capture_default_str();
  app.add_option("--samples", a.samples, "1: analytic sphere edges; 4: 2x2 supersampling (3x slower)")->check(CLI::Range(1, 4))->capture_default_str();
  app.add_flag("--arrows", a.arrows, "draw M1 (red) and M2 (blue) on every induced moment (on for crystal_balls)");
  app.add_option("--threads", a.threads, "OpenMP threads for the magnetics, at most 4 x the cores")->check(CLI::Range(1, 1000000000));
  app.add_option("--count", a.count, "number of balls / letters (registry scenes)")->check(CLI::Range(1, 1000000000));
  app.add_option("--strength", a.strength, "multiplies every permanent moment")->check(CLI::PositiveNumber);
  app.add_option("--dt-m", a.dt_m, "magnetization time step Δt_m (s), e.g. 1e-7")->check(CLI::PositiveNumber);
  app.add_option("--tol", a.tol, "magnetization convergence tolerance")->check(CLI::PositiveNumber);
  app.add_option("--max-iter", a.max_iter, "magnetization iteration cap per step")->check(CLI::Range(1, 1000000000));
  app.add_option("--quickstep-iterations", a.quickstep_iterations,
                 "ODE QuickStep (contact solver) iterations per rigid step (default: the scene's, 20)")
      ->check(CLI::Range(1, 100000));
  app.add_option("--space", a.space, "ODE broad phase: sap | hash | simple (default: the scene's, sap)");
  app.add_flag("--auto-disable", a.auto_disable, "let ODE put resting bodies to sleep (woken when their magnetic load changes)");
  app.add_option("--force-model", a.force_model,
                 "force on induced moments: method (the method's own: classic for kim2018, eq. 4 "
                 "otherwise) | zeeman (eq. 4) | classic (eqs. 13-14) (default: the scene's, method)");
  app.add_option("--max-substeps", a.max_substeps,
                 "most rigid sub-steps per frame; a frame is split when bodies move fast (1 = never; default: the scene's)")
      ->check(CLI::Range(1, 64));
  app.add_option("--substep-reach", a.substep_reach,
                 "fraction of the smallest dynamic shape radius a body may cover per sub-step (default 0.25)")
      ->check(CLI::PositiveNumber);
  app.add_option("--rolling-friction", a.rolling_friction,
                 "rolling resistance rho (m): contacts resist rolling with a torque <= rho * normal force (0 = none; default: the scene's)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--quickstep-w", a.quickstep_w, "ODE QuickStep over-relaxation W in (0, 2) (default: the scene's, 1.3)")
      ->check(CLI::Range(1e-6, 1.999999));
  app.add_option("--dt", a.dt, "rigid (frame) step dt_r in seconds, (0, 0.1] (default: the scene's, 1e-3)")
      ->check(CLI::Range(1e-7, 0.1));
  app.add_option("--bounded-pairs", a.bounded_pairs,
                 "on | off: evaluate a pair of moments no closer than the sum of their interaction radii (default: the scene's, off)");
  a.field.add(&app,
              "direct | barnes-hut | auto: how the dipole fields are summed, for the magnetization "
              "and the forces alike (default: the scene's, auto); auto = Barnes-Hut from "
              "--bh-threshold moments on");
  app.add_flag("--list", a.list, "list the registry's scenes and exit");

  app.footer("Exit codes: 0 done, 1 bad usage, flags or scene, 2 the simulation failed (summary.json "
             "holds the error), 3 an output file could not be written.\nRuns longer than 1e7 rigid "
             "steps are refused.");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kBadInput;
  }
  if (a.list) {
    for (const scenes::SceneEntry& e : scenes::registry()) std::printf("%-16s %s\n", e.name, e.summary);
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
      std::fprintf(stderr, "error: writing the list to stdout failed (%s)\n", errno_text().c_str());
      return kIoError;
    }
    return kOk;
  }
  if (a.scene.empty()) {
    std::fprintf(stderr, "error: name a scene (%s) or a FILE.json; --help for usage\n", registry_names().c_str());
    return kBadInput;
  }
  try {
    return run(a, app);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kBadInput;
  } catch (const IoError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kIoError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kRunFailed;
  }
}
