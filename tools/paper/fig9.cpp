// tools/paper/fig9.cpp — Fig. 9: the stability map over Δt × |H|, shardable.
#include "tools/paper/experiments.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

namespace magsim::experiments {

// Fig. 9: one moment, sub-magnetizations ±60° from a fixed axis (|M| = Ms/2), H = s·|M| in
// a random direction; iterations until e_M < 1e-3 (cap 999 = failure).

namespace {

int fig9_cell(mag::Method m, double dt, double s, int dirs, double tol, std::uint64_t seed,
              double* mean_iters) {
  const double Ms = 1.6e6;
  mag::DynamicsOptions d;
  d.method = m;
  d.dt = dt;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  const Vec3 axis(0, 0, 1), perp(1, 0, 0);
  const double c60 = 0.5, s60 = std::sqrt(0.75);  // ±60° from the axis: |M| = Ms/2
  int failures = 0;
  double total = 0;
  for (int k = 0; k < dirs; ++k) {
    const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Vec3 H = s * 0.5 * Ms * dir;
    const Vec3 Mgt = mag::curve_M(mag::curve_of(m), H, Ms);
    const double den = std::max(Mgt.norm(), 1e-3 * Ms);  // H = 0: absolute, relative to Ms
    Vec3 M1 = Ms * (c60 * axis + s60 * perp), M2 = Ms * (c60 * axis - s60 * perp);
    int it = 0;
    for (it = 1; it <= 999; ++it) {
      const Vec3 Heff = mag::effective_field(m, d, H, 0.5 * (M1 + M2), Ms);
      mag::update_pair(m, d, Ms, Heff, &M1, &M2);
      if ((0.5 * (M1 + M2) - Mgt).norm() / den < tol) break;
    }
    if (it > 999) {
      it = 999;
      ++failures;
    }
    total += it;
  }
  *mean_iters = total / dirs;
  return failures;
}

/// Cell c of the map (row-major over Δt, then |H|): its Δt multiplier (1.00 … 1.50) and
/// |H|/|M| (0 … 10).
std::pair<double, double> grid_point(const Fig9Opts& o, long c) {
  const int i = static_cast<int>(c / o.h_steps), j = static_cast<int>(c % o.h_steps);
  const double dtm = o.dt_steps > 1 ? 1.0 + 0.5 * i / (o.dt_steps - 1) : 1.0;
  const double s = o.h_steps > 1 ? 10.0 * j / (o.h_steps - 1) : 1.0;
  return {dtm, s};
}

}  // namespace

int run_fig9(const Fig9Opts& o) {
  ensure_dir(o.out);
  int shard_i = 0, shard_n = 1;
  if (std::sscanf(o.shard.c_str(), "%d/%d", &shard_i, &shard_n) != 2 || shard_n < 1 ||
      shard_i < 0 || shard_i >= shard_n)
    throw CLI::ValidationError("--shard", "must be i/n with 0 <= i < n, got " + o.shard);
  const std::string suffix = shard_n > 1 ? "_shard" + std::to_string(shard_i) + "of" + std::to_string(shard_n) : "";
  json summary;
  for (mag::Method m : parse_methods(o.methods)) {
    if (m == mag::Method::Anderson) {  // its sweep is M ← f(H): no Δt, nothing to map
      std::printf("fig9 %-15s not on this map: no Δt dynamics (solves M = f(H(M)) directly)\n",
                  mag::method_name(m));
      continue;
    }
    const long cells = static_cast<long>(o.dt_steps) * o.h_steps;
    std::vector<double> mean(cells, -1);
    std::vector<int> fails(cells, 0);
    const auto t0 = Clock::now();
#pragma omp parallel for schedule(dynamic, 4)
    for (long c = 0; c < cells; ++c) {
      if (c % shard_n != shard_i) continue;
      const auto [dtm, s] = grid_point(o, c);
      fails[c] = fig9_cell(m, 100e-9 * dtm, s, o.dirs, o.tol, 0x9E3779B97F4A7C15ull * (c + 1), &mean[c]);
    }
    const std::string path = o.out + "/fig9_" + mag::method_name(m) + suffix + ".csv";
    std::ofstream csv(path);
    csv << "dt_mult,h_mult,mean_iterations,failed_directions,directions\n";
    long done = 0, ok = 0;
    double sum_iters = 0;
    for (long c = 0; c < cells; ++c) {
      if (mean[c] < 0) continue;
      const auto [dtm, s] = grid_point(o, c);
      csv << dtm << ',' << s << ',' << mean[c] << ',' << fails[c] << ',' << o.dirs << '\n';
      ++done;
      ok += fails[c] == 0;
      sum_iters += mean[c];
    }
    const double frac = done ? static_cast<double>(ok) / done : 0.0;
    summary[mag::method_name(m)] = {{"cells", done}, {"converged_cells", ok},
                                    {"converged_fraction", frac},
                                    {"mean_iterations", done ? sum_iters / done : 0.0},
                                    {"seconds", ms_since(t0) / 1000}};
    std::printf("fig9 %-15s %ld cells, %.1f %% converge in every direction, mean %.1f iterations (%.1f s)\n",
                mag::method_name(m), done, 100 * frac, done ? sum_iters / done : 0.0,
                ms_since(t0) / 1000);
  }
  summary["grid"] = {{"dt_steps", o.dt_steps}, {"h_steps", o.h_steps}, {"directions", o.dirs},
                     {"tol", o.tol}, {"shard", o.shard}};
  std::ofstream(o.out + "/fig9" + suffix + ".json") << summary.dump(2) << "\n";
  return 0;
}

}  // namespace magsim::experiments
