// tools/bench/bench.cpp — Table 1 of the paper, measured: per scene and method the medians of
// T_i, T_f, T_r per 1 ms rigid step over a window after a warm-up, the magnetization
// iterations per step, and the ratio ours/Kim 2018 of T_i measured in the same run; plus the
// scaling of the step with the number of balls (sakura_tree with N balls). Writes JSON.
// Timings are figures to read, never pass/fail. --field-solver / --bh-theta / --bh-threshold
// (the table of run options' flags, as magsim-scene's) set the dipole-field summation of every run; the scaling runs use --scaling-solver (default
// auto: Barnes–Hut from --bh-threshold moments on), or --field-solver when only that is given.
// --near-field-cost measures every scene and method twice in the same run, with the near field
// `dipole` and `pair`, and writes the ratio pair/dipole of T_i + T_f + T_r per step.
#include "engine/simulation.hpp"
#include "scenes/registry.hpp"
#include "tools/bench/bench_common.hpp"
#include "tools/cli/option_flags.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>

#include <sys/resource.h>

namespace eng = magsim::engine;
namespace mag = magsim::mag;
using nlohmann::json;

namespace {

// the paper's Table 1 (ms per frame, 6-core i7-8700, Bullet): {T_i, T_f, T_r}
struct PaperRow {
  const char* scene;
  double kim[3], ours[3];
};
const PaperRow kPaper[] = {
    {"balls_up", {20, 3.5, 14}, {1.8, 3.8, 14}},
    {"alphabets", {3.3, 1.3, 15}, {1.3, 1.4, 110}},
    {"falling_magnet", {251, 58, 59}, {36, 61, 60}},
    {"sakura_tree", {778, 97, 65}, {61, 101, 75}},
};

using magsim::bench::median;
using magsim::bench::split;

struct Window {
  double T_i = 0, T_f = 0, T_r = 0, total = 0, iters = 0, cap_frac = 0;
  double collide = 0, quickstep = 0, contacts = 0;  ///< T_r's parts (ms) and contact joints
  int moments = 0;
  int quickstep_iterations = 0;  ///< ODE QuickStep iterations of the scene
  std::string solver;  ///< the field solver used (Auto resolved for the scene's moment count)
  bool failed = false;
  std::string error;
};

Window measure(const std::string& scene, mag::Method method, int count, int warmup, int steps,
               int threads, const magsim::tools::OptionFlags& field,
               std::optional<mag::FieldSolver> solver = std::nullopt,
               std::optional<mag::NearField> near_field = std::nullopt) {
  magsim::scenes::SceneParams p;
  p.count = count;
  eng::SceneDesc d = magsim::scenes::find_scene(scene)->build(p);
  d.options.magnetics.method = method;
  if (threads > 0) d.options.threads = threads;
  field.apply(&d.options);  // checked in main
  if (solver) d.options.magnetics.field.solver = *solver;
  if (near_field) d.options.magnetics.field.near_field.model = *near_field;
  eng::Simulation sim(d);
  Window w;
  w.moments = sim.model().nmoment;
  w.solver = mag::field_solver_name(
      mag::resolve_solver(sim.model().options.magnetics.field, static_cast<std::size_t>(w.moments)));
  w.quickstep_iterations = sim.model().options.quickstep_iterations;
  std::vector<double> ti, tf, tr, tot, it, co, qs, nc;
  int caps = 0;
  try {
    for (int k = 0; k < warmup + steps; ++k) {
      sim.step();
      if (k < warmup) continue;
      const eng::StepProfile& pr = sim.last_profile();
      ti.push_back(pr.T_i);
      tf.push_back(pr.T_f);
      tr.push_back(pr.T_r);
      co.push_back(pr.collide_ms);
      qs.push_back(pr.quickstep_ms);
      nc.push_back(pr.contacts);
      tot.push_back(pr.T_i + pr.T_f + pr.T_r);
      it.push_back(pr.iterations);
      caps += pr.cap_hit;
    }
  } catch (const std::exception& e) {
    w.failed = true;
    w.error = e.what();
  }
  w.T_i = median(ti);
  w.T_f = median(tf);
  w.T_r = median(tr);
  w.collide = median(co);
  w.quickstep = median(qs);
  w.contacts = median(nc);
  w.total = median(tot);
  w.iters = median(it);
  w.cap_frac = ti.empty() ? 0 : static_cast<double>(caps) / ti.size();
  return w;
}

// The process's peak resident memory so far (MB; getrusage's ru_maxrss is in kB on Linux).
double peak_resident_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

// A whole run, as a user pays for it: the scene's standard run (or `seconds`), wall time per
// simulated second, the means per step of its first and last 0.5 s and of its last second, and
// the warm window's medians (steps [warmup, warmup + steps)) from the same run.
struct WholeRun {
  double seconds = 0, wall = 0;
  double first[4] = {0, 0, 0, 0}, last[4] = {0, 0, 0, 0};  ///< T_i, T_f, T_r, step (ms)
  double last_second[4] = {0, 0, 0, 0};                    ///< the same over the last 1 s
  Window window;
  int asleep = 0;  ///< bodies asleep at the end
  bool failed = false;
  std::string error;
};

WholeRun whole_run(const std::string& scene, mag::Method method, int count, double seconds, int warmup,
                   int steps, int threads, const magsim::tools::OptionFlags& field) {
  magsim::scenes::SceneParams p;
  p.count = count;
  eng::SceneDesc d = magsim::scenes::find_scene(scene)->build(p);
  d.options.magnetics.method = method;
  if (threads > 0) d.options.threads = threads;
  field.apply(&d.options);
  eng::Simulation sim(d);
  const long n = std::lround((seconds > 0 ? seconds : d.default_seconds) / d.options.dt);
  const long half = std::max<long>(1, std::lround(0.5 / d.options.dt));
  std::vector<double> ti, tf, tr, tot;
  WholeRun r;
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  auto last_report = t0;
  try {
    for (long k = 0; k < n; ++k) {
      sim.step();
      const eng::StepProfile& pr = sim.last_profile();
      ti.push_back(pr.T_i);
      tf.push_back(pr.T_f);
      tr.push_back(pr.T_r);
      tot.push_back(pr.total_ms);
      if (clock::now() - last_report > std::chrono::seconds(10)) {
        last_report = clock::now();
        std::fprintf(stderr, "bench: %s %s step %ld/%ld, %d asleep\n", scene.c_str(),
                     mag::method_name(method), k + 1, n, pr.asleep);
      }
    }
  } catch (const std::exception& e) {
    r.failed = true;
    r.error = e.what();
  }
  r.wall = std::chrono::duration<double>(clock::now() - t0).count();
  r.seconds = sim.time();
  r.asleep = sim.last_profile().asleep;
  const long m = static_cast<long>(tot.size());
  auto mean = [](const std::vector<double>& v, long a, long b) {
    double acc = 0;
    for (long k = a; k < b; ++k) acc += v[k];
    return b > a ? acc / static_cast<double>(b - a) : 0.0;
  };
  const std::vector<double>* parts[4] = {&ti, &tf, &tr, &tot};
  for (int q = 0; q < 4; ++q) {
    r.first[q] = mean(*parts[q], 0, std::min(m, half));
    r.last[q] = mean(*parts[q], std::max(0L, m - half), m);
    r.last_second[q] = mean(*parts[q], std::max(0L, m - 2 * half), m);
  }
  if (m >= warmup + steps) {
    std::vector<double> a(ti.begin() + warmup, ti.begin() + warmup + steps), b(tf.begin() + warmup, tf.begin() + warmup + steps),
        c(tr.begin() + warmup, tr.begin() + warmup + steps), t(steps);
    for (int k = 0; k < steps; ++k) t[k] = a[k] + b[k] + c[k];
    r.window.T_i = median(a);
    r.window.T_f = median(b);
    r.window.T_r = median(c);
    r.window.total = median(t);
  }
  return r;
}

json window_json(const Window& w) {
  json j = {{"timing_ms", {{"T_i", {{"median", w.T_i}}}, {"T_f", {{"median", w.T_f}}},
                           {"T_r", {{"median", w.T_r}}}, {"total", {{"median", w.total}}}}},
            {"iterations_median", w.iters}, {"cap_hit_fraction", w.cap_frac},
            {"field_solver", w.solver}, {"moments", w.moments},
            {"T_r_parts_ms", {{"collide", {{"median", w.collide}}}, {"quickstep", {{"median", w.quickstep}}}}},
            {"contacts_median", w.contacts}, {"quickstep_iterations", w.quickstep_iterations}};
  if (w.failed) j["error"] = w.error;
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench — Table 1 measured (medians of T_i, T_f, T_r per 1 ms step after a "
               "warm-up) and the scaling of a step with the number of balls"};
  std::string scenes = "balls_up,alphabets,falling_magnet,sakura_tree";
  std::string methods = "ours,ours-realigned,anderson,kim2018";
  std::string out = "out/bench/bench.json";
  std::string scaling = "250,500,1000,2500,5000,10000";
  std::string scaling_methods = "ours-realigned,anderson";
  // 400 warm-up steps: the window (0.4–0.5 s) starts after sakura_tree's balls have landed
  // on the tree (t ≈ 0.28 s), falling_magnet's magnet on the pile (0.13 s), balls_up's balls
  // on the magnet. The scaling runs' 500: at 300 steps the 10,000-ball run of the old
  // stacked sheets was still falling (2 iterations, T_r 9.7 ms); the single wide sheet of
  // today lands by t ≈ 0.3 s, and 500 leaves the window clear of the impact
  int warmup = 400, steps = 100, threads = 0, scaling_steps = 30, scaling_warmup = 500;
  std::string scaling_solver = "auto";
  bool near_field_cost = false;
  // the field flags are the table's (magsim-scene's spellings, ranges and help)
  magsim::tools::OptionFlags::Offer offer;
  offer.keys = {"magnetics.field.solver", "magnetics.field.bh_theta", "magnetics.field.auto_threshold",
                "magnetics.field.near_field.model", "magnetics.field.near_field.mu_r", "sleep"};
  magsim::tools::OptionFlags field;
  app.add_option("--scenes", scenes, "comma list of registry scenes")->capture_default_str();
  app.add_option("--methods", methods, "comma list of methods")->capture_default_str();
  app.add_option("--warmup", warmup, "steps before the window")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--steps", steps, "steps in the window (medians)")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--threads", threads, "OpenMP threads (0: the scene's default)")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--scaling", scaling, "ball counts for sakura_tree scaling, or 'none'")->capture_default_str();
  app.add_option("--scaling-methods", scaling_methods, "methods for the scaling runs")->capture_default_str();
  app.add_option("--scaling-steps", scaling_steps, "window of each scaling run")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--scaling-warmup", scaling_warmup, "steps before each scaling window")->check(CLI::NonNegativeNumber)->capture_default_str();
  field.add(&app, "Options", offer);
  app.add_option("--scaling-solver", scaling_solver,
                 "field solver of the scaling runs (default auto, or --field-solver when only that is given)")
      ->capture_default_str();
  app.add_flag("--near-field-cost", near_field_cost,
               "measure every scene and method twice, with --near-field dipole and pair, and print "
               "the ratio pair/dipole of T_i + T_f + T_r per step (not with --near-field)");
  bool whole = false;
  double whole_seconds = 0;
  int whole_count = 0;
  app.add_flag("--whole-run", whole,
               "instead of the Table 1 windows: each scene's whole standard run per method, wall time per "
               "simulated second, the means per step of its first and last 0.5 s, and the warm window's medians "
               "from the same run (what a user pays)");
  app.add_option("--whole-run-seconds", whole_seconds, "with --whole-run: simulated seconds (0: the scene's standard run)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--whole-run-count", whole_count, "with --whole-run: balls / letters of the registry scenes (0: the scene's)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--json", out, "where to write the JSON")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (near_field_cost && field.given("magnetics.field.near_field.model")) {
    std::fprintf(stderr, "bench: --near-field-cost measures both near fields; do not give --near-field with it\n");
    return 2;
  }

  // the scaling runs: --scaling-solver, or --field-solver when only that is given
  const bool solver_given = field.given("magnetics.field.solver");
  if (!app.count("--scaling-solver") && solver_given) scaling_solver = field.text("magnetics.field.solver");
  mag::FieldSolver scaling_field;
  eng::SimOptions requested;  // the table's defaults with the flags given, for the JSON
  try {
    field.apply(&requested);
    if (!mag::parse_field_solver(scaling_solver, &scaling_field))
      throw std::invalid_argument("--scaling-solver: " + mag::kFieldSolverNames.unknown("solver", scaling_solver));
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "bench: %s\n", e.what());
    return 2;
  }

  std::vector<std::pair<std::string, mag::Method>> ms;
  for (const std::string& m : split(methods)) {
    mag::Method x;
    if (!mag::parse_method(m, &x)) {
      std::fprintf(stderr, "bench: %s\n", mag::kMethodNames.unknown("method", m).c_str());
      return 2;
    }
    ms.emplace_back(m, x);
  }
  for (const std::string& s : split(scenes)) {
    if (!magsim::scenes::find_scene(s)) {
      std::fprintf(stderr, "bench: unknown scene '%s'\n", s.c_str());
      return 2;
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(out).parent_path(), ec);

  json doc;
  doc["warmup_steps"] = warmup;
  doc["window_steps"] = steps;
  doc["scaling_warmup_steps"] = scaling_warmup;
  doc["scaling_window_steps"] = scaling_steps;
  // requested for the Table 1 runs (each run records the one used)
  doc["field_solver"] = solver_given ? field.text("magnetics.field.solver") : "scene default";
  doc["scaling_solver"] = scaling_solver;
  doc["bh_theta"] = requested.magnetics.field.bh_theta;
  doc["bh_threshold"] = requested.magnetics.field.auto_threshold;
  doc["runs"] = json::array();
  if (whole) {
    doc["whole_run"] = json::array();
    std::printf("%-15s %-15s %10s %10s %28s %28s %12s %22s %7s\n", "scene", "method", "sim s", "wall/sim s",
                "first 0.5 s T_i/T_f/T_r", "last 0.5 s T_i/T_f/T_r", "last 1 s step", "window T_i/T_f/T_r", "asleep");
    for (const std::string& s : split(scenes))
      for (const auto& [name, m] : ms) {
        const WholeRun r = whole_run(s, m, whole_count, whole_seconds, warmup, steps, threads, field);
        json j = {{"scene", s}, {"method", name}, {"count", whole_count}, {"simulated_seconds", r.seconds},
                  {"wall_seconds", r.wall}, {"wall_per_simulated_second", r.seconds > 0 ? r.wall / r.seconds : 0.0},
                  {"first_half_second_ms", {{"T_i", r.first[0]}, {"T_f", r.first[1]}, {"T_r", r.first[2]}, {"step", r.first[3]}}},
                  {"last_half_second_ms", {{"T_i", r.last[0]}, {"T_f", r.last[1]}, {"T_r", r.last[2]}, {"step", r.last[3]}}},
                  {"last_second_ms", {{"T_i", r.last_second[0]}, {"T_f", r.last_second[1]}, {"T_r", r.last_second[2]}, {"step", r.last_second[3]}}},
                  {"peak_resident_mb", peak_resident_mb()},
                  {"window_median_ms", {{"T_i", r.window.T_i}, {"T_f", r.window.T_f}, {"T_r", r.window.T_r}, {"total", r.window.total}}},
                  {"asleep_at_end", r.asleep}};
        for (const PaperRow& pr : kPaper)
          if (s == pr.scene) {
            const double* v = m == mag::Method::Kim2018 ? pr.kim : pr.ours;
            j["paper_wall_per_simulated_second"] = (v[0] + v[1] + v[2]);  // ms per 1 ms frame = s per s
          }
        if (r.failed) j["error"] = r.error;
        doc["whole_run"].push_back(j);
        std::printf("%-15s %-15s %10.3f %10.2f %10.2f/%7.2f/%8.2f %10.2f/%7.2f/%8.2f %12.2f %7.2f/%6.2f/%7.2f %7d%s%s\n",
                    s.c_str(), name.c_str(), r.seconds, r.seconds > 0 ? r.wall / r.seconds : 0.0, r.first[0], r.first[1],
                    r.first[2], r.last[0], r.last[1], r.last[2], r.last_second[3], r.window.T_i, r.window.T_f, r.window.T_r, r.asleep,
                    r.failed ? "  FAILED: " : "", r.failed ? r.error.c_str() : "");
        std::fflush(stdout);
      }
    std::ofstream(out) << doc.dump(2) << "\n";
    std::printf("bench: wrote %s\n", out.c_str());
    return 0;
  }
  std::printf("%-15s %-15s %9s %9s %9s %9s %7s %6s %-10s   paper T_i/T_f/T_r (ms per frame)\n",
              "scene", near_field_cost ? "method/near" : "method", "T_i", "T_f", "T_r", "total", "iters", "cap%", "solver");
  // the near fields of the Table 1 runs: the scene's (or --near-field's), or both
  std::vector<std::optional<mag::NearField>> near_fields{std::nullopt};
  if (near_field_cost) near_fields = {mag::NearField::Dipole, mag::NearField::Pair};
  for (const std::string& s : split(scenes)) {
    std::map<std::string, double> ti;  // method name → median T_i
    for (const auto& [name, m] : ms) {
      std::map<mag::NearField, double> nf_total;  // near field → median T_i + T_f + T_r
      for (const std::optional<mag::NearField>& nf : near_fields) {
        const Window w = measure(s, m, 0, warmup, steps, threads, field, std::nullopt, nf);
        json r = window_json(w);
        r["scene"] = s;
        r["method"] = name;
        if (nf) {
          r["near_field"] = mag::kNearFieldNames.name(*nf);
          nf_total[*nf] = w.total;
        }
        for (const PaperRow& p : kPaper) {
          if (s != p.scene) continue;
          const double* v = m == mag::Method::Kim2018 ? p.kim : p.ours;
          r["paper_ms_per_frame"] = {{"T_i", v[0]}, {"T_f", v[1]}, {"T_r", v[2]}};
        }
        doc["runs"].push_back(r);
        const std::string label = nf ? name + "/" + mag::kNearFieldNames.name(*nf) : name;
        std::printf("%-15s %-15s %9.3f %9.3f %9.3f %9.3f %7.1f %5.0f%% %-10s", s.c_str(), label.c_str(),
                    w.T_i, w.T_f, w.T_r, w.total, w.iters, 100 * w.cap_frac, w.solver.c_str());
        if (r.contains("paper_ms_per_frame"))
          std::printf("   %g / %g / %g", r["paper_ms_per_frame"]["T_i"].get<double>(),
                      r["paper_ms_per_frame"]["T_f"].get<double>(),
                      r["paper_ms_per_frame"]["T_r"].get<double>());
        if (w.failed) std::printf("   FAILED: %s", w.error.c_str());
        std::printf("\n%-15s %-15s T_r = collide %.3f + QuickStep %.3f ms (%d iterations, %.0f contacts)\n", "", "",
                    w.collide, w.quickstep, w.quickstep_iterations, w.contacts);
        std::fflush(stdout);
        if (!nf || *nf == mag::NearField::Dipole) ti[name] = w.T_i;
      }
      const auto dipole = nf_total.find(mag::NearField::Dipole), pair = nf_total.find(mag::NearField::Pair);
      if (dipole != nf_total.end() && pair != nf_total.end() && dipole->second > 0) {
        const double ratio = pair->second / dipole->second;
        doc["near_field_cost"][s][name] = {{"dipole_total_ms", dipole->second},
                                           {"pair_total_ms", pair->second},
                                           {"pair_over_dipole", ratio}};
        std::printf("%-15s %-15s T_i + T_f + T_r pair/dipole = %.3f (same run)\n", s.c_str(), name.c_str(), ratio);
      }
    }
    // T_i of every method over Kim 2018's, measured in this run
    if (ti.count("kim2018") && ti["kim2018"] > 0) {
      for (const auto& [name, t] : ti) {
        if (name == "kim2018") continue;
        const std::string key = name == "ours" ? "T_i_ours_over_kim" : "T_i_" + name + "_over_kim";
        doc["ratios"][s][key] = t / ti["kim2018"];
        std::printf("%-15s T_i %s/kim2018 = %.3f (same run)\n", s.c_str(), name.c_str(),
                    t / ti["kim2018"]);
      }
    }
  }
  if (scaling != "none") {
    doc["scaling"] = json::array();
    for (const std::string& m : split(scaling_methods)) {
      mag::Method x;
      if (!mag::parse_method(m, &x)) continue;
      for (const std::string& n : split(scaling)) {
        const int N = std::stoi(n);
        const Window w = measure("sakura_tree", x, N, scaling_warmup, scaling_steps, threads, field, scaling_field);
        json row = {{"balls", N}, {"method", m}, {"total_ms", w.total},
                    {"T_i", w.T_i}, {"T_f", w.T_f}, {"T_r", w.T_r},
                    {"iterations_median", w.iters}, {"moments", w.moments},
                    {"solver", w.solver}, {"solver_requested", scaling_solver},
                    {"collide", w.collide}, {"quickstep", w.quickstep}, {"contacts_median", w.contacts}};
        if (w.failed) row["error"] = w.error;
        doc["scaling"].push_back(row);
        std::printf("scaling sakura_tree N=%-6d %-15s total %9.3f ms (T_i %.3f, T_f %.3f, T_r %.3f = collide %.3f + QuickStep %.3f, %.0f contacts), %.0f iterations, %s%s%s\n",
                    N, m.c_str(), w.total, w.T_i, w.T_f, w.T_r, w.collide, w.quickstep, w.contacts, w.iters, w.solver.c_str(),
                    w.failed ? "  FAILED: " : "", w.failed ? w.error.c_str() : "");
        std::fflush(stdout);
      }
    }
  }
  std::ofstream(out) << doc.dump(2) << "\n";
  std::printf("bench: wrote %s\n", out.c_str());
  return 0;
}
