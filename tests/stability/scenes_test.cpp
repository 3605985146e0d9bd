// Paper §5 claims on the demo scenes, each asserted for both methods (a contrast test that
// passed for both would prove nothing). Thresholds come from measured runs, with margin.
#include "tests/stability/run_scene.hpp"

#include <catch2/catch.hpp>

using namespace magsim;
using mag::Method;
using test::run_scene;

TEST_CASE("balls_up: ours lifts the pile onto the magnet and it settles, Kim 2018 lifts almost none",
          "[stability][balls_up]") {
  // 243 balls, 2 s, trailing window 0.5 s. Measured (ours = the engine default,
  // ours-realigned, with the scene's motion sub-steps, ≤ 8 per frame): 243 of 243 attached,
  // none escaped (beyond the scene's 0.15 m), fastest body in the window 0.11 m/s. Over
  // 238–243 balls ours throws 0–2 balls by 2 s (1–9 in one step per frame: a ball climbed a
  // side face of the magnet and went over its top edge at 12 m/s; issue #12). Kim 2018, same
  // sub-steps: the classic force lifts 3 balls; the rest, magnetized side by side, repel and
  // slide off over the frictionless ground (182 escaped), 2.1e-2 J in the window.
  const auto ours = run_scene("balls_up", Method::OursRealigned, 2.0, 0.5);
  INFO("ours: attached " << ours.min_attached_tail << ", escaped " << ours.last.escaped
                         << ", fastest not escaped " << ours.tail_max_speed_inside << " m/s");
  REQUIRE_FALSE(ours.failed);
  CHECK(ours.min_attached_tail >= 235);     // measured 243; Kim 2018: 3
  CHECK(ours.last.escaped <= 3);            // measured 0 (0–2 over 238–243 balls); Kim 2018: 182
  CHECK(ours.tail_max_speed_inside < 0.5);  // m/s; ~4x the measured 0.11
  const auto kim = run_scene("balls_up", Method::Kim2018, 2.0, 0.5);
  INFO("kim2018: attached " << kim.min_attached_tail << ", escaped " << kim.last.escaped << ", KE "
                            << kim.tail_max_ke << " J");
  REQUIRE_FALSE(kim.failed);
  CHECK(kim.min_attached_tail < 100);  // measured 3
  CHECK(kim.last.escaped > 100);       // measured 182
  CHECK(kim.tail_max_ke > 1e-3);       // J; measured 2.1e-2
}

TEST_CASE("balls_up at 3x strength with 20 QuickStep iterations keeps its pile: robustness corners",
          "[stability][balls_up][robustness]") {
  // Corners of tools/robustness.sh (1 s, ×3 = 24 A·m², 20 QuickStep iterations instead of
  // the scene's 100). Measured with the scene's motion sub-steps (≤ 8 per frame), fastest
  // body over every step and balls beyond 0.15 m at 1 s: 24.1 m/s and 4 (W 1.0, 1 ms), 13.6
  // and 3 (W 1.0, 2 ms), 27.6 and 2 (W 1.3, 1 ms); the matrix, sampling frames at 60 fps,
  // saw 14.4, 11.7 and 12.1 m/s. In one step per frame the same runs reached 56, 90 and
  // 72 m/s at those frames and threw all 243 balls (issue #12).
  struct Corner {
    double w, dt;
  };
  for (const Corner c : {Corner{1.0, 0.001}, Corner{1.0, 0.002}, Corner{1.3, 0.001}}) {
    const auto r = run_scene("balls_up", Method::OursRealigned, 1.0, 0.1, 0, 3.0, 0.0,
                             [&](engine::SceneDesc& d) {
                               d.options.quickstep_w = c.w;
                               d.options.quickstep_iterations = 20;
                               d.options.dt = c.dt;
                             });
    INFO("W " << c.w << ", dt " << c.dt << ": peak " << r.max_speed << " m/s, escaped "
              << r.last.escaped << ", KE " << r.last.kinetic_energy << " J");
    REQUIRE_FALSE(r.failed);
    CHECK(r.max_speed < 50.0);    // m/s; 1.8x the measured 27.6
    CHECK(r.last.escaped <= 12);  // measured 2-4; one step per frame: 243
  }
}

TEST_CASE("falling_magnet without magnetism comes to rest: rolling resistance on the ground",
          "[stability][falling_magnet]") {
  // The mechanical control of issue #12: the 12×12×8 block collapses under the falling
  // magnet (strength 0.001: no magnetic force to speak of), and the issue asks that no ball
  // move faster than 0.1 m/s in the last of 2 s. Without rolling resistance the balls rolled
  // on for ever (final KE 0.126 J, 0.69 m/s through the last second, 17 beyond 1 m at 2 s).
  // With the scene's ρ = 0.2 r but ODE's 20 QuickStep iterations the heap still crept: small
  // avalanches at 0.21 m/s at 1.86 s (final KE 7.8e-6 J). With the scene's 50 iterations,
  // measured here (every 5 steps): 0.048 m/s, final KE 4.2e-7 J; at 50 fps over 4 runs with
  // 1032…1029 balls 0.014–0.054 m/s (20 iterations: 0.06–0.32, two of four above 0.1).
  const auto r = run_scene("falling_magnet", Method::OursRealigned, 2.0, 1.0, 0, 0.001);
  INFO("last second: fastest " << r.tail_max_speed << " m/s; KE " << r.last.kinetic_energy
                               << " J; escaped " << r.last.escaped);
  REQUIRE_FALSE(r.failed);
  CHECK(r.tail_max_speed < 0.1);        // m/s; the bound, 2× the measured 0.048
  CHECK(r.last.kinetic_energy < 1e-5);  // J; 24× the measured 4.2e-7
  CHECK(r.last.escaped == 0);           // none beyond 1 m (17 without resistance)
}

TEST_CASE("falling_magnet: the magnet lands in the heap and holds it, nothing is thrown far",
          "[stability][falling_magnet]") {
  // The paper's Fig. 5 on our side (issue #12 asks a contrast test; Kim 2018 does not fail
  // here, so it is stated, not asserted): 1032 balls, 1 s, the scene's defaults (eq. 4,
  // softening 2.5 mm, up to 8 motion sub-steps). Measured (every 5 steps): 647 held, 933
  // attached, none beyond 1 m, fastest ball 8.1 m/s (as the magnet lands), 0.78 m/s in the
  // last 0.2 s (648, 939 and 1.6 m/s while a ball rolling on the floor still split frames);
  // at 2 s, over 1032…1029 balls, 0–2 beyond 1 m. Kim 2018 (its magnetization,
  // the classic force), 1 s, frames at 60 fps: 596 held, 941 attached, none beyond 1 m,
  // fastest 5.6 m/s: it does not scatter the balls as the paper's Fig. 5b shows (README).
  const auto r = run_scene("falling_magnet", Method::OursRealigned, 1.0, 0.2);
  INFO("held " << r.last.held << ", attached " << r.last.attached << ", escaped "
               << r.last.escaped << ", fastest " << r.max_speed << " m/s, in the last 0.2 s "
               << r.tail_max_speed << " m/s");
  REQUIRE_FALSE(r.failed);
  CHECK(r.last.held >= 400);     // measured 647
  CHECK(r.last.escaped <= 6);    // measured 0 (issue #12 found 52 beyond 1 m at 2 s)
  CHECK(r.max_speed < 20.0);     // m/s; 2.5x the measured 8.1
}

TEST_CASE("falling_magnet at 3x strength with 40 QuickStep iterations: the torque balance stops the runaway",
          "[stability][falling_magnet][torque_balance]") {
  // eq. 4's reaction-symmetric forces sum to zero but leave a net torque (about 1 N·m in the
  // 1032-ball scene at ×3, apply_forces.cpp); with 40 iterations it spins and rolls the magnet
  // and its heap across the floor while the magnetic work keeps growing (1031 balls, 2 s: KE
  // 17.1 J, 248 beyond 1 m). 600 balls, 0.5 s, measured (every 5 steps): without the balance
  // KE up to 11.6 J in the last 0.1 s, with it 0.10 J (1 and 0 beyond 1 m; the landing's
  // fastest ball 18.7 and 21.4 m/s either way, so that is not asserted). 600, 599, 598 balls
  // at 0.5 s (20 fps): KE 11.6, 10.7, 5.7 J without, 0.09, 0.21, 0.30 with; at 1 s 166, 154,
  // 88 balls beyond 1 m without, 2, 4, 6 with.
  auto run = [](bool balance) {
    return run_scene("falling_magnet", Method::OursRealigned, 0.5, 0.1, 600, 3.0, 0.0,
                     [balance](engine::SceneDesc& d) {
                       d.options.quickstep_iterations = 40;
                       d.options.balance_magnetic_torque = balance;
                     });
  };
  const auto off = run(false);
  const auto on = run(true);
  INFO("KE in the last 0.1 s: without the balance " << off.tail_max_ke << " J, with it " << on.tail_max_ke
                                                     << " J; escaped " << off.last.escaped << ", " << on.last.escaped
                                                     << "; fastest " << off.max_speed << ", " << on.max_speed << " m/s");
  REQUIRE_FALSE(off.failed);
  REQUIRE_FALSE(on.failed);
  CHECK(off.tail_max_ke > 2.0);  // J; measured 11.6
  CHECK(on.tail_max_ke < 1.0);   // J; measured 0.10
}

TEST_CASE("sakura_tree: balls land on the branch-end magnets and stay without being flung",
          "[stability][sakura_tree]") {
  // 500 balls (23 × 23 sheet over the tree), 0.6 s: they reach the tips at ≈ 0.16 s. Measured
  // with ours-realigned: fastest ball over the run 8.3 m/s (free fall alone gives 2.8 m/s at
  // the ground), 220 balls held by the magnets at the end (9.95 and 205 before the scene
  // resisted rolling between balls). With 20 A·m² point moments on 4 mm
  // twigs instead of sphere magnets with colliders, balls were flung at 10²–10⁴ m/s and the
  // tree was bare by 0.5 s: this test fails on that scene.
  const auto r = run_scene("sakura_tree", Method::OursRealigned, 0.6, 0.1, 500);
  INFO("max speed " << r.max_speed << " m/s, attached " << r.last.attached << ", KE "
                    << r.last.kinetic_energy << " J");
  REQUIRE_FALSE(r.failed);
  CHECK(r.max_speed < 20.0);       // m/s; 2.4× the measured 8.3
  CHECK(r.last.attached >= 150);   // measured 220
}

TEST_CASE("sakura_tree with QuickStep W 1.0: bounded pairs keep the balls on the tips, point pairs throw them",
          "[stability][sakura_tree][robustness]") {
  // A corner of tools/robustness.sh (W 1.0 instead of the scene's 1.3), 500 balls, 0.6 s.
  // QuickStep at W 1.0 leaves two balls at a tip closer than touching, their point-dipole
  // pull grows as 1/d⁴, and the pair is thrown (2500 balls: two balls 5.6 mm apart, 8 mm
  // across, left at 94 m/s at 0.196 s). The scene evaluates each pair no closer than the
  // two radii summed (bounded pairs), so an overlap cannot raise the pull. Measured here
  // (every 5 steps): with them fastest ball 7.5 m/s, 6 beyond 0.5 m, 215 held; without
  // them 149 m/s and 53 beyond 0.5 m.
  // Rolling resistance between balls is off in both runs, as when this test was made: it
  // changes the paths of the balls at the tips (with ρ = 0.2 r between balls the point-pairs
  // run peaked at 7.5 m/s), and this test is about the pairs.
  auto w_one = [](bool bounded) {
    return [bounded](engine::SceneDesc& d) {
      d.options.quickstep_w = 1.0;
      d.options.magnetics.field.bounded_pairs = bounded;
      d.options.rolling_friction_bodies = 0.0;
    };
  };
  const auto off = run_scene("sakura_tree", Method::OursRealigned, 0.6, 0.1, 500, 1.0, 0.0, w_one(false));
  INFO("point pairs: fastest " << off.max_speed << " m/s, escaped " << off.last.escaped);
  CHECK((off.failed || off.max_speed > 50.0));  // m/s; measured 149
  const auto on = run_scene("sakura_tree", Method::OursRealigned, 0.6, 0.1, 500, 1.0, 0.0, w_one(true));
  INFO("bounded pairs: fastest " << on.max_speed << " m/s, escaped " << on.last.escaped
                                 << ", held " << on.last.held);
  REQUIRE_FALSE(on.failed);
  CHECK(on.max_speed < 20.0);      // m/s; the matrix's bound, 2.7× the measured 7.5
  CHECK(on.last.escaped <= 20);    // measured 6; point pairs: 53
}

TEST_CASE("sakura_tree: rolling resistance between balls stops the balls at the tips spinning and swinging",
          "[stability][sakura_tree]") {
  // 500 balls, 1.2 s (they reach the tips at 0.16 s). A ball that hangs on one neighbour at
  // a tip rolls to and fro on it without loss unless the contact between the two balls
  // resists rolling (tests/engine/rolling_test.cpp shows the mechanism on two balls). The
  // scene's default has ρ = 0.2 r between balls as on the ground. Measured here: with it
  // final KE 0.0073 J of which 0.0008 J spin; without it 0.088 J of which 0.080 J spin
  // (balls at the tips spinning at hundreds of rad/s).
  const auto with = run_scene("sakura_tree", Method::OursRealigned, 1.2, 0.2, 500);
  const auto without = run_scene("sakura_tree", Method::OursRealigned, 1.2, 0.2, 500, 1.0, 0.0,
                                 [](engine::SceneDesc& d) { d.options.rolling_friction_bodies = 0.0; });
  INFO("with: KE " << with.last.kinetic_energy << " J, spin " << with.last.rotational_energy
                   << " J; without: " << without.last.kinetic_energy << " J, spin "
                   << without.last.rotational_energy << " J");
  REQUIRE_FALSE(with.failed);
  REQUIRE_FALSE(without.failed);
  CHECK(with.last.rotational_energy < 0.008);     // J; 10x the measured 0.0008
  CHECK(without.last.rotational_energy > 0.03);   // J; measured 0.080
  CHECK(with.last.kinetic_energy < 0.5 * without.last.kinetic_energy);  // measured 0.08x
}

TEST_CASE("alphabets at 300 A m^2: ours gathers the letters and they come to rest, Kim 2018 keeps them moving, in one step per frame they are flung",
          "[stability][alphabets]") {
  // The bottom layer of the grid (25 letters, 10.5 cm below the 300 A·m² centre), 1.2 s,
  // trailing window 0.5 s: they reach the collider at ≈ 0.2 s. Measured with the scene's up
  // to 16 sub-steps (load and motion, substeps.cpp): all 25 held in the centre's cluster,
  // none beyond 0.3 m, fastest letter 24.5 m/s while gathering, 0.39 m/s in the window,
  // 0.039 m/s at the end. Kim 2018, same sub-steps: 21 of 25 held, 5.9 m/s in the window
  // (with 100 letters its magnetization hits the cap in 1866 of 2000 frames, ours in 35,
  // registry.cpp). The same run in one ODE step per frame (max_substeps 1) reached 170 m/s
  // and threw 9 letters out.
  const auto r = run_scene("alphabets", Method::OursRealigned, 1.2, 0.5, 25);
  INFO("held " << r.last.held << ", escaped " << r.last.escaped << ", fastest " << r.max_speed
               << " m/s, in the window " << r.tail_max_speed << " m/s, at the end "
               << r.last.max_speed << " m/s");
  REQUIRE_FALSE(r.failed);
  CHECK(r.last.escaped == 0);
  CHECK(r.last.held == 25);
  CHECK(r.max_speed < 50.0);       // m/s; 2x the measured 24.5
  CHECK(r.tail_max_speed < 1.0);   // m/s; 2.5x the measured 0.39; Kim 2018: 5.9
  CHECK(r.last.max_speed < 0.2);   // m/s; 5x the measured 0.039
  const auto kim = run_scene("alphabets", Method::Kim2018, 1.2, 0.5, 25);
  INFO("kim2018: held " << kim.last.held << ", in the window " << kim.tail_max_speed << " m/s");
  REQUIRE_FALSE(kim.failed);
  CHECK(kim.tail_max_speed > 2.0);  // m/s; measured 5.9
  CHECK(kim.last.held < 25);        // measured 21
  const auto one = run_scene("alphabets", Method::OursRealigned, 0.6, 0.1, 25, 1.0, 0.0,
                             [](engine::SceneDesc& d) { d.options.max_substeps = 1; });
  INFO("one step per frame: fastest " << one.max_speed << " m/s, escaped " << one.last.escaped
                                      << (one.failed ? ", failed: " + one.error : std::string()));
  CHECK((one.failed || one.max_speed > 100.0));  // measured 170 m/s
}

TEST_CASE("determinism: two runs of a scene give the same state hash", "[stability]") {
  const auto a = run_scene("balls_up", Method::OursRealigned, 0.2, 0.1, 54);
  const auto b = run_scene("balls_up", Method::OursRealigned, 0.2, 0.1, 54);
  const auto c = run_scene("balls_up", Method::Kim2018, 0.2, 0.1, 54);
  CHECK(a.hash == b.hash);
  CHECK(a.hash != c.hash);
}
