// Tests for tools/cli/magsim_scene/ (magsim-scene): the ODE flags (--space, --quickstep-iterations,
// --auto-disable) reach the run, and bad values are refused with a one-line error.
#include "engine/simulation.hpp"
#include "scenes/registry.hpp"
#include "scenes/scene_file.hpp"
#include "tests/tools/cli/run_command.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

namespace {

using Result = magsim::test::CommandResult;

Result run_scene(const std::string& args) { return magsim::test::run_command(MAGSIM_SCENE_BIN, args); }

std::string tmp_dir(const std::string& name) {
  return magsim::test::scratch("scene_cli_" + name);
}

}  // namespace

TEST_CASE("magsim-scene: --space, --quickstep-iterations and --auto-disable reach the run", "[tools]") {
  const std::string out = tmp_dir("flags");
  const Result r = run_scene("balls_up --steps 3 --no-render --count 20 --space hash "
                             "--quickstep-iterations 7 --auto-disable --out " + out);
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::ifstream f(out + "/summary.json");
  REQUIRE(f.good());
  const auto j = nlohmann::json::parse(f);
  CHECK(j["options"]["space"] == "hash");
  CHECK(j["options"]["quickstep_iterations"] == 7);
  CHECK(j["options"]["auto_disable"] == true);
  CHECK(j["steps"] == 3);
  // attachment metrics next to "attached", final and per frame
  CHECK(j["escape_radius"] == 0.15);
  CHECK(j["final"]["held"].is_number_integer());
  CHECK(j["final"]["escaped"] == 0);  // 3 ms: nothing has left the pile
  CHECK(j["series"]["held"].size() == j["series"]["attached"].size());
  CHECK(j["series"]["held_max_speed"].size() == j["series"]["held"].size());
  CHECK(j["series"]["escaped"].size() == j["series"]["time"].size());
  // the deepest contact overlap: over every step, so at least that of any recorded frame
  REQUIRE(j["series"]["contact_depth"].size() == j["series"]["time"].size());
  double framed = 0.0;
  for (const auto& v : j["series"]["contact_depth"]) framed = std::max(framed, v.get<double>());
  CHECK(j["contact_depth"]["max"].get<double>() >= framed);
  CHECK(j["contact_depth"]["max"].get<double>() < 0.005);  // less than a ball's radius
  CHECK(j["contact_depth"]["max_at"].get<double>() <= 0.003 + 1e-12);
  // the energy audit: final values and per-frame series; its books balance
  const auto& e = j["energy"];
  CHECK(e["substeps"] == 3);
  const double balance = e["kinetic_change"].get<double>() + e["gravitational_change"].get<double>() -
                         e["magnetic_work"].get<double>() - e["eddy_work"].get<double>() -
                         e["contact_work"].get<double>() +
                         e["gravity_drift"].get<double>();
  CHECK(std::abs(balance) <= 1e-12 + 1e-9 * std::abs(e["magnetic_work"].get<double>()));
  CHECK(e["kinetic"].get<double>() == Approx(j["final"]["kinetic_energy"].get<double>()).epsilon(1e-12));
  // the rotational part of the final kinetic energy: balls rolling on one another spin
  CHECK(j["final"]["rotational_energy"].get<double>() >= 0);
  CHECK(j["final"]["rotational_energy"].get<double>() <= j["final"]["kinetic_energy"].get<double>());
  CHECK(e["magnetic_energy"].get<double>() < 0);  // iron drawn to the magnet: bound
  CHECK(e["escaped_bodies"]["count"] == j["final"]["escaped"]);
  CHECK(e["contact_work_in"].get<double>() >= 0);
  for (const char* k : {"energy_kinetic", "energy_gravitational", "energy_magnetic_work",
                        "energy_contact_work", "energy_eddy_work", "energy_magnetic"})
    CHECK(j["series"][k].size() == j["series"]["time"].size());
}

TEST_CASE("magsim-scene: --force-model zeeman-total and --softening reach the run", "[tools]") {
  const std::string out = tmp_dir("total");
  const Result r = run_scene("balls_up --steps 3 --no-render --count 20 --force-model zeeman-total "
                             "--softening 0.002 --out " + out);
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::ifstream f(out + "/summary.json");
  REQUIRE(f.good());
  const auto j = nlohmann::json::parse(f);
  CHECK(j["options"]["force_model"] == "zeeman-total");
  CHECK(j["options"]["magnetics"]["field"]["softening"] == 0.002);
}

TEST_CASE("magsim-scene: the default broad phase is sweep and prune", "[tools]") {
  const std::string out = tmp_dir("default");
  const Result r = run_scene("balls_up --steps 1 --no-render --count 20 --out " + out);
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::ifstream f(out + "/summary.json");
  REQUIRE(f.good());
  CHECK(nlohmann::json::parse(f)["options"]["space"] == "sap");
}

TEST_CASE("magsim-scene refuses bad ODE flags with a message and exit code 1", "[tools]") {
  struct Case {
    const char* args;
    const char* says;
  };
  const Case cases[] = {
      {"balls_up --steps 1 --no-render --space octree", "--space: unknown broad phase 'octree' (hash, sap, simple)"},
      {"balls_up --steps 1 --no-render --quickstep-iterations 0", "--quickstep-iterations"},
      {"balls_up --steps 1 --no-render --quickstep-iterations many", "--quickstep-iterations"},
      {"balls_up --steps 1 --no-render --softening -0.001", "--softening"},
      {"balls_up --steps 1 --no-render --softening 1", "--softening"},
      {"balls_up --steps 1 --no-render --force-model total",
       "--force-model: unknown force model 'total' (method, zeeman, classic, zeeman-total)"},
      {"balls_up --steps 1 --no-render --substep-load maybe", "--substep-load"},
      {"balls_up --steps 1 --no-render --bounded-pairs yes", "--bounded-pairs"},
      {"balls_up --steps 1 --no-render --balance-magnetic-torque yes", "--balance-magnetic-torque"},
      // balls_up's forces are not reaction-symmetric: the balance has nothing to balance
      {"balls_up --steps 1 --no-render --balance-magnetic-torque on", "needs reaction_symmetric_forces"},
  };
  for (const Case& c : cases) {
    const Result r = run_scene(c.args);
    INFO(c.args << ": exit " << r.code << ", said: " << r.out);
    CHECK(r.code == 1);
    CHECK(r.out.find(c.says) != std::string::npos);
  }
}

TEST_CASE("magsim-scene: summary.json's options, replayed as a scene file's, reproduce the run's state hash", "[tools]") {
  // a run whose options differ from the scene's in many places
  const std::string out = tmp_dir("replay");
  const Result r = run_scene("balls_up --count 27 --steps 50 --no-render --space hash --dt-m 8e-8 --tol 3e-5 "
                             "--quickstep-iterations 40 --quickstep-w 1.2 --rolling-friction 1e-4 --rolling-friction-bodies 2e-4 "
                             "--eddy-conductivity 5e6 --max-substeps 2 "
                             "--substep-load off "
                             "--method anderson --threads 1 --out " + out);
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::ifstream f(out + "/summary.json");
  const auto summary = nlohmann::json::parse(f);
  CHECK(summary["options"]["magnetics"]["dt"] == 8e-8);
  CHECK(summary["options"]["magnetics"]["method"] == "anderson");
  CHECK(summary["options"]["substep_load"] == false);
  CHECK(summary["options"]["rolling_friction_bodies"] == 2e-4);
  CHECK(summary["options"]["eddy_conductivity"] == 5e6);
  CHECK(summary["energy"]["eddy_work"].get<double>() < 0);  // the balls move in the magnet's field
  // the registry scene's bodies with the summary's options, read as a scene file
  magsim::scenes::SceneParams p;
  p.count = 27;
  nlohmann::json scene = magsim::scenes::scene_to_json(magsim::scenes::find_scene("balls_up")->build(p));
  scene["options"] = summary["options"];
  magsim::engine::Simulation sim(magsim::scenes::parse_scene_json(scene.dump(), "replay.json"));
  sim.run(50);
  char hash[19];
  std::snprintf(hash, sizeof hash, "%016" PRIx64, sim.state_hash());
  CHECK(std::string(hash) == summary["state_hash"].get<std::string>());
  // and not by accident: the scene's own options give another hash
  magsim::engine::Simulation plain(magsim::scenes::find_scene("balls_up")->build(p));
  plain.run(50);
  CHECK(plain.state_hash() != sim.state_hash());
}

TEST_CASE("magsim-scene NAME --write-scene FILE: the file runs to the registry run's state hash", "[tools]") {
  const std::string dir = tmp_dir("write_scene");
  const std::string file = dir + "_balls_up.json";
  const Result w = run_scene("balls_up --write-scene " + file);
  INFO(w.out);
  REQUIRE(w.code == 0);
  const Result a = run_scene("balls_up --steps 50 --no-render --out " + dir + "/registry");
  const Result b = run_scene(file + " --steps 50 --no-render --out " + dir + "/file");
  INFO(a.out << b.out);
  REQUIRE(a.code == 0);
  REQUIRE(b.code == 0);
  std::ifstream fa(dir + "/registry/summary.json"), fb(dir + "/file/summary.json");
  const auto ja = nlohmann::json::parse(fa), jb = nlohmann::json::parse(fb);
  CHECK(jb["bodies"] == 244);
  CHECK(jb["source"] == file);
  CHECK(ja["state_hash"] == jb["state_hash"]);
  CHECK(ja["options"] == jb["options"]);
}

TEST_CASE("tools/ensemble.py: one row per perturbed run, each from its summary.json, and the spread", "[tools]") {
  const std::string out = tmp_dir("ensemble");
  const std::string py = std::string("MAGSIM_SCENE_BIN=") + MAGSIM_SCENE_BIN + " /usr/bin/python3";
  const Result r = magsim::test::run_command(
      py, std::string(MAGSIM_SOURCE_DIR) + "/tools/scripts/ensemble.py balls_up --runs 2 --seconds 0.02 --base-count 20 --out " +
              out + " -- --threads 1");
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::ifstream f(out + "/ensemble.json");
  REQUIRE(f.good());
  const auto j = nlohmann::json::parse(f);
  REQUIRE(j["runs"].size() == 2);
  double sum = 0;
  for (int k = 0; k < 2; ++k) {
    const auto& row = j["runs"][k];
    CHECK(row["count"] == 20 - k);
    std::ifstream sf(out + "/run_" + std::to_string(20 - k) + "/summary.json");
    REQUIRE(sf.good());
    const auto s = nlohmann::json::parse(sf);
    CHECK(s["dynamic_bodies"] == 20 - k);  // one ball fewer each run
    CHECK(row["escaped"] == s["final"]["escaped"]);
    CHECK(row["held"] == s["final"]["held"]);
    CHECK(row["max_speed_end"].get<double>() == s["final"]["max_speed"].get<double>());
    sum += row["escaped"].get<double>();
  }
  CHECK(j["stats"]["escaped"]["mean"].get<double>() == Approx(sum / 2));
  CHECK(j["failed"] == 0);
  // bad usage: exit 2 and a one-line reason
  for (const char* bad : {"balls_up --runs 0", "balls_up --seconds -1", "nosuch_scene", "balls_up --frobnicate"}) {
    const Result b = magsim::test::run_command(py, std::string(MAGSIM_SOURCE_DIR) + "/tools/scripts/ensemble.py " + bad);
    INFO(bad << ": " << b.out);
    CHECK(b.code == 2);
    CHECK(b.out.find("ensemble.py:") != std::string::npos);
  }
}
