// tests/engine/state_test.cpp — the state hash and save/restore.
#include "engine/simulation.hpp"
#include "engine/state.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <cstring>

using namespace magsim;
using namespace magsim::test;

TEST_CASE("state: the hash sees every bit of poses, velocities and magnetizations", "[state]") {
  engine::Simulation sim(pile_under_magnet(2));
  sim.run(5);
  const engine::State a = sim.save_state();
  engine::State b = a;
  CHECK(engine::state_hash(a) == engine::state_hash(b));
  CHECK(engine::state_hash(a) == sim.state_hash());

  // flip the lowest mantissa bit of one component
  auto flip = [](double* x) {
    std::uint64_t u;
    std::memcpy(&u, x, 8);
    u ^= 1u;
    std::memcpy(x, &u, 8);
  };
  flip(&b.mag.M1[3].y());
  CHECK(engine::state_hash(a) != engine::state_hash(b));
  b = a;
  flip(&b.angvel[2].z());
  CHECK(engine::state_hash(a) != engine::state_hash(b));
  b = a;
  flip(&b.quat[4].w());
  CHECK(engine::state_hash(a) != engine::state_hash(b));
}

TEST_CASE("state: save/restore round-trips and reproduces the continuation", "[state]") {
  engine::Simulation sim(pile_under_magnet(3));
  sim.run(100);
  const engine::State saved = sim.save_state();
  const std::uint64_t h100 = sim.state_hash();
  sim.run(100);
  const std::uint64_t h200 = sim.state_hash();
  REQUIRE(h200 != h100);

  sim.restore_state(saved);
  CHECK(sim.steps() == 100);
  CHECK(sim.time() == Approx(0.1));
  CHECK(sim.state_hash() == h100);
  sim.run(100);
  CHECK(sim.state_hash() == h200);

  // and in a fresh simulation of the same scene
  engine::Simulation other(pile_under_magnet(3));
  other.restore_state(saved);
  other.run(100);
  CHECK(other.state_hash() == h200);
}

TEST_CASE("state: a restored state keeps the sub-step choice of the original", "[state][substeps]") {
  // the number of sub-steps reads the last frame's velocity change and magnetic load
  // (State::dvel, State::mag_accel): a fresh simulation restored from a state must split
  // its frames as the original did
  SceneDesc s = pile_under_magnet(3, 4.0);
  s.options.max_substeps = 16;
  engine::Simulation sim(s);
  sim.run(60);
  const engine::State saved = sim.save_state();
  int split = 0;
  for (int k = 0; k < 40; ++k) {
    sim.step();
    split += sim.last_profile().substeps > 1;
  }
  REQUIRE(split > 0);  // the test means something only if frames were split
  engine::Simulation other(s);
  other.restore_state(saved);
  other.run(40);
  CHECK(other.state_hash() == sim.state_hash());
}

TEST_CASE("state: restore rejects a state of another model or with non-finite values", "[state]") {
  engine::Simulation sim(pile_under_magnet(2));
  engine::Simulation small(pile_under_magnet(1));
  CHECK_THROWS_AS(sim.restore_state(small.save_state()), std::invalid_argument);
  engine::State s = sim.save_state();
  s.vel[1].x() = std::nan("");
  CHECK_THROWS_AS(sim.restore_state(s), std::invalid_argument);
}
