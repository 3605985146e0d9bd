// tools/cli/magsim_scene/magsim_scene.hpp — what the files of magsim-scene share: the
// command-line arguments, the errors that pick the exit code, and the entry points
// (main.cpp: flags and the scene they name; run.cpp: the run and --write-scene;
// outputs.hpp/.cpp: summary.json's parts, states.csv, moments.csv, frames).
#pragma once

#include "engine/scene_desc.hpp"
#include "tools/cli/cli_common.hpp"
#include "tools/cli/option_flags.hpp"

#include <CLI/CLI.hpp>

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
/// From this many bodies magsim-scene says what it is doing while it reads and builds.
constexpr double kProgressBodies = 20000;

std::string fmt(double x);
bool ends_with(const std::string& s, const std::string& tail);
/// "balls_up, alphabets, …"
std::string registry_names();
/// The scene named on the command line, with the command line's overrides applied
/// (main.cpp); throws UsageError.
engine::SceneDesc resolve_scene(const Args& a, const CLI::App& app);
/// The run: summary.json, states.csv, moments.csv and frames into --out (run.cpp).
int run(const Args& a, const CLI::App& app);
/// --write-scene FILE (run.cpp).
int write_scene(const Args& a, const CLI::App& app);

}  // namespace magsim::scene_tool
