// tools/cli/magsim_scene/main.cpp — magsim-scene's command line: the flags, the scene they
// name with their overrides applied (resolve_scene), --list, and the exit codes.
#include "scenes/options_json.hpp"
#include "scenes/registry.hpp"
#include "scenes/scene_file.hpp"
#include "tools/cli/magsim_scene/gltf_output.hpp"
#include "tools/cli/replace_file.hpp"
#include "tools/cli/magsim_scene/magsim_scene.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <utility>


namespace magsim::scene_tool {

namespace scenes = magsim::scenes;
namespace fs = std::filesystem;

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
    check_registry_memory(*e, p, a.scene + " --count " + std::to_string(p.count));
    s = e->build(p);
  }
  // the option flags given (the table's: engine/options_table.hpp); the scene's values stand
  // for the rest
  try {
    a.options.apply(&s.options);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  // the thread cap holds for the flag and the scene file alike (--write-scene too)
  if (s.options.threads > tools::max_threads())
    throw UsageError((app.count("--threads") ? std::string("--threads: ") : a.scene + ": options.threads: ") +
                     "at most " + std::to_string(tools::max_threads()) + " (4 x the " +
                     std::to_string(tools::max_threads() / 4) + " cores), got " + std::to_string(s.options.threads));
  return s;
}


// The run of the scene the command line names, as its flags plan it (run.cpp).
int run(const Args& a, const CLI::App& app) {
  RunPlan plan;
  const engine::SceneDesc scene = resolve_scene(a, app);
  plan.source = a.scene;
  plan.count = a.count;
  if (app.count("--strength")) plan.strength = a.strength;
  if (app.count("--steps")) plan.steps = a.steps;
  if (app.count("--seconds")) plan.seconds = a.seconds;
  plan.out = a.out;
  plan.fps = a.fps;
  plan.render = !a.no_render;
  plan.arrows = a.arrows;
  plan.width = a.width;
  plan.height = a.height;
  plan.samples = a.samples;
  plan.gltf = a.gltf;
  plan.gltf_channels = a.gltf_channels;
  return run_scene(scene, plan);
}

// --write-scene FILE: the resolved scene as a scene file (scenes::scene_to_json), written whole
// through a temporary file (tools/cli/replace_file.hpp): a regular file or a symlink to one is
// replaced, a missing one created; a directory, device, FIFO or dangling link is refused.
int write_scene(const Args& a, const CLI::App& app) {
  const engine::SceneDesc scene = resolve_scene(a, app);
  try {
    tools::replace_file(a.write_scene, scene_file_text(scene));
  } catch (const tools::NotARegularFile& e) {
    throw UsageError("--write-scene " + a.write_scene + ": " + e.what());
  } catch (const tools::WriteFailed& e) {
    throw IoError("--write-scene: cannot write " + a.write_scene + ": " + e.what());
  }
  std::fprintf(stderr, "%s: %zu bodies written to %s\n", scene.name.c_str(), scene.bodies.size(), a.write_scene.c_str());
  return kOk;
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

// --width / --height: H.264 (tools/scripts/make_video.sh) needs even frame sizes
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
  app.add_option("--count", a.count, "number of balls / letters (registry scenes)")->check(tools::Range(1, 1000000000));
  app.add_option("--strength", a.strength, "multiplies every permanent moment")->check(tools::PositiveNumber);
  // the run options' flags, one per entry of the table that has one
  a.options.add(&app, "Options of the run (each overrides the scene's options.<key>; the scene file's ranges)");
  app.add_option("--gltf", a.gltf,
                 "also write the run as one binary glTF 2.0 file PATH.glb (y-up: magsim's (x, y, z) as (x, z, -y)): "
                 "a node per body with its shapes, one animation keyed at the recorded frames' simulated times "
                 "(those of states.csv), the camera and the ground; works with --no-render (tools/PROGRAMS.md)");
  app.add_option("--gltf-channels", a.gltf_channels,
                 "with --gltf: per-body values per frame, comma-separated, at most 3 of m_norm (|total moment|, "
                 "A*m^2), speed (m/s), spin (rad/s); carried as the animated scale of a node <body>.channels, "
                 "channel k on Blender's scale axis k");
  app.add_flag("--list", a.list, "list the registry's scenes and exit");
  bool options_json = false;
  app.add_flag("--options-json", options_json,
               "print the table of options as JSON (key, kind, unit, default, range or names, flag, doc; "
               "engine/options_table.cpp) and exit");
  app.add_option("--write-scene", a.write_scene,
                 "write the scene (with --count, --strength and the option flags applied) as a scene "
                 "FILE.json to edit and run, and exit without running");

  app.footer(magsim::tools::exit_codes_footer("bad usage, flags or scene", "the simulation failed (summary.json holds the error)",
                                      "an output file could not be written",
                                      "Runs longer than 1e7 rigid steps are refused; so are runs whose estimated memory exceeds "
                                      "MemAvailable or what ulimit -v leaves, --gltf files that could exceed glTF's 4 GiB, scene files "
                                      "that are not regular files or are larger than 1 GiB, and OMP_NUM_THREADS above 4 x "
                                      "the cores.\n" +
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
  if (options_json) {
    errno = 0;
    std::printf("%s\n", scenes::table_json().dump(1).c_str());
    return tools::stdout_written("error: ", "the options") ? kOk : kIoError;
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
  for (const auto& [flag, path] : {std::pair<const char*, const std::string&>{"--write-scene", a.write_scene}, {"--out", a.out}, {"--gltf", a.gltf}})
    if (app.count(flag) && path.empty()) {
      std::fprintf(stderr, "error: %s: needs a non-empty path\n", flag);
      return kBadInput;
    }
  try {
    if (app.count("--gltf-channels") && !app.count("--gltf")) throw UsageError("--gltf-channels needs --gltf");
    if (app.count("--gltf-channels")) parse_gltf_channels(a.gltf_channels);
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
