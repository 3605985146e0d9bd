// tools/paper/experiments.hpp — what the experiment programs share: the helpers of
// every figure (methods, the crystal_balls moment set, fixed windows of sweeps, medians), the
// speed-against-accuracy machinery, the sakura_tree snapshot, and one options struct and
// run_* entry per subcommand (one file each: fig8.cpp, fig9.cpp, fig10.cpp, speed.cpp,
// tolerance.cpp, snapshot_speed.cpp; the command line in main.cpp).
#pragma once

#include "engine/simulation.hpp"
#include "magnetics/curves.hpp"
#include "magnetics/forces.hpp"
#include "magnetics/ground_truth.hpp"
#include "scenes/moment_set.hpp"
#include "scenes/registry.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <map>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace magsim::experiments {

namespace mag = magsim::mag;
using mag::Vec3;
using nlohmann::json;

using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// ---- helpers (common.cpp) ---------------------------------------------------------------
/// The dynamics compared in the charts (Exact is the reference; Anderson appears when
/// the build has it).
std::vector<mag::Method> dynamics_methods();
/// "all" or a comma list of method names.
std::vector<mag::Method> parse_methods(const std::string& list);
/// Options that run exactly `iters` sweeps of method m (tol unreachable: the window is
/// fixed, e_M is what the experiments record).
mag::DynamicsOptions window(mag::Method m, int iters, double dt = 100e-9);
/// crystal_balls at rest with its bar magnet at `strength`.
mag::MomentSet crystal(double strength);
void ensure_dir(const std::string& d);
double median(std::vector<double> v);
/// A comma list of numbers (a bad one names `flag`).
std::vector<double> parse_doubles(const std::string& list, const std::string& flag);

/// Mean and max over the induced moments of `kinds` of |ref_j − other_j| / |ref_j|.
struct RelativeDifference {
  double mean = 0, max = 0;
};
RelativeDifference relative_difference(const mag::MomentSet& kinds, const std::vector<Vec3>& ref,
                                       const std::vector<Vec3>& other);

// ---- speed against accuracy (common.cpp): e_M against cumulative wall time -------------
/// One dynamics run of a speed chart: its name in the CSV and its options.
struct SpeedRun {
  std::string name;
  mag::DynamicsOptions opt;
};

/// A run per method: `iters` fixed sweeps with the field options `field`.
std::vector<SpeedRun> method_runs(const std::vector<mag::Method>& methods, int iters,
                                  const mag::FieldOptions& field = {});
/// For every run, rows "label,name,k,wall_ms,e_M" (k = 1 … opt.max_iter) from `start`;
/// e_M against the ground truth of the run's curve. Wall time per sweep: median over
/// `repeat` runs without the e_M bookkeeping. Returns name → ms per sweep.
std::map<std::string, double> speed_curves(std::ostream& csv, const std::string& label,
                                           const mag::MomentSet& start,
                                           const std::vector<SpeedRun>& runs,
                                           const std::vector<Vec3>& gt_tanh,
                                           const std::vector<Vec3>& gt_kim, int repeat);

/// The Newton ground-truth solver run one step at a time from `start`: the solution and,
/// per Newton step, the cumulative wall time (median over `repeat`) and the iterate.
struct NewtonTrace {
  mag::MomentSet solution;
  std::vector<double> ms;                ///< cumulative wall time after step k + 1
  std::vector<std::vector<Vec3>> iterate;
  bool converged = false;
};

NewtonTrace newton_trace(const mag::MomentSet& start, mag::Curve curve,
                         const mag::FieldOptions& field, int repeat = 1, double tol = 1e-12);
/// Rows "label,exact,-1,wall_ms,e_M" for every Newton step of `tr` against `gt`.
void newton_rows(std::ostream& csv, const std::string& label, const NewtonTrace& tr,
                 const std::vector<Vec3>& gt);

// ---- the sakura_tree snapshot (snapshot.cpp) ---------------------------------------------
// A sakura_tree snapshot: the scene stepped with ours-realigned until balls have landed on the
// tree's magnets and are strongly magnetized (shared by `tolerance` and `snapshot-speed`).
// At the scene's 1 ms rigid step the first balls to reach a branch-end magnet (t ≈ 0.12 s)
// are flung off at 10²–10⁴ m/s and the tree is bare by 0.5 s; at 0.2 ms a few hundred balls
// stay on it. The snapshot is cached in the output directory (both subcommands use it).
struct SnapshotOpts {
  int count = 1000;       // balls (the paper's scene: 2500; Newton is dense, O(count³))
  double seconds = 0.40;  // simulated time before the snapshot (s): balls on the tree magnets
  double dt = 1e-3;       // rigid step while stepping to it (s): the scene's
  bool reuse = true;      // load <out>/sakura_snapshot.json when it was made with these options
  int threads = 1;        // OpenMP threads of the magnetics (0 = all)
};

/// OpenMP threads from here on (0 = all: the count before anything changed it). A Simulation's
/// step keeps its own count to itself (engine/step.cpp), so this holds across steps.
void use_threads(int n);

struct Snapshot {
  /// Moment positions of rigid step k + 1 with the magnetization (and sub-pairs) of step k:
  /// the warm start the engine relaxes from in step k + 1.
  mag::MomentSet warm;
  mag::DynamicsOptions dyn;  ///< the scene's magnetization options (method ours-realigned)
  bool reaction_symmetric = false;
  json info;
};

/// --count, --seconds, --dt, --reuse, --threads of a snapshot subcommand.
void add_option(CLI::App* c, SnapshotOpts* s);
Snapshot sakura_snapshot(const SnapshotOpts& o, const std::string& out);

/// Ground truths of the snapshot (Newton from the warm start, to 1e-12): eq. 10 (with its
/// per-step trace) and eq. 7; the magnetization level goes into sn->info.
struct GroundTruth {
  NewtonTrace tanh;
  mag::MomentSet kim;
};

GroundTruth snapshot_ground_truth(Snapshot* sn);
/// Forces of the method's force model and curve on every moment of s.
std::vector<Vec3> forces_of(const mag::MomentSet& s, mag::Method m, const Snapshot& sn);
/// max_j and RMS_j of |F_j − F_gt,j| / max_j |F_gt,j| over induced moments.
std::pair<double, double> force_error(const mag::MomentSet& s, const std::vector<Vec3>& F,
                                      const std::vector<Vec3>& F_gt);

// ---- the subcommands, one file each ------------------------------------------------------
// Fig. 8 and §6.3
struct Fig8Opts {
  std::string out = "out/report";
  int iters = 999;
  double weak = 0.05, strong = 1.0;  // crystal_balls strengths
  std::string methods = "all";
};
int run_fig8(const Fig8Opts& o);

// Fig. 9: one moment, sub-magnetizations ±60° from a fixed axis (|M| = Ms/2), H = s·|M| in
// a random direction; iterations until e_M < 1e-3 (cap 999 = failure).
struct Fig9Opts {
  std::string out = "out/report";
  int dt_steps = 11;    // paper: 51 (Δt × 1.00, 1.01 … 1.50)
  int h_steps = 101;    // paper: 1001 (|H| = 0 … 10 |M|)
  int dirs = 64;        // paper: 10,000
  std::string shard = "0/1";
  std::string methods = "ours,ours-realigned,kim2018,damping-llg";
  double tol = 1e-3;
};
int run_fig9(const Fig9Opts& o);

// Fig. 10: a uniformly magnetized sphere (radius 1 cm, NdFeB 1e6 A/m, moment along z) at the
// origin; an iron ball (radius 2 mm) at each point of the x–z cross-section outside it.
struct Fig10Opts {
  std::string out = "out/report";
  int n = 121;
};
int run_fig10(const Fig10Opts& o);

// Speed against accuracy on crystal_balls (weak and strong): e_M against cumulative wall time
// for every dynamics and per Newton step (from M = 0); Δt_m against iterations to e_M ≤ 1e-4.
struct SpeedOpts {
  std::string out = "out/report";
  int iters = 999;
  int repeat = 3;
};
int run_speed(const SpeedOpts& o);

// Convergence tolerance against force error (on the sakura_tree snapshot) and against a
// scene's outcome (balls_up run with ours-realigned at each tolerance).
struct ToleranceOpts {
  std::string out = "out/report";
  SnapshotOpts snap;
  std::string methods = "ours,ours-realigned,kim2018,anderson";
  std::string tols = "1e-2,3e-3,1e-3,3e-4,1e-4,1e-5,1e-6";
  int max_iter = 999;
  int repeat = 3;
  bool cold = true;
  std::string outcome_scene = "balls_up";
  double outcome_seconds = 1.0;
  std::string outcome_tols = "1e-2,1e-3,1e-4,1e-5";
};
int run_tolerance(const ToleranceOpts& o);

// Speed against accuracy on the sakura_tree snapshot: e_M against cumulative wall time per
// method (from the warm start and from M = 0) and per Newton step; ours-realigned with the
// Barnes–Hut field; and the Barnes–Hut field's error against its time per evaluation.
struct SnapshotSpeedOpts {
  std::string out = "out/report";
  SnapshotOpts snap;
  int iters = 200;
  int repeat = 1;
  std::string thetas = "0.2,0.3,0.5,0.7";
  int field_repeat = 7;
};
int run_snapshot_speed(const SnapshotSpeedOpts& o);

}  // namespace magsim::experiments
