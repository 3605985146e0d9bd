// tools/experiments.cpp — the paper's magnetics experiments as data (CSV/JSON), and the
// speed-against-accuracy measurements beyond the paper. Charts: tools/charts.py.
//
//   experiments fig8     e_M per iteration on crystal_balls, weak and strong magnet (Fig. 8)
//                        and the uniqueness figure of §6.3
//   experiments fig9     the stability map over Δt × |H| (Fig. 9), shardable
//   experiments fig10    force magnitude near a uniformly magnetized sphere (Fig. 10)
//   experiments speed    e_M against wall time per method and for the Newton solver; Δt_m
//                        against iterations
#include "magnetics/curves.hpp"
#include "magnetics/forces.hpp"
#include "magnetics/ground_truth.hpp"
#include "scenes/moment_set.hpp"
#include "scenes/registry.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <map>
#include <sstream>

namespace mag = magsim::mag;
using mag::Vec3;
using nlohmann::json;

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// The dynamics compared in the charts (Exact is the reference; Anderson appears when
/// the build has it).
std::vector<mag::Method> dynamics_methods() {
  std::vector<mag::Method> v = {mag::Method::Ours, mag::Method::OursRealigned,
                                mag::Method::Kim2018, mag::Method::DampingLLG};
  mag::Method a;
  if (mag::parse_method("anderson", &a)) v.push_back(a);
  return v;
}

std::vector<mag::Method> parse_methods(const std::string& list) {
  if (list == "all") return dynamics_methods();
  std::vector<mag::Method> v;
  std::stringstream ss(list);
  std::string name;
  while (std::getline(ss, name, ',')) {
    mag::Method m;
    if (!mag::parse_method(name, &m)) throw CLI::ValidationError("--methods", "unknown method " + name);
    v.push_back(m);
  }
  return v;
}

/// Options that run exactly `iters` sweeps of method m (tol unreachable: the window is
/// fixed, e_M is what the experiments record).
mag::DynamicsOptions window(mag::Method m, int iters, double dt = 100e-9) {
  mag::DynamicsOptions d;
  d.method = m;
  d.dt = dt;
  d.max_iter = iters;
  d.tol = 1e-300;
  return d;
}

mag::MomentSet crystal(double strength) {
  magsim::scenes::SceneParams p;
  p.strength = strength;
  return magsim::scenes::moment_set_at_rest(magsim::scenes::find_scene("crystal_balls")->build(p));
}

void ensure_dir(const std::string& d) {
  std::error_code ec;
  std::filesystem::create_directories(d, ec);
  if (ec) throw std::runtime_error("cannot create " + d + ": " + ec.message());
}

// ---------------------------------------------------------------------------------------
// Fig. 8 and §6.3
struct Fig8Opts {
  std::string out = "out/report";
  int iters = 999;
  double weak = 0.05, strong = 1.0;  // crystal_balls strengths
  std::string methods = "all";
};

int run_fig8(const Fig8Opts& o) {
  ensure_dir(o.out);
  std::ofstream csv(o.out + "/fig8.csv");
  csv << "magnet,method,iteration,e_M\n";
  json summary;
  std::map<std::string, std::vector<Vec3>> final_weak;
  for (const auto& [label, strength] : {std::pair<std::string, double>{"weak", o.weak},
                                        {"strong", o.strong}}) {
    const mag::MomentSet base = crystal(strength);
    mag::MomentSet gt_tanh = base, gt_kim = base;
    mag::solve_exact(&gt_tanh, mag::Curve::Tanh, {});
    mag::solve_exact(&gt_kim, mag::Curve::Kim, {});
    double hmax = 0;
    {
      mag::MagWorkspace w;
      mag::compute_fields(gt_tanh, {}, &w.H, nullptr, &w.field);
      for (std::size_t j = 0; j < base.size(); ++j)
        if (base.kind[j] == mag::MomentKind::Induced) hmax = std::max(hmax, w.H[j].norm() / base.Ms[j]);
    }
    summary[label]["strength"] = strength;
    summary[label]["max_H_over_Ms"] = hmax;
    for (mag::Method m : parse_methods(o.methods)) {
      mag::MomentSet s = base;
      const mag::DynamicsOptions d = window(m, o.iters);
      mag::MagWorkspace ws;
      const auto& gt = mag::curve_of(m) == mag::Curve::Kim ? gt_kim.M : gt_tanh.M;
      int first4 = -1, first6 = -1;
      double e = 0;
      mag::relax_magnetization(&s, d, &ws, [&](int k, const mag::MomentSet& cur) {
        e = mag::magnetization_error(cur, gt);
        csv << label << ',' << mag::method_name(m) << ',' << k << ',' << e << '\n';
        if (first4 < 0 && e <= 1e-4) first4 = k;
        if (first6 < 0 && e <= 1e-6) first6 = k;
      });
      json r = {{"final_e_M", e}, {"iterations_to_1e-4", first4}, {"iterations_to_1e-6", first6}};
      summary[label]["methods"][mag::method_name(m)] = r;
      std::printf("fig8 %-6s %-15s e_M ≤ 1e-4 at %4d, ≤ 1e-6 at %4d, final %.3e\n",
                  label.c_str(), mag::method_name(m), first4, first6, e);
      if (label == "weak") final_weak[mag::method_name(m)] = s.M;
    }
  }
  // §6.3 uniqueness: per ball |M_K − M_O| / |M_K|, weak magnet
  if (final_weak.count("kim2018") && final_weak.count("ours")) {
    const mag::MomentSet base = crystal(o.weak);
    for (const char* ours : {"ours", "ours-realigned"}) {
      if (!final_weak.count(ours)) continue;
      double sum = 0, mx = 0;
      int n = 0;
      for (std::size_t j = 0; j < base.size(); ++j) {
        if (base.kind[j] != mag::MomentKind::Induced) continue;
        const Vec3& K = final_weak["kim2018"][j];
        const double d = (K - final_weak[ours][j]).norm() / K.norm();
        sum += d;
        mx = std::max(mx, d);
        ++n;
      }
      summary["uniqueness"][ours] = {{"mean", sum / n}, {"max", mx}, {"paper_mean", 0.0008}};
      std::printf("uniqueness (weak magnet) |M_K − M_%s|/|M_K|: mean %.3e, max %.3e (paper 8e-4)\n",
                  ours, sum / n, mx);
    }
  }
  {
    // the floor of that comparison: the two curves' own ground truths (eq. 7 against eq. 10)
    mag::MomentSet gk = crystal(o.weak), go = gk;
    mag::solve_exact(&gk, mag::Curve::Kim, {});
    mag::solve_exact(&go, mag::Curve::Tanh, {});
    double sum = 0, mx = 0;
    int n = 0;
    for (std::size_t j = 0; j < gk.size(); ++j) {
      if (gk.kind[j] != mag::MomentKind::Induced) continue;
      const double d = (gk.M[j] - go.M[j]).norm() / gk.M[j].norm();
      sum += d;
      mx = std::max(mx, d);
      ++n;
    }
    summary["uniqueness"]["ground_truths"] = {{"mean", sum / n}, {"max", mx}};
    std::printf("uniqueness floor: eq. 7 vs eq. 10 ground truths differ by mean %.3e, max %.3e\n",
                sum / n, mx);
  }
  std::ofstream(o.out + "/fig8.json") << summary.dump(2) << "\n";
  return 0;
}

// ---------------------------------------------------------------------------------------
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

int run_fig9(const Fig9Opts& o) {
  ensure_dir(o.out);
  int shard_i = 0, shard_n = 1;
  if (std::sscanf(o.shard.c_str(), "%d/%d", &shard_i, &shard_n) != 2 || shard_n < 1 ||
      shard_i < 0 || shard_i >= shard_n)
    throw CLI::ValidationError("--shard", "must be i/n with 0 <= i < n, got " + o.shard);
  const std::string suffix = shard_n > 1 ? "_shard" + std::to_string(shard_i) + "of" + std::to_string(shard_n) : "";
  json summary;
  for (mag::Method m : parse_methods(o.methods)) {
    const long cells = static_cast<long>(o.dt_steps) * o.h_steps;
    std::vector<double> mean(cells, -1);
    std::vector<int> fails(cells, 0);
    const auto t0 = Clock::now();
#pragma omp parallel for schedule(dynamic, 4)
    for (long c = 0; c < cells; ++c) {
      if (c % shard_n != shard_i) continue;
      const int i = static_cast<int>(c / o.h_steps), j = static_cast<int>(c % o.h_steps);
      const double dtm = o.dt_steps > 1 ? 1.0 + 0.5 * i / (o.dt_steps - 1) : 1.0;
      const double s = o.h_steps > 1 ? 10.0 * j / (o.h_steps - 1) : 1.0;
      fails[c] = fig9_cell(m, 100e-9 * dtm, s, o.dirs, o.tol, 0x9E3779B97F4A7C15ull * (c + 1), &mean[c]);
    }
    const std::string path = o.out + "/fig9_" + mag::method_name(m) + suffix + ".csv";
    std::ofstream csv(path);
    csv << "dt_mult,h_mult,mean_iterations,failed_directions,directions\n";
    long done = 0, ok = 0;
    double sum_iters = 0;
    for (long c = 0; c < cells; ++c) {
      if (mean[c] < 0) continue;
      const int i = static_cast<int>(c / o.h_steps), j = static_cast<int>(c % o.h_steps);
      const double dtm = o.dt_steps > 1 ? 1.0 + 0.5 * i / (o.dt_steps - 1) : 1.0;
      const double s = o.h_steps > 1 ? 10.0 * j / (o.h_steps - 1) : 1.0;
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

// ---------------------------------------------------------------------------------------
// Fig. 10: a uniformly magnetized sphere (radius 1 cm, NdFeB 1e6 A/m, moment along z) at the
// origin; an iron ball (radius 2 mm) at each point of the x–z cross-section outside it.
struct Fig10Opts {
  std::string out = "out/report";
  int n = 121;
};

int run_fig10(const Fig10Opts& o) {
  ensure_dir(o.out);
  const double R = 0.01, a = 0.002, Ms = 1.6e6;
  const double Vs = 4.0 / 3.0 * mag::kPi * R * R * R, Va = 4.0 / 3.0 * mag::kPi * a * a * a;
  const Vec3 m(0, 0, 1e6 * Vs);  // outside, a uniformly magnetized sphere's field is a dipole's
  std::ofstream csv(o.out + "/fig10.csv");
  csv << "x,z,F_ours,F_kim\n";
  const double L = 0.03;
  double max_ratio = 0, min_ratio = 1e300;
  for (int i = 0; i < o.n; ++i) {
    for (int k = 0; k < o.n; ++k) {
      const Vec3 p(-L + 2 * L * i / (o.n - 1), 0, -L + 2 * L * k / (o.n - 1));
      if (p.norm() < R + a) {
        csv << p.x() << ',' << p.z() << ",nan,nan\n";
        continue;
      }
      const Vec3 H = mag::dipole_field(p, m);
      const mag::Mat3 J = mag::dipole_jacobian(p, m);
      // ours: M = f(H) (eq. 10), Zeeman force (eq. 4); Kim 2018: M by eq. 7, classic (eq. 13)
      const Vec3 Mo = mag::curve_M(mag::Curve::Tanh, H, Ms);
      const Vec3 Mk = mag::curve_M(mag::Curve::Kim, H, Ms);
      const double Fo = mag::zeeman_force(mag::Curve::Tanh, Va, Ms, Mo, H, J).norm();
      const double Fk = mag::classic_force(Va * Mk, J).norm();
      csv << p.x() << ',' << p.z() << ',' << Fo << ',' << Fk << '\n';
      max_ratio = std::max(max_ratio, Fo / Fk);
      min_ratio = std::min(min_ratio, Fo / Fk);
    }
  }
  json j = {{"sphere_radius", R}, {"ball_radius", a}, {"ratio_ours_over_kim_min", min_ratio},
            {"ratio_ours_over_kim_max", max_ratio}};
  std::ofstream(o.out + "/fig10.json") << j.dump(2) << "\n";
  std::printf("fig10: |F_ours|/|F_kim| ranges %.3f … %.3f over the cross-section\n", min_ratio,
              max_ratio);
  return 0;
}

// ---------------------------------------------------------------------------------------
// Speed against accuracy on crystal_balls (weak and strong): e_M against cumulative wall time
// for every dynamics, and the Newton solver at a ladder of tolerances; Δt_m against
// iterations to e_M ≤ 1e-4.
struct SpeedOpts {
  std::string out = "out/report";
  int iters = 999;
  int repeat = 3;
};

int run_speed(const SpeedOpts& o) {
  ensure_dir(o.out);
  std::ofstream csv(o.out + "/speed_accuracy.csv");
  csv << "magnet,method,iteration,wall_ms,e_M\n";
  std::ofstream dtcsv(o.out + "/dt_iterations.csv");
  dtcsv << "magnet,method,dt_ns,iterations_to_1e-4\n";
  for (const auto& [label, strength] : {std::pair<std::string, double>{"weak", 0.05}, {"strong", 1.0}}) {
    const mag::MomentSet base = crystal(strength);
    mag::MomentSet gt_tanh = base, gt_kim = base;
    mag::solve_exact(&gt_tanh, mag::Curve::Tanh, {});
    mag::solve_exact(&gt_kim, mag::Curve::Kim, {});
    for (mag::Method m : dynamics_methods()) {
      const auto& gt = mag::curve_of(m) == mag::Curve::Kim ? gt_kim.M : gt_tanh.M;
      // wall time per sweep: median over repeats of a run without the e_M bookkeeping
      std::vector<double> per_sweep;
      for (int r = 0; r < o.repeat; ++r) {
        mag::MomentSet s = base;
        const mag::DynamicsOptions d = window(m, o.iters);
        mag::MagWorkspace ws;
        const auto t0 = Clock::now();
        mag::relax_magnetization(&s, d, &ws);
        per_sweep.push_back(ms_since(t0) / o.iters);
      }
      std::sort(per_sweep.begin(), per_sweep.end());
      const double sweep_ms = per_sweep[per_sweep.size() / 2];
      mag::MomentSet s = base;
      const mag::DynamicsOptions d = window(m, o.iters);
      mag::MagWorkspace ws;
      mag::relax_magnetization(&s, d, &ws, [&](int k, const mag::MomentSet& cur) {
        csv << label << ',' << mag::method_name(m) << ',' << k << ',' << k * sweep_ms << ','
            << mag::magnetization_error(cur, gt) << '\n';
      });
      for (double dt_ns : {30.0, 50.0, 75.0, 100.0, 125.0, 150.0, 175.0, 200.0}) {
        mag::MomentSet t = base;
        const mag::DynamicsOptions dd = window(m, o.iters, dt_ns * 1e-9);
        int first = -1;
        mag::relax_magnetization(&t, dd, &ws, [&](int k, const mag::MomentSet& cur) {
          if (first < 0 && mag::magnetization_error(cur, gt) <= 1e-4) first = k;
        });
        dtcsv << label << ',' << mag::method_name(m) << ',' << dt_ns << ',' << first << '\n';
      }
      std::printf("speed %-6s %-15s %.4f ms per sweep\n", label.c_str(), mag::method_name(m), sweep_ms);
    }
    // the Newton ground-truth solver: time and e_M for a ladder of tolerances
    for (double tol : {1e-1, 1e-2, 1e-4, 1e-6, 1e-9, 1e-12}) {
      std::vector<double> times;
      mag::MomentSet s = base;
      for (int r = 0; r < o.repeat; ++r) {
        s = base;
        const auto t0 = Clock::now();
        mag::solve_exact(&s, mag::Curve::Tanh, {}, tol);
        times.push_back(ms_since(t0));
      }
      std::sort(times.begin(), times.end());
      csv << label << ",exact," << -1 << ',' << times[times.size() / 2] << ','
          << mag::magnetization_error(s, gt_tanh.M) << '\n';
    }
  }
  std::printf("speed: wrote %s/speed_accuracy.csv and dt_iterations.csv\n", o.out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"experiments — the paper's magnetics figures as data (Figs. 8, 9, 10, §6.3) and "
               "speed against accuracy. Charts: python3 tools/charts.py OUT_DIR"};
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
  CLI11_PARSE(app, argc, argv);
  try {
    if (*c8) return run_fig8(f8);
    if (*c9) return run_fig9(f9);
    if (*c10) return run_fig10(f10);
    if (*cs) return run_speed(sp);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "experiments: %s\n", e.what());
    return 1;
  }
  return 0;
}
