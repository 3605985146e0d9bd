// tools/cli/magsim_scene/magsim_scene.hpp — what the files of magsim-scene share: the
// command-line arguments, the errors that pick the exit code, and the entry points
// (main.cpp: flags, the scene they name and --write-scene; run.cpp: the run;
// outputs.hpp/.cpp: summary.json's parts, states.csv, moments.csv, frames; memory.cpp: the
// memory estimate). run.cpp, outputs.cpp and memory.cpp are the library magsim_scene_run,
// which the Python module's magsim.run links too, so both write the same files.
#pragma once

#include "engine/scene_desc.hpp"
#include "scenes/registry.hpp"
#include "tools/cli/cli_common.hpp"
#include "tools/cli/option_flags.hpp"

#include <CLI/CLI.hpp>

#include <functional>
#include <stdexcept>
#include <string>

namespace magsim::scene_tool {

namespace engine = magsim::engine;
namespace mag = magsim::mag;
using tools::errno_text;
using tools::Exit;
using tools::kBadInput;
using tools::kIoError;
using tools::kOk;
using tools::kRunFailed;

// Runs above this many rigid steps are refused up front: the per-step timings alone take
// 56 bytes a step (560 MB here), and at ~1 ms a step it is hours of wall time; a typo such
// as --seconds 1e8 or "dt": 1e-12 would otherwise end in bad_alloc.
constexpr double kMaxSteps = 1e7;


struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// an output file could not be written (exit 3)
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};


struct Args {
  std::string scene;
  double seconds = 0.0;
  long steps = 0;
  std::string out;
  double fps = 60.0;
  bool no_render = false;
  bool arrows = false;
  int width = 1280, height = 720, samples = 1;
  int count = 0;
  double strength = 0.0;
  /// the flags of the run options (--method, --dt, --threads, …): engine/options_table.hpp
  tools::OptionFlags options;
  bool list = false;
  std::string write_scene;
  std::string gltf;           ///< --gltf PATH.glb: the run as binary glTF (gltf_output.hpp)
  std::string gltf_channels;  ///< --gltf-channels m_norm,speed,spin
};


// ---- memory ---------------------------------------------------------------------------------
// A run's memory is estimated up front and refused (exit 1) when it will not fit, instead of
// ending in bad_alloc after minutes. Measured peaks (Release, --steps 1 --no-render, RSS):
// balls_up 6.6 KiB a body (1 shape, 1 moment), falling_magnet 7.8, sakura_tree and
// crystal_balls 3.7, alphabets 25 (letters of several shapes and 2.6 moments), over a base
// of about 60 MB. The estimate below is above all of them (up to 2.7x for sakura_tree):
// refusing a run that would have fit is the lesser harm.
struct MemoryNeed {
  double bodies = 0, moments = 0, shapes = 0;  // the scene's
  double steps = 0, frames = 0;                 // the run's
  double recording = 0;                         // bytes held for --gltf (gltf_output.hpp)
  /// bytes: base + per body, moment and shape (ODE bodies, geoms and contacts, the model,
  /// state and magnetics workspace), per step (the timing series) and per recorded frame
  /// (summary.json's series)
  double bytes() const {
    return 64.0 * (1 << 20) + 6144.0 * bodies + 2048.0 * (moments + shapes) + 80.0 * steps + 512.0 * frames + recording;
  }
};
/// The scene's bodies, moments and shapes.
MemoryNeed memory_need(const engine::SceneDesc& s);
/// Bytes this process may still take: /proc/meminfo's MemAvailable, and the address-space
/// limit (RLIMIT_AS) less what is mapped now when it is lower; *source says which. < 0 when
/// neither can be read (then nothing is refused).
double memory_available(std::string* source);
/// Throws UsageError "<what>: needs about X GB of memory (...), more than the Y GB available
/// (...)" when need.bytes() exceeds memory_available(); prints a progress line for large
/// scenes (from kProgressBodies bodies) with the estimate.
void check_memory(const std::string& what, const MemoryNeed& need);
/// check_memory for registry scene `e` built with p, before it is built: its size extrapolated
/// from builds of 1 and 100 (a count of 1e8 would take tens of GB to describe).
void check_registry_memory(const scenes::SceneEntry& e, const scenes::SceneParams& p, const std::string& what);
/// From this many bodies magsim-scene says what it is doing while it reads and builds.
constexpr double kProgressBodies = 20000;

std::string fmt(double x);
bool ends_with(const std::string& s, const std::string& tail);
/// "balls_up, alphabets, …"
std::string registry_names();
/// The scene named on the command line, with the command line's overrides applied
/// (main.cpp); throws UsageError.
engine::SceneDesc resolve_scene(const Args& a, const CLI::App& app);
/// What a run does besides its scene: magsim-scene's flags (main.cpp) or magsim.run's
/// arguments (tools/python/).
struct RunPlan {
  std::string source = "registry";  ///< the scene file or "registry": summary.json "source"; outputs never overwrite a *.json source
  int count = 0;                    ///< summary.json "params"
  double strength = 1.0;
  long steps = 0;                   ///< > 0: this many rigid steps
  double seconds = 0.0;             ///< > 0 (and steps = 0): this long; neither: the scene's default_seconds
  std::string out;                  ///< the output folder; "" = out/<scene>_<method>
  double fps = 60.0;
  bool render = true;
  bool arrows = false;
  int width = 1280, height = 720, samples = 1;
  std::string gltf;           ///< "" or the binary glTF file to write (gltf_output.hpp)
  std::string gltf_channels;  ///< per-body channels of that file, comma-separated
  /// Polled before each step: a signal number ends the run as that signal would (whole rows,
  /// summary.json "interrupted"). Unset: SIGINT, SIGTERM and SIGHUP are caught for the run.
  std::function<int()> stop;
  /// When set, receives the one-line error of a failed run (exit 2 or 3).
  std::string* error = nullptr;
};
/// The run: summary.json, states.csv, moments.csv and frames into plan.out (run.cpp). Returns
/// the exit code (kRunFailed: a SimulationError; kIoError; 128 + a stop signal); throws
/// UsageError and IoError as magsim-scene's exit 1 and 3.
int run_scene(const engine::SceneDesc& scene, const RunPlan& plan);
/// The scene as --write-scene writes it: the scene file's JSON, one space a level, a final newline.
std::string scene_file_text(const engine::SceneDesc& scene);
/// The run the command line names (main.cpp).
int run(const Args& a, const CLI::App& app);
/// --write-scene FILE (main.cpp).
int write_scene(const Args& a, const CLI::App& app);

}  // namespace magsim::scene_tool
