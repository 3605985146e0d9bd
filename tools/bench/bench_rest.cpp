// tools/bench/bench_rest.cpp — where a scene's step goes once it has come to rest, and what
// each option would save there.
//
// Runs a registry scene (with --strength and the --set options) once to --at seconds, keeps
// that state, then steps --steps from it under the scene's own options and under each
// --variant (options-table keys set to values), so that every variant starts from the same
// bits. Per variant: the means per step of T_i, T_f, T_r and T_r's collide and QuickStep
// parts, rigid sub-steps, contact joints, the magnetization's sweeps (over all sub-steps),
// bodies asleep at the end, the fastest body at the end and the deepest contact over the
// window: the cost beside what a viewer would see change.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/options_table.hpp"
#include "engine/simulation.hpp"
#include "scenes/registry.hpp"
#include "tools/bench/bench_common.hpp"

namespace eng = magsim::engine;
using json = nlohmann::json;

namespace {

struct Variant {
  std::string name;                                       ///< "scene" or the --variant text
  std::vector<std::pair<std::string, std::string>> sets;  ///< key, value as typed
};

// "key=value,key=value" → sets; an item without a key or a value (or an empty
// one) is a one-line error (std::invalid_argument) before any step is taken.
Variant parse_variant(const std::string& text, const char* flag = "--variant") {
  Variant v{text, {}};
  const std::vector<std::string> items = magsim::bench::split(text);
  const auto commas = static_cast<std::size_t>(std::count(text.begin(), text.end(), ','));
  for (const std::string& item : items) {
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size()) break;
    v.sets.emplace_back(item.substr(0, eq), item.substr(eq + 1));
  }
  if (v.sets.size() != commas + 1)
    throw std::invalid_argument(std::string(flag) + " '" + text + "': expected key=value[,key=value...]");
  return v;
}

void apply(const Variant& v, eng::SimOptions* o) {
  for (const auto& [key, text] : v.sets) {
    const auto& table = eng::options_table();
    const auto it = std::find_if(table.begin(), table.end(), [&](const eng::OptionSpec& s) { return s.key == key; });
    if (it == table.end()) throw std::invalid_argument("unknown option '" + key + "'");
    if (const std::string err = it->assign(*o, text); !err.empty()) throw std::invalid_argument(key + ": " + err);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "bench_rest — a scene's step at rest: one saved state, stepped "
      "under the scene's options and under "
      "each --variant, with T_i/T_f/T_r, QuickStep, sub-steps, "
      "contacts and the fastest body"};
  std::string scene = "alphabets", out = "out/bench/bench_rest.json";
  double at = 2.5;
  int steps = 200, threads = 2;
  std::vector<std::string> variants;
  std::string set;
  double strength = 1.0;
  app.add_option("--scene", scene, "a registry scene")->capture_default_str();
  app.add_option("--strength", strength, "multiplies every permanent moment of the scene")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--set", set,
                 "options-table keys and values for the run to --at and every window, e.g. "
                 "sleep=false,quickstep_iterations=40");
  app.add_option("--at", at, "simulated seconds run once before the windows (s)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--steps", steps, "steps in each window")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--threads", threads, "OpenMP threads")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--variant", variants,
                 "options-table keys and values for one more window, e.g. "
                 "quickstep_iterations=25,max_contacts=2 "
                 "(repeat the flag for more windows)");
  app.add_option("--json", out, "where to write the JSON")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const magsim::scenes::SceneEntry* entry = magsim::scenes::find_scene(scene);
  if (!entry) {
    std::fprintf(stderr, "bench_rest: unknown scene '%s'\n", scene.c_str());
    return 1;
  }
  std::vector<Variant> vs = {{"scene", {}}};
  magsim::scenes::SceneParams params;
  params.strength = strength;
  eng::SceneDesc base = entry->build(params);
  base.options.threads = threads;
  try {
    if (!set.empty()) apply(parse_variant(set, "--set"), &base.options);
    for (const std::string& t : variants) {
      vs.push_back(parse_variant(t));
      eng::SimOptions check = base.options;
      apply(vs.back(), &check);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_rest: %s\n", e.what());
    return 1;
  }

  json doc = {{"scene", scene},     {"strength", strength},    {"set", set}, {"at_seconds", at}, {"steps", steps},
              {"threads", threads}, {"windows", json::array()}};
  eng::State saved;
  try {  // a scene the options refuse, or a blow-up before --at: one line, exit 2
    eng::Simulation sim(base);
    const long n0 = std::lround(at / base.options.dt);
    for (long k = 0; k < n0; ++k) {
      sim.step();
      if ((k + 1) % 500 == 0)
        std::fprintf(stderr, "bench_rest: %s to %.3f s, step %ld/%ld\n", scene.c_str(), at, k + 1, n0);
    }
    saved = sim.save_state();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_rest: %s before %g s: %s\n", scene.c_str(), at, e.what());
    return 2;
  }
  std::printf("%-40s %7s %7s %7s %8s %9s %8s %9s %7s %7s %10s %10s\n", "variant", "T_i", "T_f", "T_r", "collide",
              "QuickStep", "substeps", "contacts", "sweeps", "asleep", "fastest", "deepest");
  for (const Variant& v : vs) {
    eng::SceneDesc d = base;
    apply(v, &d.options);
    double sum[8] = {0, 0, 0, 0, 0, 0, 0, 0}, deepest = 0, fastest = 0;
    std::string error;  // a variant refused or blowing up ends its window, not the others
    int taken = 0, asleep = 0;
    std::unique_ptr<eng::Simulation> sim;  // after a blow-up it holds the last good state
    try {
      sim = std::make_unique<eng::Simulation>(d);
      sim->restore_state(saved);
      for (int k = 0; k < steps; ++k, ++taken) {
        sim->step();
        const eng::StepProfile& p = sim->last_profile();
        const double parts[8] = {p.T_i,
                                 p.T_f,
                                 p.T_r,
                                 p.collide_ms,
                                 p.quickstep_ms,
                                 double(p.substeps),
                                 double(p.contacts),
                                 double(p.iterations)};
        for (int q = 0; q < 8; ++q) sum[q] += parts[q];
        deepest = std::max(deepest, sim->state().contact_depth);
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (sim) {
      for (const eng::Vec3& vel : sim->state().vel) fastest = std::max(fastest, vel.norm());
      asleep = sim->last_profile().asleep;
    }
    for (double& s : sum) s /= std::max(taken, 1);
    std::printf(
        "%-40s %7.2f %7.2f %7.2f %8.2f %9.2f %8.2f %9.0f %7.2f %7d %10.4f "
        "%10.2e%s%s\n",
        v.name.c_str(), sum[0], sum[1], sum[2], sum[3], sum[4], sum[5], sum[6], sum[7], asleep, fastest, deepest,
        error.empty() ? "" : "  FAILED: ", error.c_str());
    std::fflush(stdout);
    doc["windows"].push_back(
        {{"variant", v.name},
         {"mean_ms", {{"T_i", sum[0]}, {"T_f", sum[1]}, {"T_r", sum[2]}, {"collide", sum[3]}, {"quickstep", sum[4]}}},
         {"substeps_mean", sum[5]},
         {"contacts_mean", sum[6]},
         {"magnetization_sweeps_mean", sum[7]},
         {"asleep_at_end", asleep},
         {"fastest_at_end", fastest},
         {"deepest_contact", deepest},
         {"steps_taken", taken}});
    if (!error.empty()) doc["windows"].back()["error"] = error;
  }
  std::filesystem::path p(out);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  std::ofstream(out) << doc.dump(2) << "\n";
  std::printf("bench_rest: wrote %s\n", out.c_str());
  return 0;
}
