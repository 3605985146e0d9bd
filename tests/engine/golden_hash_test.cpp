// tests/engine/golden_hash_test.cpp — results that must not change by accident: each
// registry scene run for a fixed number of steps ends in a stored state hash, and every ODE
// broad phase gives the same hash (the contacts are sorted into a fixed order,
// engine/ode_bridge.cpp).
#include "engine/simulation.hpp"
#include "magnetics/field_kernel.hpp"
#include "scenes/registry.hpp"

#include <catch2/catch.hpp>

#include <cinttypes>
#include <cstdio>
#include <string>

using namespace magsim;

namespace {

std::string hex(std::uint64_t h) {
  char b[19];
  std::snprintf(b, sizeof b, "%016" PRIx64, h);
  return b;
}

// The scene at its registry size, `steps` rigid steps on one magnetics thread (the hash does
// not depend on the thread count; one thread is the fastest on a busy machine).
std::string run_hash(const char* name, long steps, engine::SpaceKind space, int count = 0) {
  scenes::SceneParams p;
  p.count = count;
  engine::SceneDesc d = scenes::find_scene(name)->build(p);
  d.options.threads = 1;
  d.options.space = space;
  engine::Simulation sim(d);
  sim.run(steps);
  return hex(sim.state_hash());
}

}  // namespace

#if MAGSIM_GOLDEN_HASHES
// Stored hashes of the five registry scenes after 100 rigid steps (the Release build with
// MAGSIM_NATIVE on this project's CI machine, AMD EPYC with AVX-512: the field kernel and
// Eigen take the CPU's SIMD paths, so another CPU or the sanitizer/Debug builds round
// differently and CMake leaves this test out there; tests/engine/CMakeLists.txt).
// A change that alters results fails here. When the change is meant to alter them (a new
// default, a fixed bug), say so in the commit, run this test, and copy the "now" hashes it
// prints into the table; a refactor must leave them as they are.
TEST_CASE("golden state hashes: the five registry scenes after 100 steps", "[golden]") {
  struct Golden {
    const char* scene;
    const char* hash;
  };
  const Golden golden[] = {
      {"balls_up", "a95d03b1a1d85ead"},
      {"alphabets", "a08347b1f131819d"},
      {"falling_magnet", "238b3fe44529569e"},
      {"sakura_tree", "52b314053185f5da"},
      {"crystal_balls", "3938248ff8cd8a71"},
  };
  if (!mag::detail::simd_kernel_active()) {
    // the stored values come from the AVX-512 field kernels; the portable ones round otherwise
    WARN("no AVX-512 on this CPU: the golden hashes (made with the AVX-512 kernels) are not checked");
    return;
  }
  for (const Golden& g : golden) {
    const std::string now = run_hash(g.scene, 100, engine::SpaceKind::SweepAndPrune);
    INFO(g.scene << ": now " << now << ", stored " << g.hash);
    CHECK(now == g.hash);
  }
}
#endif

TEST_CASE("every broad phase (sap, hash, simple) gives the same state hash", "[golden]") {
  // balls resting on the ground and on each other from the first step: contacts every step
  for (const char* scene : {"balls_up", "falling_magnet"}) {
    const std::string sap = run_hash(scene, 150, engine::SpaceKind::SweepAndPrune, 150);
    INFO(scene << ": sap " << sap);
    CHECK(run_hash(scene, 150, engine::SpaceKind::Hash, 150) == sap);
    CHECK(run_hash(scene, 150, engine::SpaceKind::Simple, 150) == sap);
  }
}
