// tools/experiments.cpp — the paper's magnetics experiments as data (CSV/JSON), and the
// speed-against-accuracy measurements beyond the paper. Charts: tools/charts.py.
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
#include "engine/simulation.hpp"
#include "magnetics/curves.hpp"
#include "magnetics/forces.hpp"
#include "magnetics/ground_truth.hpp"
#include "scenes/moment_set.hpp"
#include "scenes/registry.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <omp.h>

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
// Speed against accuracy: e_M against cumulative wall time. Shared by `speed` (crystal_balls)
// and `snapshot-speed` (a sakura_tree snapshot).

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// One dynamics run of a speed chart: its name in the CSV and its options.
struct SpeedRun {
  std::string name;
  mag::DynamicsOptions opt;
};

/// A run per method: `iters` fixed sweeps with the field options `field`.
std::vector<SpeedRun> method_runs(const std::vector<mag::Method>& methods, int iters,
                                  const mag::FieldOptions& field = {}) {
  std::vector<SpeedRun> v;
  for (mag::Method m : methods) {
    SpeedRun r{mag::method_name(m), window(m, iters)};
    r.opt.field = field;
    v.push_back(r);
  }
  return v;
}

/// For every run, rows "label,name,k,wall_ms,e_M" (k = 1 … opt.max_iter) from `start`;
/// e_M against the ground truth of the run's curve. Wall time per sweep: median over
/// `repeat` runs without the e_M bookkeeping. Returns name → ms per sweep.
std::map<std::string, double> speed_curves(std::ostream& csv, const std::string& label,
                                           const mag::MomentSet& start,
                                           const std::vector<SpeedRun>& runs,
                                           const std::vector<Vec3>& gt_tanh,
                                           const std::vector<Vec3>& gt_kim, int repeat) {
  std::map<std::string, double> out;
  for (const SpeedRun& r : runs) {
    const auto& gt = mag::curve_of(r.opt.method) == mag::Curve::Kim ? gt_kim : gt_tanh;
    std::vector<double> per_sweep;
    for (int k = 0; k < repeat; ++k) {
      mag::MomentSet s = start;
      mag::MagWorkspace ws;
      const auto t0 = Clock::now();
      const mag::RelaxStats st = mag::relax_magnetization(&s, r.opt, &ws);
      per_sweep.push_back(ms_since(t0) / std::max(1, st.iterations));
    }
    const double sweep_ms = median(per_sweep);
    mag::MomentSet s = start;
    mag::MagWorkspace ws;
    mag::relax_magnetization(&s, r.opt, &ws, [&](int k, const mag::MomentSet& cur) {
      csv << label << ',' << r.name << ',' << k << ',' << k * sweep_ms << ','
          << mag::magnetization_error(cur, gt) << '\n';
    });
    std::printf("speed %-11s %-22s %.4f ms per sweep\n", label.c_str(), r.name.c_str(), sweep_ms);
    out[r.name] = sweep_ms;
  }
  return out;
}

/// The Newton ground-truth solver run one step at a time from `start`: the solution and,
/// per Newton step, the cumulative wall time (median over `repeat`) and the iterate.
struct NewtonTrace {
  mag::MomentSet solution;
  std::vector<double> ms;                ///< cumulative wall time after step k + 1
  std::vector<std::vector<Vec3>> iterate;
  bool converged = false;
};

NewtonTrace newton_trace(const mag::MomentSet& start, mag::Curve curve,
                         const mag::FieldOptions& field, int repeat = 1, double tol = 1e-12) {
  NewtonTrace tr;
  std::vector<std::vector<double>> step_ms;
  for (int r = 0; r < repeat; ++r) {
    mag::MomentSet s = start;
    for (int k = 0; k < 60; ++k) {
      const auto t0 = Clock::now();
      const mag::ExactStats st = mag::solve_exact(&s, curve, field, 0.0, 1);
      if (static_cast<int>(step_ms.size()) <= k) step_ms.emplace_back();
      step_ms[k].push_back(ms_since(t0));
      if (r == 0) tr.iterate.push_back(s.M);
      if (st.residual <= tol) {
        tr.converged = true;
        break;
      }
    }
    if (r == 0) tr.solution = s;
  }
  double cum = 0;
  for (std::size_t k = 0; k < tr.iterate.size(); ++k) tr.ms.push_back(cum += median(step_ms[k]));
  return tr;
}

/// Rows "label,exact,-1,wall_ms,e_M" for every Newton step of `tr` against `gt`.
void newton_rows(std::ostream& csv, const std::string& label, const NewtonTrace& tr,
                 const std::vector<Vec3>& gt) {
  mag::MomentSet s = tr.solution;
  for (std::size_t k = 0; k < tr.iterate.size(); ++k) {
    s.M = tr.iterate[k];
    csv << label << ",exact," << -1 << ',' << tr.ms[k] << ',' << mag::magnetization_error(s, gt)
        << '\n';
  }
}

// Speed against accuracy on crystal_balls (weak and strong): e_M against cumulative wall time
// for every dynamics and per Newton step (from M = 0); Δt_m against iterations to e_M ≤ 1e-4.
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

// ---------------------------------------------------------------------------------------
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
void use_threads(int n) {
  static const int all = omp_get_max_threads();
  omp_set_num_threads(n > 0 ? n : all);
}

struct Snapshot {
  /// Moment positions of rigid step k + 1 with the magnetization (and sub-pairs) of step k:
  /// the warm start the engine relaxes from in step k + 1.
  mag::MomentSet warm;
  mag::DynamicsOptions dyn;  ///< the scene's magnetization options (method ours-realigned)
  bool reaction_symmetric = false;
  json info;
};

void add_option(CLI::App* c, SnapshotOpts* s) {
  c->add_option("--count", s->count, "balls in the sakura_tree scene (paper: 2500; Newton cost grows as count³)")
      ->check(CLI::Range(10, 2500))->capture_default_str();
  c->add_option("--seconds", s->seconds, "simulated time (s) of the snapshot, stepped with ours-realigned")
      ->check(CLI::PositiveNumber)->capture_default_str();
  c->add_option("--dt", s->dt, "rigid step (s) while stepping to the snapshot (the scene's: 1e-3)")
      ->check(CLI::Range(1e-5, 1e-2))->capture_default_str();
  c->add_flag("--reuse,!--no-reuse", s->reuse,
              "reuse OUT/sakura_snapshot.json when made with the same --count/--seconds/--dt/"
              "--threads (default: reuse)");
  c->add_option("--threads", s->threads, "OpenMP threads for the magnetics and the stepping (0 = all); 1 times "
                "steadily on a shared 2-core machine, where a descheduled thread stalls each parallel region")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
}

json vecs_json(const std::vector<Vec3>& v) {
  json a = json::array();
  for (const Vec3& x : v) a.push_back({x.x(), x.y(), x.z()});
  return a;
}
std::vector<Vec3> vecs_from(const json& a) {
  std::vector<Vec3> v;
  for (const json& x : a) v.emplace_back(x[0].get<double>(), x[1].get<double>(), x[2].get<double>());
  return v;
}

/// The state of a moment set: positions, permanent moments and magnetizations.
json state_json(const mag::MomentSet& s) {
  return {{"position", vecs_json(s.position)}, {"M", vecs_json(s.M)}, {"M1", vecs_json(s.M1)},
          {"M2", vecs_json(s.M2)}, {"m_perm", vecs_json(s.m_perm)}, {"seeded", s.seeded}};
}
bool load_state(const json& j, mag::MomentSet* s) {
  const std::size_t n = s->size();
  if (j["position"].size() != n || j["M"].size() != n) return false;
  s->position = vecs_from(j["position"]);
  s->M = vecs_from(j["M"]);
  s->M1 = vecs_from(j["M1"]);
  s->M2 = vecs_from(j["M2"]);
  s->m_perm = vecs_from(j["m_perm"]);
  s->seeded = j["seeded"].get<std::vector<std::uint8_t>>();
  return true;
}

Snapshot sakura_snapshot(const SnapshotOpts& o, const std::string& out) {
  magsim::scenes::SceneParams p;
  p.count = o.count;
  magsim::engine::SceneDesc d = magsim::scenes::find_scene("sakura_tree")->build(p);
  d.options.method = mag::Method::OursRealigned;
  d.options.dt = o.dt;
  d.options.threads = o.threads;
  use_threads(o.threads);
  Snapshot sn;
  sn.dyn = d.options.magnetics;
  sn.dyn.method = mag::Method::OursRealigned;
  // errors against the ground truth need exact fields: the default, Auto, would take
  // Barnes–Hut from 2000 moments on (--count up to 2500)
  sn.dyn.field.solver = mag::FieldSolver::Direct;
  sn.reaction_symmetric = d.options.reaction_symmetric_forces;
  sn.warm = magsim::scenes::moment_set_at_rest(d);  // the structure; the state comes next
  const json key = {{"count", o.count}, {"seconds", o.seconds}, {"dt", o.dt}, {"threads", o.threads}};
  const std::string cache = out + "/sakura_snapshot.json";
  if (o.reuse && std::filesystem::exists(cache)) {
    json j;
    std::ifstream(cache) >> j;
    if (j.value("key", json()) == key && load_state(j["state"], &sn.warm)) {
      sn.info = j["info"];
      std::printf("snapshot: %s (t = %.3f s, %d balls on the tree)\n", cache.c_str(),
                  sn.info["seconds"].get<double>(), sn.info["attached"].get<int>());
      return sn;
    }
  }
  const auto t0 = Clock::now();
  magsim::engine::Simulation sim(d);
  double max_speed = 0;
  for (long k = 0, n = std::lround(o.seconds / d.options.dt); k < n; ++k) {
    sim.step();
    max_speed = std::max(max_speed, sim.metrics().max_speed);
  }
  const mag::MomentSet prev = sim.moments();
  sim.step();
  const mag::MomentSet& now = sim.moments();
  if (now.size() != sn.warm.size()) throw std::runtime_error("snapshot: moment count differs");
  sn.warm.position = now.position;
  sn.warm.m_perm = now.m_perm;
  sn.warm.M = prev.M;
  sn.warm.M1 = prev.M1;
  sn.warm.M2 = prev.M2;
  sn.warm.seeded = prev.seeded;
  const magsim::engine::Metrics m = sim.metrics();
  sn.info = {{"scene", "sakura_tree"}, {"balls", o.count}, {"seconds", sim.time()},
             {"rigid_dt", o.dt}, {"method", "ours-realigned"}, {"attached", m.attached},
             {"max_speed_so_far", std::max(max_speed, m.max_speed)},
             {"moments", sn.warm.size()}, {"induced", sn.warm.induced_count()},
             {"threads", o.threads},
             {"stepping_s", ms_since(t0) / 1000}};
  std::ofstream(cache) << json{{"key", key}, {"info", sn.info}, {"state", state_json(sn.warm)}}.dump() << "\n";
  std::printf("snapshot: sakura_tree, %d balls, t = %.3f s at Δt_r = %g s: %d on the tree, max "
              "speed so far %.0f m/s (%.1f s)\n", o.count, sim.time(), o.dt, m.attached,
              sn.info["max_speed_so_far"].get<double>(), ms_since(t0) / 1000);
  return sn;
}

/// Ground truths of the snapshot (Newton from the warm start, to 1e-12): eq. 10 (with its
/// per-step trace) and eq. 7; the magnetization level goes into sn->info.
struct GroundTruth {
  NewtonTrace tanh;
  mag::MomentSet kim;
};

GroundTruth snapshot_ground_truth(Snapshot* sn) {
  GroundTruth g;
  g.tanh = newton_trace(sn->warm, mag::Curve::Tanh, sn->dyn.field);
  g.kim = sn->warm;
  const auto t0 = Clock::now();
  mag::solve_exact(&g.kim, mag::Curve::Kim, sn->dyn.field);
  const double kim_ms = ms_since(t0);
  const mag::MomentSet& s = g.tanh.solution;
  double sum = 0;
  int strong = 0, n = 0;
  for (std::size_t j = 0; j < s.size(); ++j) {
    if (s.kind[j] != mag::MomentKind::Induced) continue;
    const double r = s.M[j].norm() / s.Ms[j];
    sum += r;
    strong += r > 0.5;
    ++n;
  }
  sn->info["mean_M_over_Ms"] = sum / n;
  sn->info["balls_M_over_half_Ms"] = strong;
  sn->info["newton_steps_from_warm"] = g.tanh.iterate.size();
  sn->info["newton_ms_from_warm"] = g.tanh.ms.empty() ? 0.0 : g.tanh.ms.back();
  sn->info["newton_kim_ms_from_warm"] = kim_ms;
  sn->info["warm_start_e_M"] = mag::magnetization_error(sn->warm, s.M);
  std::printf("ground truth: Newton %zu steps from the warm start, %.0f ms; mean |M|/Ms %.3f, "
              "%d balls above Ms/2; warm start e_M %.2e\n",
              g.tanh.iterate.size(), g.tanh.ms.empty() ? 0.0 : g.tanh.ms.back(), sum / n, strong,
              sn->info["warm_start_e_M"].get<double>());
  return g;
}

/// Forces of the method's force model and curve on every moment of s.
std::vector<Vec3> forces_of(const mag::MomentSet& s, mag::Method m, const Snapshot& sn) {
  mag::MagWorkspace ws;
  std::vector<Vec3> F, tau;
  mag::compute_forces(s, mag::force_model_of(m), mag::curve_of(m), sn.dyn.field, &ws, &F, &tau,
                      nullptr, sn.reaction_symmetric);
  return F;
}

/// max_j and RMS_j of |F_j − F_gt,j| / max_j |F_gt,j| over induced moments.
std::pair<double, double> force_error(const mag::MomentSet& s, const std::vector<Vec3>& F,
                                      const std::vector<Vec3>& F_gt) {
  double fmax = 0, dmax = 0, d2 = 0;
  int n = 0;
  for (std::size_t j = 0; j < s.size(); ++j) {
    if (s.kind[j] != mag::MomentKind::Induced) continue;
    fmax = std::max(fmax, F_gt[j].norm());
    const double d = (F[j] - F_gt[j]).norm();
    dmax = std::max(dmax, d);
    d2 += d * d;
    ++n;
  }
  if (fmax == 0 || n == 0) return {0.0, 0.0};
  return {dmax / fmax, std::sqrt(d2 / n) / fmax};
}

std::vector<double> parse_doubles(const std::string& list, const std::string& flag) {
  std::vector<double> v;
  std::stringstream ss(list);
  std::string x;
  while (std::getline(ss, x, ',')) {
    try {
      v.push_back(std::stod(x));
    } catch (const std::exception&) {
      throw CLI::ValidationError(flag, "not a number: " + x);
    }
  }
  return v;
}

// ---------------------------------------------------------------------------------------
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

struct Outcome {
  magsim::engine::Metrics last;
  double max_speed_run = 0, ti_median = 0, iters_median = 0, iters_mean = 0, cap_fraction = 0;
  double wall_s = 0;
  bool failed = false;
};

/// Runs a registry scene for `seconds` with the method at tolerance tol (the scene's cap).
Outcome run_outcome(const std::string& scene, mag::Method method, double tol, double seconds) {
  const auto* e = magsim::scenes::find_scene(scene);
  if (!e) throw CLI::ValidationError("--outcome-scene", "unknown scene " + scene);
  magsim::engine::SceneDesc d = e->build({});
  d.options.method = method;
  d.options.magnetics.tol = tol;
  magsim::engine::Simulation sim(d);
  Outcome o;
  std::vector<double> ti, it;
  long caps = 0;
  const auto t0 = Clock::now();
  try {
    for (long k = 0, n = std::lround(seconds / d.options.dt); k < n; ++k) {
      sim.step();
      const magsim::engine::StepProfile& pr = sim.last_profile();
      ti.push_back(pr.T_i);
      it.push_back(pr.iterations);
      caps += pr.cap_hit;
      o.max_speed_run = std::max(o.max_speed_run, sim.metrics().max_speed);
    }
  } catch (const magsim::engine::SimulationError& err) {
    o.failed = true;
    std::fprintf(stderr, "tolerance: %s at tol %g: %s\n", scene.c_str(), tol, err.what());
  }
  o.wall_s = ms_since(t0) / 1000;
  o.last = sim.metrics();
  o.ti_median = median(ti);
  o.iters_median = median(it);
  for (double x : it) o.iters_mean += x / std::max<std::size_t>(1, it.size());
  o.cap_fraction = static_cast<double>(caps) / std::max<std::size_t>(1, it.size());
  return o;
}

int run_tolerance(const ToleranceOpts& o) {
  ensure_dir(o.out);
  const auto t_all = Clock::now();
  Snapshot sn = sakura_snapshot(o.snap, o.out);
  const GroundTruth gt = snapshot_ground_truth(&sn);
  json summary = {{"snapshot", sn.info}, {"max_iter", o.max_iter}};
  std::ofstream csv(o.out + "/tolerance_snapshot.csv");
  csv << "start,method,tol,iterations,converged,wall_ms,e_M,e_M_max_moment,force_err_max,force_err_rms\n";
  std::map<mag::Curve, std::vector<Vec3>> F_gt;
  F_gt[mag::Curve::Tanh] = forces_of(gt.tanh.solution, mag::Method::OursRealigned, sn);
  F_gt[mag::Curve::Kim] = forces_of(gt.kim, mag::Method::Kim2018, sn);
  const std::vector<double> tols = parse_doubles(o.tols, "--tols");
  std::vector<std::string> starts = {"warm"};
  if (o.cold) starts.push_back("cold");
  for (const std::string& start : starts) {
    mag::MomentSet base = sn.warm;
    if (start == "cold") base.reset_magnetization();
    for (mag::Method m : parse_methods(o.methods)) {
      const mag::MomentSet& gs = mag::curve_of(m) == mag::Curve::Kim ? gt.kim : gt.tanh.solution;
      json capped;  // a run that hit the cap: every smaller tolerance repeats it exactly
      for (double tol : tols) {
        json row;
        if (!capped.is_null() && tol < capped["tol"].get<double>()) {
          row = capped;
        } else {
          mag::DynamicsOptions d = sn.dyn;
          d.method = m;
          d.tol = tol;
          d.max_iter = o.max_iter;
          std::vector<double> ms;
          mag::MomentSet s;
          mag::RelaxStats st;
          for (int r = 0; r < o.repeat && (r == 0 || ms[0] < 100); ++r) {  // long runs: once
            s = base;
            mag::MagWorkspace ws;
            const auto t0 = Clock::now();
            st = mag::relax_magnetization(&s, d, &ws);
            ms.push_back(ms_since(t0));
          }
          const auto [fmax, frms] = force_error(s, forces_of(s, m, sn), F_gt[mag::curve_of(m)]);
          row = {{"iterations", st.iterations}, {"converged", st.converged},
                 {"wall_ms", median(ms)}, {"e_M", mag::magnetization_error(s, gs.M)},
                 {"e_M_max_moment", mag::max_moment_error(s, gs.M)}, {"force_err_max", fmax},
                 {"force_err_rms", frms}};
          if (!st.converged) capped = row;
          if (!st.converged) capped["tol"] = tol;
        }
        row["tol"] = tol;
        csv << start << ',' << mag::method_name(m) << ',' << tol << ',' << row["iterations"] << ','
            << row["converged"].get<bool>() << ',' << row["wall_ms"] << ',' << row["e_M"] << ','
            << row["e_M_max_moment"] << ',' << row["force_err_max"] << ','
            << row["force_err_rms"] << '\n';
        summary["snapshot_runs"][start][mag::method_name(m)].push_back(row);
        std::printf("tolerance %-4s %-15s tol %-6g %4d it%s %8.2f ms  e_M %.2e  |ΔF|/max|F| max %.2e rms %.2e\n",
                    start.c_str(), mag::method_name(m), tol, row["iterations"].get<int>(),
                    row["converged"].get<bool>() ? "" : " (cap)", row["wall_ms"].get<double>(),
                    row["e_M"].get<double>(), row["force_err_max"].get<double>(),
                    row["force_err_rms"].get<double>());
      }
    }
  }
  // the scene outcome: last, since a Simulation of few moments sets OpenMP to one thread
  std::ofstream oc(o.out + "/tolerance_outcome.csv");
  oc << "scene,method,tol,seconds,kinetic_energy,attached,max_speed_final,max_speed_run,"
        "T_i_median_ms,iterations_median,iterations_mean,cap_fraction,failed\n";
  for (double tol : parse_doubles(o.outcome_tols, "--outcome-tols")) {
    const Outcome r = run_outcome(o.outcome_scene, mag::Method::OursRealigned, tol, o.outcome_seconds);
    oc << o.outcome_scene << ",ours-realigned," << tol << ',' << r.last.time << ','
       << r.last.kinetic_energy << ',' << r.last.attached << ',' << r.last.max_speed << ','
       << r.max_speed_run << ',' << r.ti_median << ',' << r.iters_median << ','
       << r.iters_mean << ',' << r.cap_fraction << ',' << r.failed << '\n';
    summary["outcome"].push_back(
        {{"scene", o.outcome_scene}, {"method", "ours-realigned"}, {"tol", tol},
         {"seconds", r.last.time}, {"kinetic_energy", r.last.kinetic_energy},
         {"attached", r.last.attached}, {"balls", r.last.dynamic_bodies},
         {"max_speed_final", r.last.max_speed}, {"max_speed_run", r.max_speed_run},
         {"T_i_median_ms", r.ti_median}, {"iterations_median", r.iters_median},
         {"iterations_mean", r.iters_mean}, {"cap_fraction", r.cap_fraction},
         {"failed", r.failed}});
    std::printf("outcome %s tol %-6g t %.2f s: KE %.3e J, %d/%d attached, max speed %.3f m/s "
                "(run %.3f), T_i median %.3f ms, %g iterations median, cap %.0f %% (%.1f s)\n",
                o.outcome_scene.c_str(), tol, r.last.time, r.last.kinetic_energy, r.last.attached,
                r.last.dynamic_bodies, r.last.max_speed, r.max_speed_run, r.ti_median,
                r.iters_median, 100 * r.cap_fraction, r.wall_s);
  }
  summary["seconds"] = ms_since(t_all) / 1000;
  std::ofstream(o.out + "/tolerance.json") << summary.dump(2) << "\n";
  std::printf("tolerance: wrote %s/tolerance_snapshot.csv, tolerance_outcome.csv, tolerance.json "
              "(%.1f s)\n", o.out.c_str(), ms_since(t_all) / 1000);
  return 0;
}

// ---------------------------------------------------------------------------------------
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
