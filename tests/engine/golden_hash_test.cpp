// tests/engine/golden_hash_test.cpp — results that must not change by accident: each
// registry scene run for a fixed number of steps ends in its one stored state hash, and
// every ODE broad phase gives the same hash (the contacts are sorted into a fixed order,
// engine/ode_bridge.cpp).
#include "engine/simulation.hpp"
#include "magnetics/field_kernel.hpp"
#include "scenes/registry.hpp"

#include <catch2/catch.hpp>

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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

// The one golden table (tests/engine/golden_hashes.txt): each registry scene after 100 rigid
// steps ends in one state hash on every x86-64 CPU and path — native or portable build,
// Release, Debug or ASan+UBSan, AVX-512, FMA or generic field kernels, any thread count,
// whichever libm variants glibc picks — because nothing that reaches the state depends on
// them: no FMA contraction by the compiler, no Eigen vectorization, field kernels with a
// fixed lane count and sum tree whose multiply-adds are always fused (magnetics/simd.hpp),
// and deterministic transcendental functions (magnetics/det_math.hpp). This test checks the
// build it is in with the kernels the CPU picks, and again on each slower path;
// tools/scripts/golden_check.py runs magsim-scene under the other paths (MAGSIM_KERNEL,
// GLIBC_TUNABLES, 2 threads, the portable and -march=x86-64-v3/-v2 builds). A change meant to alter results (a new
// default, a fixed bug) says so in its commit and copies the "now" hashes printed here into
// the table; a refactor leaves them as they are.
namespace {

struct Golden {
  std::string scene, hash;
};

std::vector<Golden> golden_table() {
  std::ifstream in(std::string(MAGSIM_SOURCE_DIR) + "/tests/engine/golden_hashes.txt");
  std::vector<Golden> t;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream f(line);
    Golden g;
    f >> g.scene >> g.hash;
    t.push_back(g);
  }
  return t;
}

}  // namespace

TEST_CASE("golden state hashes: the five registry scenes after 100 steps, one hash on every path",
          "[golden]") {
  const std::vector<Golden> table = golden_table();
  REQUIRE(table.size() == 5);
  using mag::detail::KernelPath;
  const KernelPath best = mag::detail::kernel_path();
  for (KernelPath p : {KernelPath::Avx512, KernelPath::Fma, KernelPath::Generic}) {
    if (p < best) continue;  // a path this CPU or build does not have
    mag::detail::limit_kernel_path(p);
    for (const Golden& g : table) {
      // the generic kernels emulate each fused multiply-add (about 40x slower): the two
      // small scenes here, every scene in .ci/run (golden_check.py --variants generic)
      if (p == KernelPath::Generic && best != KernelPath::Generic && g.scene != "balls_up" &&
          g.scene != "crystal_balls")
        continue;
      const std::string now = run_hash(g.scene.c_str(), 100, engine::SpaceKind::SweepAndPrune);
      INFO(g.scene << " (" << mag::detail::kernel_path_name(mag::detail::kernel_path())
                   << " kernels): now " << now << ", stored " << g.hash);
      CHECK(now == g.hash);
    }
  }
  mag::detail::limit_kernel_path(KernelPath::Avx512);
}

TEST_CASE("every broad phase (sap, hash, simple) gives the same state hash", "[golden]") {
  // balls resting on the ground and on each other from the first step: contacts every step
  for (const char* scene : {"balls_up", "falling_magnet"}) {
    const std::string sap = run_hash(scene, 150, engine::SpaceKind::SweepAndPrune, 150);
    INFO(scene << ": sap " << sap);
    CHECK(run_hash(scene, 150, engine::SpaceKind::Hash, 150) == sap);
    CHECK(run_hash(scene, 150, engine::SpaceKind::Simple, 150) == sap);
  }
}
