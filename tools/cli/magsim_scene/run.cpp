// tools/cli/magsim_scene/run.cpp — runs one scene (from the registry or a JSON file) with one
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
#include "scenes/options_json.hpp"
#include "scenes/scene_file.hpp"
#include "tools/cli/cpu_share.hpp"
#include "tools/cli/magsim_scene/gltf_output.hpp"
#include "tools/cli/magsim_scene/outputs.hpp"
#include "tools/cli/replace_file.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cinttypes>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace magsim::scene_tool {

namespace scenes = magsim::scenes;

namespace {

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

// The signal that asked the run to stop (0: none). Read once per step: no syscall.
volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void on_stop_signal(int sig) { g_stop_signal = sig; }

// SIGINT, SIGTERM and SIGHUP stop the run after the step it is in: whole CSV rows, summary.json
// with "interrupted": true, exit 128 + the signal. Repeats are caught too (a second one
// must not cut a row in half either); SIGKILL remains for a step that will not end. A signal
// the caller ignores stays ignored (nohup, background jobs of a shell).
void catch_stop_signals() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction before {};
    if (sigaction(sig, nullptr, &before) == 0 && before.sa_handler == SIG_IGN) continue;
    sigaction(sig, &sa, nullptr);
  }
}

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
  }
  return "a signal";
}

// A step of a large scene can take minutes (10^6 balls: the first one longer than the build):
// for scenes from kProgressBodies bodies a watcher thread says every 10 s that the step is
// still running, so a long run is never silent. Smaller scenes start no thread and pay
// nothing per step.
class SlowStepNotice {
 public:
  SlowStepNotice(bool on, std::string what) : on_(on), what_(std::move(what)) {
    if (on_) thread_ = std::thread([this] { watch(); });
  }
  ~SlowStepNotice() {
    if (!on_) return;
    {
      std::lock_guard<std::mutex> l(m_);
      done_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  SlowStepNotice(const SlowStepNotice&) = delete;
  SlowStepNotice& operator=(const SlowStepNotice&) = delete;
  void begin(long step) {
    if (!on_) return;
    std::lock_guard<std::mutex> l(m_);
    step_ = step;
    start_ = std::chrono::steady_clock::now();
  }
  void end() {
    if (!on_) return;
    std::lock_guard<std::mutex> l(m_);
    step_ = -1;
  }

 private:
  void watch() {
    std::unique_lock<std::mutex> l(m_);
    while (!done_) {
      cv_.wait_for(l, std::chrono::seconds(10));
      if (done_ || step_ < 0) continue;
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
      if (s >= 10) std::fprintf(stderr, "%s: step %ld still running after %.0f s\n", what_.c_str(), step_, s);
    }
  }

  bool on_;
  std::string what_;
  std::thread thread_;
  std::mutex m_;
  std::condition_variable cv_;
  bool done_ = false;
  long step_ = -1;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

int run_scene(const engine::SceneDesc& scene, const RunPlan& a) {
  // busy machines (cpu_share.hpp): unless the user fixed the thread count (--threads, the scene
  // file's options.threads or OMP_NUM_THREADS), the magnetics use as many threads as the other
  // processes leave cores free; the first window of the estimate is the scene's set-up
  const unsigned cores = std::thread::hardware_concurrency();
  engine::ThreadGovernor governor(cores > 0 ? static_cast<int>(cores) : 1);  // Simulation caps it at its own count
  const std::string method = mag::method_name(scene.options.magnetics.method);
  {
    // the memory the run will take, refused up front when it will not fit (magsim_scene.hpp);
    // the steps as below, bounded by kMaxSteps (a longer run is refused there)
    MemoryNeed need = memory_need(scene);
    const double secs = a.seconds > 0 ? a.seconds : scene.default_seconds;
    need.steps = a.steps > 0 ? static_cast<double>(a.steps)
                                      : std::min(kMaxSteps, std::max(1.0, secs / scene.options.dt));
    need.frames = std::min(need.steps, need.steps * a.fps * scene.options.dt) + 2;
    if (!a.gltf.empty()) {
      if (!ends_with(a.gltf, ".glb")) throw UsageError("--gltf: the path must end in .glb, got '" + a.gltf + "'");
      // --gltf: refused up front when the file would pass glTF's 4 GiB; its frames are held
      // in memory until the end (a frame every max(1, round(1/(fps dt))) steps, first and last)
      const double every = std::max(1.0, std::round(1.0 / (a.fps * scene.options.dt)));
      const double frames = std::floor(need.steps / std::min(every, need.steps)) + 2;
      const std::size_t channels = a.gltf_channels.empty() ? 0 : parse_gltf_channels(a.gltf_channels).size();
      check_gltf_size(scene, frames, channels);
      need.recording = gltf_memory(scene, frames, channels);
    }
    check_memory("scene '" + scene.name + "'", need);
  }
  std::unique_ptr<engine::Simulation> sim_ptr;
  const auto build_start = std::chrono::steady_clock::now();
  try {
    sim_ptr = std::make_unique<engine::Simulation>(scene);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("scene '") + scene.name + "': " + e.what());
  }
  if (static_cast<double>(scene.bodies.size()) >= kProgressBodies)
    std::fprintf(stderr, "%s: %zu bodies built in %.1f s; stepping\n", scene.name.c_str(), scene.bodies.size(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count());
  engine::Simulation& sim = *sim_ptr;
  const engine::Model& model = sim.model();
  const bool adaptive = scene.options.threads == 0 && std::getenv("OMP_NUM_THREADS") == nullptr;
  const double dt = model.options.dt;

  // the run's length, checked in double before any conversion to long
  long n_steps = a.steps;
  if (a.steps <= 0) {
    const bool flag = a.seconds > 0;
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
  const std::string dir = !a.out.empty() ? a.out : "out/" + scene.name + "_" + method;
  // summary.json must not overwrite the scene file it was made from (--out = its folder)
  if (ends_with(a.source, ".json"))
    for (const char* n : kOutputNames) {
      std::error_code ec;
      if (fs::equivalent(fs::path(dir) / n, a.source, ec))
        throw UsageError("--out " + dir + ": the output " + n + " would overwrite the input scene file " + a.source);
    }
  // from here on the folder is touched: a stop signal ends the run cleanly, not the process
  // (before, nothing of this run is on disk and the default action applies); a caller that
  // polls for its own stop (the Python module) keeps its handlers
  if (!a.stop) catch_stop_signals();
  auto stop_requested = [&a]() -> int { return a.stop ? a.stop() : static_cast<int>(g_stop_signal); };
  const OutDirLock lock = prepare_out_dir(dir);
  std::unique_ptr<GltfOutput> glb;  // --gltf: its file is made now, so a bad path fails before the run
  if (!a.gltf.empty()) glb = std::make_unique<GltfOutput>(a, model);
  FrameRenderer painter(a.render, a.width, a.height, a.samples, dir, a.arrows || scene.name == "crystal_balls");

  Recorder rec(dir, sim);
  auto record = [&] {  // a frame of states.csv is a frame of the glTF file, even when drawing it fails
    if (!rec.frame()) return;
    if (glb) glb->frame(sim);
    painter.draw(sim);
  };
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
  double deepest = 0.0, deepest_at = 0.0;  // the deepest contact overlap of any step (m), its time (s)
  std::string error;

  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  auto last_report = t0;
  std::string io_error;  // the first failed write; the run stops there
  SlowStepNotice notice(static_cast<double>(scene.bodies.size()) >= kProgressBodies, scene.name + " " + method);
  try {
    record();
    for (long k = 0; k < n_steps; ++k) {
      if (stop_requested()) break;
      if (adaptive) sim.limit_default_threads(governor.threads());
      threads.push_back(sim.threads());
      try {
        notice.begin(sim.steps() + 1);
        sim.step();
        notice.end();
      } catch (const engine::SimulationError& e) {
        notice.end();
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
      if (sim.state().contact_depth > deepest) {
        deepest = sim.state().contact_depth;
        deepest_at = sim.time();
      }
      if (sim.steps() % per_frame == 0) record();
      const auto now = clock::now();
      if (now - last_report >= std::chrono::seconds(2)) {
        last_report = now;
        std::fprintf(stderr,
                     "%s %s: step %ld/%ld  t = %.4f s  wall %.1f s  T_i %.3f  T_f %.3f  T_r %.3f ms  "
                     "iterations %d%s  threads %d%s\n",
                     scene.name.c_str(), method.c_str(), sim.steps(), n_steps, sim.time(),
                     std::chrono::duration<double>(now - t0).count(), p.T_i, p.T_f, p.T_r, p.iterations,
                     p.cap_hit ? " (cap)" : "", sim.threads(),
                     sim.model().options.sleep ? ("  asleep " + std::to_string(p.asleep)).c_str() : "");
      }
    }
    record();  // the final (or last good) state, if not yet recorded
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
  // a signal during the last step still marks the run: the summary then says what it saw
  const int stop = stop_requested();
  json gltf_info = nullptr;
  if (glb) {  // the frames there are, with the run's outcome in the asset's extras
    const std::string err = !error.empty() ? error : io_error;
    const json extras{{"scene", scene.name}, {"method", method}, {"frames", rec.frames()}, {"seconds", sim.time()},
                      {"fps", a.fps}, {"complete", err.empty() && stop == 0},
                      {"error", err.empty() ? json(nullptr) : json(err)}, {"interrupted", stop != 0},
                      {"signal", stop ? json(signal_name(stop)) : json(nullptr)},
                      {"axes", "y-up: magsim (x, y, z) is written as (x, z, -y)"}};
    try {
      gltf_info = {{"path", glb->path()}, {"bytes", glb->write(extras)}};
    } catch (const IoError& e) {
      if (io_error.empty()) io_error = e.what();
    }
  }

  const engine::Metrics fin = sim.metrics();
  char hash[19];
  std::snprintf(hash, sizeof hash, "%016" PRIx64, sim.state_hash());
  auto stats = [](const std::vector<double>& v) { return json{{"median", median(v)}, {"total", sum(v)}}; };
  // means per step of T_i, T_f, T_r and the whole step over steps [from, from + n)
  const long per_half = std::max<long>(1, std::lround(0.5 / model.options.dt));
  auto phase = [&](long from, long n) {
    auto mean = [&](const std::vector<double>& v) {
      const long a = std::min<long>(from, static_cast<long>(v.size()));
      const long b = std::min<long>(from + n, static_cast<long>(v.size()));
      double acc = 0.0;
      for (long k = a; k < b; ++k) acc += v[k];
      return b > a ? acc / static_cast<double>(b - a) : 0.0;
    };
    return json{{"T_i", mean(Ti)}, {"T_f", mean(Tf)}, {"T_r", mean(Tr)}, {"step", mean(total)}};
  };
  json summary{
      {"scene", scene.name},
      {"source", ends_with(a.source, ".json") ? a.source : "registry"},
      {"description", scene.description},
      {"modelling_level", scene.modelling_level},
      {"method", method},
      // the force actually used, in --force-model's spelling ("zeeman" = eq. 4)
      {"force_model", mag::kForceModelNames.name(model.resolved.force)},
      // the run's options in the scene file's spelling (scenes/options_json.hpp): pasted into
      // a scene file as "options" they rerun this run
      {"options", scenes::to_json(model.options)},
      {"field_solver_used", mag::field_solver_name(mag::resolve_solver(model.options.magnetics.field,
                                                                        static_cast<std::size_t>(model.nmoment)))},
      {"contact_margin_used", model.contact_margin},
      {"H0", scenes::vec3_json(model.H0)},
      {"params", {{"count", a.count}, {"strength", a.strength}}},
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
        {"step", stats(total)},
        // what the motion and the rest cost: means per step over the run's first and last 0.5 s
        {"first_half_second", phase(0, per_half)},
        {"last_half_second", phase(std::max<long>(0, static_cast<long>(total.size()) - per_half), per_half)}}},
      {"wall_per_simulated_second", sim.time() > 0 ? wall / sim.time() : 0.0},
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
      // the deepest overlap of any contact in any step (m) and the time of that step (s):
      // bodies sink into contacts the solver (QuickStep's iterations) leaves unbalanced
      {"contact_depth", {{"max", deepest}, {"max_at", deepest_at}}},
      {"final",
       {{"kinetic_energy", fin.kinetic_energy},
        {"rotational_energy", fin.rotational_energy},
        {"max_speed", fin.max_speed},
        {"bounding_radius", fin.bounding_radius},
        {"magnet_radius", fin.magnet_radius},
        {"attached", fin.attached},
        {"held", fin.held},
        {"escaped", fin.escaped},
        {"momentum", scenes::vec3_json(fin.momentum)},
        {"contacts", fin.contacts}}},
      {"energy", energy_json(sim)},
      {"series", rec.series()},
      {"state_hash", hash},
      {"gltf", gltf_info},  // --gltf: the file and its size, null without it or when it failed
      // stopped by SIGINT, SIGTERM or SIGHUP after `steps` whole steps (the last good state)
      {"interrupted", stop != 0},
      {"signal", stop ? json(signal_name(stop)) : json(nullptr)},
      {"error", !error.empty() ? json(error) : !io_error.empty() ? json(io_error) : json(nullptr)}};

  // written to a unique temporary name and renamed when complete (tools/cli/replace_file.hpp): a
  // full disk leaves no summary.json that looks valid
  const fs::path path = fs::path(dir) / "summary.json";
  try {
    tools::replace_file(path.string(), summary.dump(1) + "\n");
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "error: cannot write %s: %s%s%s\n", path.c_str(), tools::one_line(e.what()).c_str(),
                 io_error.empty() ? "" : "; before that: ", tools::one_line(io_error).c_str());
    return kIoError;
  }
  if (a.error) *a.error = !io_error.empty() ? io_error : error;
  if (!io_error.empty()) {
    std::fprintf(stderr, "error: %s\n(summary with the error in %s)\n", tools::one_line(io_error).c_str(), path.c_str());
    return kIoError;
  }
  if (!error.empty()) {
    std::fprintf(stderr, "error: %s\n(summary with the last good state in %s)\n", tools::one_line(error).c_str(),
                 path.c_str());
    return kRunFailed;
  }
  if (stop) {
    std::fprintf(stderr, "%s %s: interrupted by %s after %ld of %ld steps; outputs complete to there, summary in %s\n",
                 scene.name.c_str(), method.c_str(), signal_name(stop), sim.steps(), n_steps, path.c_str());
    return 128 + stop;
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


std::string scene_file_text(const engine::SceneDesc& scene) { return scenes::scene_to_json(scene).dump(1) + "\n"; }

}  // namespace magsim::scene_tool
