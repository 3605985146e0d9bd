// tools/paper/speed.cpp — speed against accuracy on crystal_balls (weak and strong): e_M against
// cumulative wall time per dynamics and per Newton step; Δt_m against iterations to e_M ≤ 1e-4.
#include "tools/paper/experiments.hpp"

#include <cstdio>
#include <fstream>

namespace magsim::experiments {

int run_speed(const SpeedOpts& o) {
  ensure_dir(o.out);
  std::ofstream csv(o.out + "/speed_accuracy.csv");
  csv << "magnet,method,iteration,wall_ms,e_M\n";
  std::ofstream dtcsv(o.out + "/dt_iterations.csv");
  dtcsv << "magnet,method,dt_ns,iterations_to_1e-4\n";
  for (const auto& [label, strength] : {std::pair<std::string, double>{"weak", 0.05}, {"strong", 1.0}}) {
    const mag::MomentSet base = crystal(strength);
    const NewtonTrace newton = newton_trace(base, mag::Curve::Tanh, {}, o.repeat);
    mag::MomentSet gt_kim = base;
    mag::solve_exact(&gt_kim, mag::Curve::Kim, {});
    const std::vector<Vec3>& gt_tanh = newton.solution.M;
    speed_curves(csv, label, base, method_runs(dynamics_methods(), o.iters), gt_tanh, gt_kim.M,
                 o.repeat);
    newton_rows(csv, label, newton, gt_tanh);
    mag::MagWorkspace ws;
    for (mag::Method m : dynamics_methods()) {
      const auto& gt = mag::curve_of(m) == mag::Curve::Kim ? gt_kim.M : gt_tanh;
      for (double dt_ns : {30.0, 50.0, 75.0, 100.0, 125.0, 150.0, 175.0, 200.0}) {
        mag::MomentSet t = base;
        const mag::DynamicsOptions dd = window(m, o.iters, dt_ns * 1e-9);
        int first = -1;
        mag::relax_magnetization(&t, dd, &ws, [&](int k, const mag::MomentSet& cur) {
          if (first < 0 && mag::magnetization_error(cur, gt) <= 1e-4) first = k;
        });
        dtcsv << label << ',' << mag::method_name(m) << ',' << dt_ns << ',' << first << '\n';
      }
    }
  }
  std::printf("speed: wrote %s/speed_accuracy.csv and dt_iterations.csv\n", o.out.c_str());
  return 0;
}

}  // namespace magsim::experiments
