// The paper's stability claims on the demo scenes, under the engine's default (anderson's
// converged magnetization with the classic force, −∇U*) and against a contrast that fails
// (Kim 2018, eq. 4, or the scene without one of its mechanisms): a contrast test that passed
// for both would prove nothing. Thresholds come from measured runs, with margin; each
// measured figure is stated beside its check.
#include "tests/stability/run_scene.hpp"

#include <catch2/catch.hpp>

using namespace magsim;
using mag::Method;
using test::run_scene;

TEST_CASE("balls_up: the default lifts the pile onto the magnet and holds it at rest, the paper's 2 cm cube does not",
          "[stability][balls_up]") {
  // 243 balls, 2 s, trailing window 0.5 s, the scene's 3 cm N52 cube (29.7 A·m²) and iron's
  // eddy loss. The marks read the lifted pile, the bodies the engine counts as held (the
  // paper's "stably stuck to each other and to the magnet"): balls knocked onto the
  // frictionless floor keep their speed, as they should, and are reported, not asserted.
  // Ensemble: tools/findings/energy.md, "balls_up's marks on the lifted pile" (8 runs,
  // 243…236 balls: held 142–155, the pile's fastest 0.028–0.101 m/s; 0.101 is this run of
  // 243, a ball rocking on the skirt). The contrast is the magnet eq. 4 was sized with, the
  // paper's 2 cm cube (8.8 A·m², strength 0.296): under the classic force it lifts almost
  // nothing.
  const auto def = run_scene("balls_up", Method::Anderson, 2.0, 0.5);
  const int on_floor = def.last.dynamic_bodies - def.last.held;
  INFO("default: held " << def.last.held << ", its fastest in the last 0.5 s " << def.tail_max_speed_held
                        << " m/s; not held " << on_floor << ", fastest body " << def.tail_max_speed << " m/s");
  REQUIRE_FALSE(def.failed);
  CHECK(def.last.held >= 131);
  CHECK(def.tail_max_speed_held <= 0.2);  // m/s: twice the ensemble's worst
  const auto small = run_scene("balls_up", Method::Anderson, 2.0, 0.5, 0, 8.8 / 29.7);
  INFO("2 cm cube: held " << small.last.held);
  REQUIRE_FALSE(small.failed);
  CHECK(small.last.held <= 10);
}

TEST_CASE("balls_up at 3x strength with 20 QuickStep iterations keeps its pile: robustness corners",
          "[stability][balls_up][robustness]") {
  // corners of tools/scripts/robustness.sh (1 s, ×3, 20 QuickStep iterations instead of the
  // scene's 100). Ensemble: tools/findings/energy.md, "the default suite's scene tests on
  // ensembles" (4 runs a corner, 243…240: peak 3.4–8.2 m/s, 0–1 escaped)
  struct Corner {
    double w, dt;
  };
  for (const Corner c : {Corner{1.0, 0.001}, Corner{1.0, 0.002}, Corner{1.3, 0.001}}) {
    const auto r = run_scene("balls_up", Method::Anderson, 1.0, 0.1, 0, 3.0, 0.0,
                             [&](engine::SceneDesc& d) {
                               d.options.quickstep_w = c.w;
                               d.options.quickstep_iterations = 20;
                               d.options.dt = c.dt;
                             });
    INFO("W " << c.w << ", dt " << c.dt << ": peak " << r.max_speed << " m/s, escaped "
              << r.last.escaped << ", KE " << r.last.kinetic_energy << " J");
    REQUIRE_FALSE(r.failed);
    CHECK(r.max_speed < 20.0);  // m/s: the matrix's bound
    CHECK(r.last.escaped <= 3);
  }
}

TEST_CASE("falling_magnet without magnetism comes to rest: rolling resistance on the ground",
          "[stability][falling_magnet][long]") {
  // The mechanical control: the 12×12×8 block collapses under the falling magnet (strength
  // 0.001: no magnetic force to speak of). Without rolling resistance the balls roll on for
  // ever (final KE 0.126 J, 17 beyond 1 m at 2 s). Ensemble: tools/findings/energy.md, "the
  // long tests on ensembles" (1032…1029: fastest in the last second 0.006–0.094 m/s, final
  // KE 7e-8–8e-7 J, none escaped).
  const auto r = run_scene("falling_magnet", Method::Anderson, 2.0, 1.0, 0, 0.001);
  INFO("last second: fastest " << r.tail_max_speed << " m/s; KE " << r.last.kinetic_energy
                               << " J; escaped " << r.last.escaped);
  REQUIRE_FALSE(r.failed);
  CHECK(r.tail_max_speed < 0.2);        // m/s: twice the ensemble's worst
  CHECK(r.last.kinetic_energy < 1e-4);  // J
  CHECK(r.last.escaped == 0);           // none beyond 1 m (17 without resistance)
}

TEST_CASE("falling_magnet: the magnet lands in the heap and holds it, nothing is thrown far",
          "[stability][falling_magnet][long]") {
  // 1032 balls, 1.2 s, the scene's defaults; window the last 0.2 s. Ensemble: "the long
  // tests on ensembles" (1032…1029: held 616–638, none escaped, fastest 0.13–0.50 m/s)
  const auto r = run_scene("falling_magnet", Method::Anderson, 1.2, 0.2);
  INFO("held " << r.last.held << ", attached " << r.last.attached << ", escaped "
               << r.last.escaped << ", fastest " << r.max_speed << " m/s, in the last 0.2 s "
               << r.tail_max_speed << " m/s");
  REQUIRE_FALSE(r.failed);
  CHECK(r.last.held >= 550);
  CHECK(r.last.escaped == 0);
  CHECK(r.tail_max_speed < 1.0);  // m/s
}

TEST_CASE("falling_magnet at 3x strength with 40 QuickStep iterations: the default throws nothing, eq. 4 runs away",
          "[stability][falling_magnet][long]") {
  // 600 balls, 0.6 s. eq. 4's surplus work, with its reaction-symmetric forces' net torque,
  // spun and rolled the magnet and its heap across the floor at this corner. Ensemble of the
  // default: "the long tests on ensembles" (600…597: KE in the last 0.1 s 0.0046–0.0104 J,
  // none escaped)
  auto run = [](Method m) {
    return run_scene("falling_magnet", m, 0.6, 0.1, 600, 3.0, 0.0,
                     [](engine::SceneDesc& d) { d.options.quickstep_iterations = 40; });
  };
  const auto def = run(Method::Anderson);
  INFO("default: KE in the last 0.1 s " << def.tail_max_ke << " J, escaped " << def.last.escaped << ", fastest "
                                        << def.max_speed << " m/s");
  REQUIRE_FALSE(def.failed);
  CHECK(def.tail_max_ke < 0.1);  // J
  CHECK(def.last.escaped == 0);
  const auto eq4 = run(Method::OursRealigned);
  INFO("eq. 4: KE in the last 0.1 s " << eq4.tail_max_ke << " J, escaped " << eq4.last.escaped
                                      << (eq4.failed ? ", failed: " + eq4.error : std::string()));
  CHECK((eq4.failed || eq4.tail_max_ke > 0.5));  // J; measured 46
}

TEST_CASE("sakura_tree: balls land on the branch-end magnets and stay without being flung",
          "[stability][sakura_tree]") {
  // 500 balls (23 × 23 sheet over the tree), 0.8 s: they reach the tips at ≈ 0.16 s.
  // Ensemble: tools/findings/energy.md, "the default suite's scene tests on ensembles"
  // (4 runs, 500…497: peak 5.9 m/s, held 234–235, escaped 7–9)
  const auto r = run_scene("sakura_tree", Method::Anderson, 0.8, 0.1, 500);
  INFO("max speed " << r.max_speed << " m/s, held " << r.last.held << ", escaped " << r.last.escaped
                    << ", in the last 0.1 s " << r.tail_max_speed << " m/s");
  REQUIRE_FALSE(r.failed);
  CHECK(r.max_speed < 20.0);
  CHECK(r.last.held >= 180);
  CHECK(r.last.escaped <= 15);
}

TEST_CASE("alphabets at 300 A m^2: the default gathers every letter and loses energy, Kim 2018's dynamics caps",
          "[stability][alphabets]") {
  // The bottom layer of the grid (25 letters, 9 cm below the 300 A·m² centre), 1.2 s: they
  // reach the collider at ≈ 0.2 s. |H| ≥ 2.5 Ms at the letters, where the paper's Fig. 9 has
  // Kim 2018's dynamics fail: its magnetization hits the iteration cap. Whether the last
  // letter has stopped by 1.2 s is chaos (0.015–2.5 m/s at the end over the ensemble), so it
  // is stated, not asserted; every run gathers all its letters and E only falls.
  // Ensemble: tools/findings/energy.md, "the default suite's scene tests on ensembles"
  // (6 runs, 25…20 letters).
  const auto r = run_scene("alphabets", Method::Anderson, 1.2, 0.5, 25);
  INFO("held " << r.last.held << ", escaped " << r.last.escaped << ", fastest " << r.max_speed
               << " m/s, at the end " << r.last.max_speed << " m/s, cap " << r.cap_fraction << ", E rose "
               << r.energy_rise << " J of " << r.energy_lost << " J lost");
  REQUIRE_FALSE(r.failed);
  CHECK(r.last.escaped == 0);
  CHECK(r.last.held >= 24);
  CHECK(r.cap_fraction == 0.0);
  CHECK(r.energy_lost > 20.0);                      // J
  CHECK(r.energy_rise <= 0.01 * r.energy_lost);
  const auto kim = run_scene("alphabets", Method::Kim2018, 1.2, 0.5, 25);
  INFO("kim2018: held " << kim.last.held << ", in the window " << kim.tail_max_speed << " m/s, cap "
                        << kim.cap_fraction);
  REQUIRE_FALSE(kim.failed);
  CHECK(kim.cap_fraction > 0.3);
}

TEST_CASE("determinism: two runs of a scene give the same state hash", "[stability]") {
  const auto a = run_scene("balls_up", Method::Anderson, 0.2, 0.1, 54);
  const auto b = run_scene("balls_up", Method::Anderson, 0.2, 0.1, 54);
  const auto c = run_scene("balls_up", Method::Kim2018, 0.2, 0.1, 54);
  CHECK(a.hash == b.hash);
  CHECK(a.hash != c.hash);
}
