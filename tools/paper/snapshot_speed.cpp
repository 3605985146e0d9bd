// tools/paper/snapshot_speed.cpp — speed against accuracy on the sakura_tree snapshot, and the
// Barnes–Hut field error against its time per evaluation.
#include "tools/paper/experiments.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace magsim::experiments {

// Speed against accuracy on the sakura_tree snapshot: e_M against cumulative wall time per
// method (from the warm start and from M = 0) and per Newton step; ours-realigned with the
// Barnes–Hut field; and the Barnes–Hut field's error against its time per evaluation.
int run_snapshot_speed(const SnapshotSpeedOpts& o) {
  ensure_dir(o.out);
  const auto t_all = Clock::now();
  Snapshot sn = sakura_snapshot(o.snap, o.out);
  const GroundTruth gt = snapshot_ground_truth(&sn);
  const std::vector<Vec3>& gt_tanh = gt.tanh.solution.M;
  json summary = {{"snapshot", sn.info}, {"iters", o.iters}};
  std::ofstream csv(o.out + "/speed_sakura.csv");
  csv << "magnet,method,iteration,wall_ms,e_M\n";
  const std::vector<double> thetas = parse_doubles(o.thetas, "--thetas");
  std::vector<SpeedRun> runs = method_runs(dynamics_methods(), o.iters, sn.dyn.field);
  for (double th : thetas) {
    SpeedRun r{"ours-realigned+bh" + json(th).dump(), window(mag::Method::OursRealigned, o.iters)};
    r.opt.field = sn.dyn.field;
    r.opt.field.solver = mag::FieldSolver::BarnesHut;
    r.opt.field.bh_theta = th;
    runs.push_back(r);
  }
  mag::MomentSet cold = sn.warm;
  cold.reset_magnetization();
  summary["ms_per_sweep"]["warm"] = speed_curves(csv, "warm", sn.warm, runs, gt_tanh, gt.kim.M, o.repeat);
  newton_rows(csv, "warm", gt.tanh, gt_tanh);
  summary["ms_per_sweep"]["cold"] = speed_curves(csv, "cold", cold, runs, gt_tanh, gt.kim.M, o.repeat);
  const NewtonTrace newton_cold = newton_trace(cold, mag::Curve::Tanh, sn.dyn.field);
  newton_rows(csv, "cold", newton_cold, gt_tanh);
  summary["newton"] = {{"warm", {{"steps", gt.tanh.ms.size()}, {"ms", gt.tanh.ms.back()}}},
                       {"cold", {{"steps", newton_cold.ms.size()}, {"ms", newton_cold.ms.back()}}}};
  std::printf("newton: %zu steps, %.0f ms from the warm start; %zu steps, %.0f ms from M = 0\n",
              gt.tanh.ms.size(), gt.tanh.ms.back(), newton_cold.ms.size(), newton_cold.ms.back());

  // the Barnes–Hut field at the ground-truth magnetization against the direct sum
  std::ofstream bh(o.out + "/sakura_bh.csv");
  bh << "solver,theta,ms_per_eval,rms_rel_err,max_rel_err\n";
  const mag::MomentSet& s = gt.tanh.solution;
  std::vector<Vec3> H_ref;
  auto time_field = [&](const mag::FieldOptions& f, std::vector<Vec3>* H) {
    mag::FieldWorkspace ws;
    std::vector<double> ms;
    for (int r = 0; r < o.field_repeat + 1; ++r) {  // the first builds the workspace: not timed
      const auto t0 = Clock::now();
      mag::compute_fields(s, f, H, nullptr, &ws);
      if (r > 0) ms.push_back(ms_since(t0));
    }
    return median(ms);
  };
  mag::FieldOptions direct = sn.dyn.field;
  direct.solver = mag::FieldSolver::Direct;
  const double direct_ms = time_field(direct, &H_ref);
  bh << "direct,0," << direct_ms << ",0,0\n";
  summary["field"].push_back({{"solver", "direct"}, {"ms_per_eval", direct_ms}});
  std::printf("field: direct %.3f ms per evaluation (%zu moments)\n", direct_ms, s.size());
  for (double th : thetas) {
    mag::FieldOptions f = direct;
    f.solver = mag::FieldSolver::BarnesHut;
    f.bh_theta = th;
    std::vector<Vec3> H;
    const double ms = time_field(f, &H);
    double num = 0, den = 0, mx = 0;
    for (std::size_t j = 0; j < s.size(); ++j) {
      const double d = (H[j] - H_ref[j]).norm(), h = H_ref[j].norm();
      num += d * d;
      den += h * h;
      if (h > 0) mx = std::max(mx, d / h);
    }
    const double rms = den > 0 ? std::sqrt(num / den) : 0.0;
    bh << "barnes-hut," << th << ',' << ms << ',' << rms << ',' << mx << '\n';
    summary["field"].push_back({{"solver", "barnes-hut"}, {"theta", th}, {"ms_per_eval", ms},
                                {"rms_rel_err", rms}, {"max_rel_err", mx}});
    std::printf("field: barnes-hut θ = %.2f: %.3f ms per evaluation, relative error RMS %.2e, "
                "max %.2e\n", th, ms, rms, mx);
  }
  summary["seconds"] = ms_since(t_all) / 1000;
  std::ofstream(o.out + "/snapshot_speed.json") << summary.dump(2) << "\n";
  std::printf("snapshot-speed: wrote %s/speed_sakura.csv, sakura_bh.csv, snapshot_speed.json "
              "(%.1f s)\n", o.out.c_str(), ms_since(t_all) / 1000);
  return 0;
}

}  // namespace magsim::experiments
