// tools/magsim_scene/main.cpp — magsim-scene's command line: the flags, the scene they
// name with their overrides applied (resolve_scene), --list, and the exit codes.
#include "scenes/options_json.hpp"
#include "scenes/registry.hpp"
#include "scenes/scene_file.hpp"
#include "tools/magsim_scene/magsim_scene.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <utility>

#include <sys/resource.h>

namespace magsim::scene_tool {

namespace scenes = magsim::scenes;
namespace fs = std::filesystem;

std::string fmt(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", x);
  return b;
}


bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}


std::string registry_names() {
  std::string names;
  for (const scenes::SceneEntry& e : scenes::registry()) names += (names.empty() ? "" : ", ") + std::string(e.name);
  return names;
}


MemoryNeed memory_need(const engine::SceneDesc& s) {
  MemoryNeed n;
  n.bodies = static_cast<double>(s.bodies.size());
  for (const engine::BodyDesc& b : s.bodies) {
    n.moments += static_cast<double>(b.moments.size());
    n.shapes += static_cast<double>(b.shapes.size());
  }
  return n;
}

double memory_available(std::string* source) {
  double avail = -1;
  if (std::FILE* f = std::fopen("/proc/meminfo", "r")) {
    char line[256];
    while (std::fgets(line, sizeof line, f)) {
      unsigned long long kb = 0;
      if (std::sscanf(line, "MemAvailable: %llu kB", &kb) == 1) {
        avail = static_cast<double>(kb) * 1024.0;
        *source = "MemAvailable";
        break;
      }
    }
    std::fclose(f);
  }
  struct rlimit rl {};
  if (::getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    double mapped = 0;  // VmSize: what the address-space limit already counts
    if (std::FILE* f = std::fopen("/proc/self/status", "r")) {
      char line[256];
      unsigned long long kb = 0;
      while (std::fgets(line, sizeof line, f))
        if (std::sscanf(line, "VmSize: %llu kB", &kb) == 1) mapped = static_cast<double>(kb) * 1024.0;
      std::fclose(f);
    }
    const double left = std::max(0.0, static_cast<double>(rl.rlim_cur) - mapped);
    if (avail < 0 || left < avail) {
      avail = left;
      *source = "the address-space limit (ulimit -v)";
    }
  }
  return avail;
}

void check_memory(const std::string& what, const MemoryNeed& need) {
  std::string source;
  const double avail = memory_available(&source);
  const double gb = 1e9;
  char detail[256];
  std::snprintf(detail, sizeof detail, "%.0f bodies, %.0f moments, %.0f shapes", need.bodies, need.moments, need.shapes);
  if (need.steps > 0) std::snprintf(detail + std::strlen(detail), sizeof detail - std::strlen(detail), ", %.0f steps", need.steps);
  if (avail >= 0 && need.bytes() > avail) {
    char msg[512];
    std::snprintf(msg, sizeof msg, "%s: needs about %.2f GB of memory (%s; estimated, magsim_scene.hpp MemoryNeed), "
                  "more than the %.2f GB available (%s)", what.c_str(), need.bytes() / gb, detail, avail / gb, source.c_str());
    throw UsageError(msg);
  }
  if (need.bodies >= kProgressBodies)
    std::fprintf(stderr, "%s: %s; about %.2f GB of memory estimated%s\n", what.c_str(), detail, need.bytes() / gb,
                 avail >= 0 ? (", " + fmt(avail / gb) + " GB available").c_str() : "");
}


namespace {

// registry scenes above this --count are sized from builds of 1 and of this many first
constexpr int kSampleCount = 100;

// the value of an on | off flag
bool on_off(const char* flag, const std::string& value) {
  if (value != "on" && value != "off")
    throw UsageError(std::string(flag) + ": expected on or off, got '" + value + "'");
  return value == "on";
}

}  // namespace

// The scene named on the command line, with the command line's overrides applied.
engine::SceneDesc resolve_scene(const Args& a, const CLI::App& app) {
  engine::SceneDesc s;
  if (ends_with(a.scene, ".json")) {
    if (app.count("--count")) throw UsageError("--count applies to registry scenes only, not to " + a.scene);
    try {
      std::error_code ec;
      const auto bytes = fs::file_size(a.scene, ec);
      if (!ec && bytes >= (32u << 20))  // a large file takes seconds: say what is going on
        std::fprintf(stderr, "%s: reading %.0f MB of scene file\n", a.scene.c_str(), static_cast<double>(bytes) / 1e6);
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
    if (p.count > kSampleCount) {
      // the scene's own description would take memory in proportion to --count (1e8 balls:
      // tens of GB before any check): its size is extrapolated from two small builds first
      scenes::SceneParams small = p;
      small.count = 1;
      const MemoryNeed one = memory_need(e->build(small));
      small.count = kSampleCount;
      const MemoryNeed many = memory_need(e->build(small));
      const double k = static_cast<double>(p.count - 1) / (kSampleCount - 1);
      MemoryNeed need;
      need.bodies = one.bodies + k * (many.bodies - one.bodies);
      need.moments = one.moments + k * (many.moments - one.moments);
      need.shapes = one.shapes + k * (many.shapes - one.shapes);
      check_memory(a.scene + " --count " + std::to_string(p.count), need);
    }
    s = e->build(p);
  }
  if (app.count("--method") && !mag::parse_method(a.method, &s.options.magnetics.method))
    throw UsageError("--method: " + mag::kMethodNames.unknown("method", a.method));
  // the thread cap holds for the flag and the scene file alike (--write-scene too)
  const std::string cap = "at most " + std::to_string(tools::max_threads()) + " (4 x the " +
                          std::to_string(tools::max_threads() / 4) + " cores), got ";
  if (app.count("--threads")) {
    if (a.threads > tools::max_threads()) throw UsageError("--threads: " + cap + std::to_string(a.threads));
    s.options.threads = a.threads;
  } else if (s.options.threads > tools::max_threads()) {
    throw UsageError(a.scene + ": options.threads: " + cap + std::to_string(s.options.threads));
  }
  if (app.count("--dt-m")) s.options.magnetics.dt = a.dt_m;
  if (app.count("--tol")) s.options.magnetics.tol = a.tol;
  if (app.count("--max-iter")) s.options.magnetics.max_iter = a.max_iter;
  if (app.count("--quickstep-iterations")) s.options.quickstep_iterations = a.quickstep_iterations;
  if (app.count("--auto-disable")) s.options.auto_disable = true;
  if (app.count("--force-model") && !mag::kForceModelNames.parse(a.force_model, &s.options.force_model))
    throw UsageError("--force-model: " + mag::kForceModelNames.unknown("force model", a.force_model));
  if (app.count("--max-substeps")) s.options.max_substeps = a.max_substeps;
  if (app.count("--substep-reach")) s.options.substep_reach = a.substep_reach;
  if (app.count("--substep-load")) s.options.substep_load = on_off("--substep-load", a.substep_load);
  if (app.count("--balance-magnetic-torque"))
    s.options.balance_magnetic_torque = on_off("--balance-magnetic-torque", a.balance_magnetic_torque);
  if (app.count("--rolling-friction")) s.options.rolling_friction = a.rolling_friction;
  if (app.count("--rolling-friction-bodies")) s.options.rolling_friction_bodies = a.rolling_friction_bodies;
  if (app.count("--eddy-conductivity")) s.options.eddy_conductivity = a.eddy_conductivity;
  if (app.count("--energy-guard")) s.options.energy_guard = on_off("--energy-guard", a.energy_guard);
  if (app.count("--energy-guard-tolerance")) s.options.energy_guard_tolerance = a.energy_guard_tolerance;
  if (app.count("--energy-guard-floor")) s.options.energy_guard_floor = a.energy_guard_floor;
  if (app.count("--energy-guard-max-substeps")) s.options.energy_guard_max_substeps = a.energy_guard_max_substeps;
  if (app.count("--quickstep-w")) s.options.quickstep_w = a.quickstep_w;
  if (app.count("--dt")) s.options.dt = a.dt;
  if (app.count("--bounded-pairs"))
    s.options.magnetics.field.bounded_pairs = on_off("--bounded-pairs", a.bounded_pairs);
  if (app.count("--softening")) s.options.magnetics.field.softening = a.softening;
  if (app.count("--space")) {
    if (!engine::parse_space(a.space, &s.options.space))
      throw UsageError("--space: " + engine::kSpaceNames.unknown("broad phase", a.space));
  }
  mag::FieldOptions& f = s.options.magnetics.field;
  try {
    a.field.apply(&f);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (const std::string e = mag::validate(f); !e.empty()) throw UsageError("field options: " + e);
  return s;
}


namespace {

// --seconds: a number > 0 that is also finite (PositiveNumber lets inf through)
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

}  // namespace magsim::scene_tool

using namespace magsim::scene_tool;

namespace tools = magsim::tools;

int main(int argc, char** argv) {
  tools::ignore_write_signals();
  CLI::App app{"magsim-scene: run one scene with one method and write summary.json, states.csv and "
               "moments.csv"};
  Args a;
  app.add_option("scene", a.scene, "a registry scene name (see --list) or a scene FILE.json");
  app.add_option("--method", a.method,
                 mag::kMethodNames.list(" | ") +
                     " (default: the scene's, anderson: M = f(H(M)) converged every sub-step, with the classic "
                     "force, -grad of the co-energy U*; ours = the paper as printed: theta dynamics eqs. 8-11 and "
                     "eq. 4, which has no energy; kim2018 = the baseline)")
      ->check(CLI::IsMember(mag::kMethodNames.names()));
  auto* seconds = app.add_option("--seconds", a.seconds, "simulated time (s); default: the scene's")
                      ->check(kFinitePositive);
  auto* steps = app.add_option("--steps", a.steps, "number of rigid steps")->check(tools::Range(1L, static_cast<long>(kMaxSteps)));
  seconds->excludes(steps);
  steps->excludes(seconds);
  app.add_option("--out", a.out, "output directory (default: out/<scene>_<method>)");
  app.add_option("--fps", a.fps, "frames of simulated time per second to record (default 60), in [0.001, 1e9]")
      ->check(tools::Range(1e-3, 1e9));
  app.add_flag("--no-render", a.no_render, "do not render frames");
  app.add_option("--width", a.width, "frame width in pixels (even, for H.264)")->check(tools::Range(16, 8192) & kEven)->capture_default_str();
  app.add_option("--height", a.height, "frame height in pixels (even, for H.264)")->check(tools::Range(16, 8192) & kEven)->capture_default_str();
  app.add_option("--samples", a.samples, "1: analytic sphere edges; 4: 2x2 supersampling (3x slower)")->check(tools::Range(1, 4))->capture_default_str();
  app.add_flag("--arrows", a.arrows, "draw M1 (red) and M2 (blue) on every induced moment (on for crystal_balls)");
  app.add_option("--threads", a.threads, "OpenMP threads for the magnetics, at most 4 x the cores (0: sized to the free cores, the default)")->check(tools::OptionCheck("threads"));
  app.add_option("--count", a.count, "number of balls / letters (registry scenes)")->check(tools::Range(1, 1000000000));
  app.add_option("--strength", a.strength, "multiplies every permanent moment")->check(tools::PositiveNumber);
  app.add_option("--dt-m", a.dt_m, "magnetization time step Δt_m (s), e.g. 1e-7, in [1e-9, 1e-6]")->check(tools::OptionCheck("magnetics.dt"));
  app.add_option("--tol", a.tol, "magnetization convergence tolerance, in (0, 1)")->check(tools::OptionCheck("magnetics.tol"));
  app.add_option("--max-iter", a.max_iter, "magnetization iteration cap per solve, in [1, 1000000]")->check(tools::OptionCheck("magnetics.max_iter"));
  app.add_option("--quickstep-iterations", a.quickstep_iterations,
                 "ODE QuickStep (contact solver) iterations per rigid step (default: the scene's, 20)")
      ->check(tools::OptionCheck("quickstep_iterations"));
  app.add_option("--space", a.space, "ODE broad phase: " + engine::kSpaceNames.list(" | ") + " (default: the scene's, sap)");
  app.add_flag("--auto-disable", a.auto_disable, "let ODE put resting bodies to sleep (woken when their magnetic load changes)");
  app.add_option("--force-model", a.force_model,
                 "force on induced moments: method (the method's own: classic for anderson, exact and kim2018, "
                 "eq. 4 for ours, ours-realigned and damping-llg) | zeeman (eq. 4, not the gradient of any energy) "
                 "| classic (eqs. 13-14, -grad U* with converged magnetizations) | zeeman-total (eq. 4 as the "
                 "gradient of the system's Zeeman energy: conservative) (default: the scene's, method)");
  app.add_option("--energy-guard", a.energy_guard,
                 "on | off: retake a rigid step in twice the sub-steps when E = K + U_g + U* rises by more than "
                 "the tolerance (default on; unavailable for eq. 4 (zeeman), which has no energy: never applied "
                 "there, summary.json energy.guard says so)");
  app.add_option("--energy-guard-tolerance", a.energy_guard_tolerance,
                 "the guard's tolerance relative to the step's K_start + K_end + |U*_start| (default 1e-3)")
      ->check(tools::OptionCheck("energy_guard_tolerance"));
  app.add_option("--energy-guard-floor", a.energy_guard_floor,
                 "the guard's absolute tolerance per step, J (default 1e-6)")
      ->check(tools::OptionCheck("energy_guard_floor"));
  app.add_option("--energy-guard-max-substeps", a.energy_guard_max_substeps,
                 "most sub-steps the guard retakes a frame in (default 32)")
      ->check(tools::OptionCheck("energy_guard_max_substeps"));
  app.add_option("--max-substeps", a.max_substeps,
                 "most rigid sub-steps per frame; a frame is split when bodies touching each other move fast or bodies "
                 "in contact are pressed hard by the magnetic force (1 = never; default: the scene's)")
      ->check(tools::OptionCheck("max_substeps"));
  app.add_option("--substep-reach", a.substep_reach,
                 "fraction of the smallest dynamic shape radius a body may cover per sub-step (default 0.25)")
      ->check(tools::OptionCheck("substep_reach"));
  app.add_option("--substep-load", a.substep_load,
                 "on | off: also split a frame by the magnetic acceleration a of bodies in contact, "
                 "a h^2 <= reach * r_min per sub-step (default on)");
  app.add_option("--balance-magnetic-torque", a.balance_magnetic_torque,
                 "on | off: cancel the net torque that eq. 4's reaction-symmetric forces leave (they sum to "
                 "zero, their torques do not), by the least forces that do, where the torque arises; needs "
                 "reaction-symmetric forces (default: the scene's, off in every registry scene)");
  app.add_option("--rolling-friction", a.rolling_friction,
                 "rolling resistance rho (m): contacts resist rolling with a torque <= rho * normal force (0 = none; default: the scene's)")
      ->check(tools::OptionCheck("rolling_friction"));
  app.add_option("--rolling-friction-bodies", a.rolling_friction_bodies,
                 "the same between two dynamic bodies (a ball rolling on a ball), rho (m) (0 = none; default: the scene's)")
      ->check(tools::OptionCheck("rolling_friction_bodies"));
  app.add_option("--eddy-conductivity", a.eddy_conductivity,
                 "electrical conductivity sigma (S/m) of the induced bodies: eddy-current loss where their flux "
                 "density changes in their own frame (iron 1e7; 0 = none; default: the scene's)")
      ->check(tools::OptionCheck("eddy_conductivity"));
  app.add_option("--quickstep-w", a.quickstep_w, "ODE QuickStep over-relaxation W in (0, 2) (default: the scene's, 1.3)")
      ->check(tools::OptionCheck("quickstep_w"));
  app.add_option("--dt", a.dt, "rigid (frame) step dt_r in seconds, in (0, 0.1] (default: the scene's, 1e-3)")
      ->check(tools::OptionCheck("dt"));
  app.add_option("--bounded-pairs", a.bounded_pairs,
                 "on | off: evaluate a pair of moments no closer than the sum of their interaction radii (default: the scene's, off)");
  app.add_option("--softening", a.softening,
                 "dipole softening length eps (m): |r|^2 -> |r|^2 + eps^2 in every field, Jacobian and "
                 "force, in [0, 0.1] (default: the scene's)")
      ->check(tools::OptionCheck("magnetics.field.softening"));
  a.field.add(&app,
              mag::kFieldSolverNames.list(" | ") + ": how the dipole fields are summed, for the magnetization "
              "and the forces alike (default: the scene's, auto); auto = Barnes-Hut from "
              "--bh-threshold moments on");
  app.add_flag("--list", a.list, "list the registry's scenes and exit");
  app.add_option("--write-scene", a.write_scene,
                 "write the scene (with --count, --strength and the option flags applied) as a scene "
                 "FILE.json to edit and run, and exit without running");

  app.footer(magsim::tools::exit_codes_footer("bad usage, flags or scene", "the simulation failed (summary.json holds the error)",
                                      "an output file could not be written",
                                      "Runs longer than 1e7 rigid steps are refused; so are runs whose estimated memory exceeds "
                                      "MemAvailable or what ulimit -v leaves, scene files that are not regular "
                                      "files or are larger than 1 GiB, and OMP_NUM_THREADS above 4 x the cores.\n" +
                                      std::string(tools::kMagsimKernelHelp) + "\n"
                                      "Every option flag has the range of its scene-file key (engine/options_table.cpp).\n"
                                      "SIGINT, SIGTERM, SIGHUP: the run finishes the step it is in, writes its outputs "
                                      "(summary.json: \"interrupted\": true) and exits 128 + the signal.\n"
                                      "One run at a time per output folder (it holds a lock on DIR/.magsim.lock)."));
  if (const int code = tools::parse_command_line(app, argc, argv, "error: "); code >= 0) return code;
  if (const std::string e = tools::omp_num_threads_error(); !e.empty()) {
    std::fprintf(stderr, "error: %s\n", e.c_str());
    return kBadInput;
  }
  if (const std::string e = tools::magsim_kernel_error(); !e.empty()) {
    std::fprintf(stderr, "error: %s\n", e.c_str());
    return kBadInput;
  }
  if (a.list) {
    errno = 0;
    for (const scenes::SceneEntry& e : scenes::registry()) std::printf("%-16s %s\n", e.name, e.summary);
    return tools::stdout_written("error: ", "the list") ? kOk : kIoError;
  }
  if (a.scene.empty()) {
    std::fprintf(stderr, "error: name a scene (%s) or a FILE.json; --help for usage\n", registry_names().c_str());
    return kBadInput;
  }
  // an empty name would be ignored (--write-scene) or fail as a folder (--out)
  for (const auto& [flag, path] : {std::pair<const char*, const std::string&>{"--write-scene", a.write_scene}, {"--out", a.out}})
    if (app.count(flag) && path.empty()) {
      std::fprintf(stderr, "error: %s: needs a non-empty path\n", flag);
      return kBadInput;
    }
  try {
    if (app.count("--write-scene")) return write_scene(a, app);
    return run(a, app);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "error: %s\n", tools::one_line(e.what()).c_str());
    return kBadInput;
  } catch (const IoError& e) {
    std::fprintf(stderr, "error: %s\n", tools::one_line(e.what()).c_str());
    return kIoError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", tools::one_line(e.what()).c_str());
    return kRunFailed;
  }
}
