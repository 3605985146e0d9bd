// tools/paper/main.cpp — the paper's magnetics experiments as data (CSV/JSON), and the
// speed-against-accuracy measurements beyond the paper. Charts: tools/scripts/charts.py.
//
//   experiments fig8     e_M per iteration on crystal_balls, weak and strong magnet (Fig. 8)
//                        and the uniqueness figure of §6.3
//   experiments fig9     the stability map over Δt × |H| (Fig. 9), shardable
//   experiments fig10    force magnitude near a uniformly magnetized sphere (Fig. 10)
//   experiments speed    e_M against wall time per method and for the Newton solver; Δt_m
//                        against iterations
//   experiments tolerance       convergence tolerance against force error on a sakura_tree
//                               snapshot and against balls_up's outcome
//   experiments snapshot-speed  e_M against wall time on a sakura_tree snapshot; Barnes–Hut
//                               field error against time per evaluation
#include "tools/paper/experiments.hpp"

#include <cstdio>

using namespace magsim::experiments;

int main(int argc, char** argv) {
  CLI::App app{"experiments — the paper's magnetics figures as data (Figs. 8, 9, 10, §6.3) and "
               "speed against accuracy. Charts: python3 tools/scripts/charts.py OUT_DIR"};
  app.require_subcommand(1);
  Fig8Opts f8;
  auto* c8 = app.add_subcommand("fig8", "e_M per iteration on crystal_balls, weak and strong (Fig. 8); uniqueness (§6.3)");
  c8->add_option("--out", f8.out, "output directory")->capture_default_str();
  c8->add_option("--iters", f8.iters, "iterations per run")->check(CLI::PositiveNumber)->capture_default_str();
  c8->add_option("--weak", f8.weak, "strength factor of the weak bar magnet")->check(CLI::PositiveNumber)->capture_default_str();
  c8->add_option("--strong", f8.strong, "strength factor of the strong bar magnet")->check(CLI::PositiveNumber)->capture_default_str();
  c8->add_option("--methods", f8.methods, "comma list or all")->capture_default_str();
  Fig9Opts f9;
  auto* c9 = app.add_subcommand("fig9", "stability map over Δt × |H| (Fig. 9); paper resolution: --dt-steps 51 --h-steps 1001 --dirs 10000");
  c9->add_option("--out", f9.out, "output directory")->capture_default_str();
  c9->add_option("--dt-steps", f9.dt_steps, "Δt values, 100 ns × 1.00 … 1.50")->check(CLI::PositiveNumber)->capture_default_str();
  c9->add_option("--h-steps", f9.h_steps, "|H| values, 0 … 10 |M|")->check(CLI::PositiveNumber)->capture_default_str();
  c9->add_option("--dirs", f9.dirs, "random H directions per cell")->check(CLI::PositiveNumber)->capture_default_str();
  c9->add_option("--shard", f9.shard, "i/n: compute every n-th cell starting at i")->capture_default_str();
  c9->add_option("--methods", f9.methods, "comma list or all")->capture_default_str();
  c9->add_option("--tol", f9.tol, "converged when e_M < tol")->check(CLI::PositiveNumber)->capture_default_str();
  Fig10Opts f10;
  auto* c10 = app.add_subcommand("fig10", "force magnitude near a uniformly magnetized sphere (Fig. 10)");
  c10->add_option("--out", f10.out, "output directory")->capture_default_str();
  c10->add_option("--n", f10.n, "grid points per side")->check(CLI::Range(3, 2001))->capture_default_str();
  SpeedOpts sp;
  auto* cs = app.add_subcommand("speed", "e_M against wall time per method and for Newton; Δt_m against iterations");
  cs->add_option("--out", sp.out, "output directory")->capture_default_str();
  cs->add_option("--iters", sp.iters, "iterations per run")->check(CLI::PositiveNumber)->capture_default_str();
  cs->add_option("--repeat", sp.repeat, "timing repeats (median)")->check(CLI::PositiveNumber)->capture_default_str();
  ToleranceOpts to;
  auto* ct = app.add_subcommand(
      "tolerance", "convergence tolerance against force error on a sakura_tree snapshot, and "
                   "against a scene's outcome (beyond the paper)");
  ct->add_option("--out", to.out, "output directory")->capture_default_str();
  add_option(ct, &to.snap);
  ct->add_option("--methods", to.methods, "comma list or all, relaxed on the snapshot")->capture_default_str();
  ct->add_option("--tols", to.tols, "comma list of tolerances (max_j |M_j − f(H_j)|/Ms_j)")->capture_default_str();
  ct->add_option("--max-iter", to.max_iter, "iteration cap per relaxation on the snapshot")->check(CLI::PositiveNumber)->capture_default_str();
  ct->add_option("--repeat", to.repeat, "timing repeats per relaxation (median)")->check(CLI::PositiveNumber)->capture_default_str();
  ct->add_flag("--cold,!--no-cold", to.cold, "also relax from M = 0, besides the engine's warm start (default: on)");
  ct->add_option("--outcome-scene", to.outcome_scene, "registry scene run with ours-realigned at each --outcome-tols")->capture_default_str();
  ct->add_option("--outcome-seconds", to.outcome_seconds, "simulated time of each outcome run (s)")->check(CLI::PositiveNumber)->capture_default_str();
  ct->add_option("--outcome-tols", to.outcome_tols, "comma list of tolerances for the outcome runs")->capture_default_str();
  SnapshotSpeedOpts ss;
  auto* css = app.add_subcommand(
      "snapshot-speed", "e_M against wall time per method and per Newton step on a sakura_tree "
                        "snapshot; Barnes–Hut field error against time (beyond the paper)");
  css->add_option("--out", ss.out, "output directory")->capture_default_str();
  add_option(css, &ss.snap);
  css->add_option("--iters", ss.iters, "sweeps per dynamics run")->check(CLI::PositiveNumber)->capture_default_str();
  css->add_option("--repeat", ss.repeat, "timing repeats per dynamics run (median)")->check(CLI::PositiveNumber)->capture_default_str();
  css->add_option("--thetas", ss.thetas, "comma list of Barnes–Hut opening angles θ")->capture_default_str();
  css->add_option("--field-repeat", ss.field_repeat, "timed field evaluations per solver (median)")->check(CLI::PositiveNumber)->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    if (*c8) return run_fig8(f8);
    if (*c9) return run_fig9(f9);
    if (*c10) return run_fig10(f10);
    if (*cs) return run_speed(sp);
    if (*ct) return run_tolerance(to);
    if (*css) return run_snapshot_speed(ss);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "experiments: %s\n", e.what());
    return 1;
  }
  return 0;
}

