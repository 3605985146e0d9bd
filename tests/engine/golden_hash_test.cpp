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
#if defined(__x86_64__) && defined(__GLIBC__)
#include <sys/platform/x86.h>  // CPU_FEATURE_ACTIVE: the CPU features glibc uses
#endif

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
// Stored hashes of the five registry scenes after 100 rigid steps, one table per path whose
// rounding is fixed by the build and by the variants of tanh, log1p, exp, sin, … that glibc's
// libm (Debian 12, glibc 2.36) picks at run time: its FMA ones where FMA and AVX2 are
// active, else its SSE2/AVX ones, which round alike; they differ from the FMA ones in the
// last bit now and then, and one such bit changes a hash.
// - kAvx512: a Release build with MAGSIM_NATIVE on a CPU with AVX-512 (AVX-512 field
//   kernels, the rest at -march=native's AVX2+FMA; made on this project's CI machine, AMD
//   EPYC, and the same on an Intel Xeon).
// - kNativeAvx2Fma: the same build with the portable field kernels, on a CPU with AVX2 and
//   FMA but without AVX-512 or with MAGSIM_KERNEL=portable (the same with -march=haswell).
// - kPortable, kPortablePlainLibm: any build with -DMAGSIM_NATIVE=OFF (baseline x86-64, no
//   FMA, the portable kernels only; CMakeLists.txt), Release and ASan+UBSan alike, on every
//   x86-64 CPU; the second where libm takes its SSE2/AVX variants (a CPU without FMA or
//   AVX2, or GLIBC_TUNABLES=glibc.cpu.hwcaps=-FMA,-AVX2).
// Where no table applies (a native build without FMA, libm's FMA4 variants of old AMD CPUs,
// not x86-64 glibc) the test says so and checks nothing: FAIL would blame the change.
// A change that alters results fails here. When the change is meant to alter them (a new
// default, a fixed bug), say so in the commit, run this test in the native and the portable
// build (tools/scripts/test.sh, tools/scripts/test.sh --portable) with MAGSIM_KERNEL unset
// and =portable, and with GLIBC_TUNABLES as above, and copy the "now" hashes it prints into
// the tables; a refactor must leave them as they are.
namespace {

struct Golden {
  const char* scene;
  const char* hash;
};

const Golden kAvx512[] = {
    {"balls_up", "a95d03b1a1d85ead"},
    {"alphabets", "da016a6d515a4991"},
    {"falling_magnet", "7355e609ceea07ec"},
    {"sakura_tree", "244bf27ce9238f95"},
    {"crystal_balls", "3938248ff8cd8a71"},
};

const Golden kNativeAvx2Fma[] = {
    {"balls_up", "6884994471367f75"},
    {"alphabets", "562a62ff5485ae06"},
    {"falling_magnet", "abc3c4912e8527a4"},
    {"sakura_tree", "a557376e0123de8e"},
    {"crystal_balls", "94c3c759b96a9f85"},
};

const Golden kPortable[] = {
    {"balls_up", "94239bb97e8d3e69"},
    {"alphabets", "02804e124b7affb1"},
    {"falling_magnet", "985504671618a667"},
    {"sakura_tree", "a38869e0a4bc5097"},
    {"crystal_balls", "944c301ec9d67fad"},
};

const Golden kPortablePlainLibm[] = {
    {"balls_up", "049979a4ba1772b6"},
    {"alphabets", "92304a322b8645a6"},
    {"falling_magnet", "78ef96e6c8a7d11f"},
    {"sakura_tree", "efefc94f95cb4359"},
    {"crystal_balls", "944c301ec9d67fad"},
};

void check_hashes(const Golden (&table)[5], const char* path) {
  for (const Golden& g : table) {
    const std::string now = run_hash(g.scene, 100, engine::SpaceKind::SweepAndPrune);
    INFO(path << ", " << g.scene << ": now " << now << ", stored " << g.hash);
    CHECK(now == g.hash);
  }
}

/// Which variants glibc's libm runs here (its ifunc rule for tanh, log1p, exp, sin, …).
enum class Libm { Fma, Fma4, Plain, Unknown };
Libm libm_variants() {
#if defined(__x86_64__) && defined(__GLIBC__)
  if (CPU_FEATURE_ACTIVE(FMA) && CPU_FEATURE_ACTIVE(AVX2)) return Libm::Fma;
  if (CPU_FEATURE_ACTIVE(FMA4)) return Libm::Fma4;
  return Libm::Plain;
#else
  return Libm::Unknown;
#endif
}

}  // namespace

TEST_CASE("golden state hashes: the five registry scenes after 100 steps", "[golden]") {
  const Libm libm = libm_variants();
#ifdef MAGSIM_PORTABLE_KERNELS
  REQUIRE_FALSE(mag::detail::simd_kernel_active());  // the portable build has no AVX-512 path
  if (libm == Libm::Fma) {
    check_hashes(kPortable, "portable build, libm's FMA variants");
  } else if (libm == Libm::Plain) {
    check_hashes(kPortablePlainLibm, "portable build, libm's SSE2/AVX variants");
  } else {
    WARN("no golden hashes for this libm: FMA4 variants (AMD family 15h) or not x86-64 glibc");
  }
#else
  if (libm != Libm::Fma) {
    WARN("native build without libm's FMA variants: no golden hashes here; a build with "
         "-DMAGSIM_NATIVE=OFF (tools/scripts/test.sh --portable) checks them on any x86-64 CPU");
  } else if (mag::detail::simd_kernel_active()) {
    check_hashes(kAvx512, "native build, AVX-512 kernels");
  } else {
#if defined(__AVX2__) && defined(__FMA__)
    check_hashes(kNativeAvx2Fma, "native build (AVX2+FMA), portable kernels");
#else
    WARN("native build without AVX2 and FMA: no golden hashes for its rounding; a build with "
         "-DMAGSIM_NATIVE=OFF (tools/scripts/test.sh --portable) checks them on any x86-64 CPU");
#endif
  }
#endif
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
