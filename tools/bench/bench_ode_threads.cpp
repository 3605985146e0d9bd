// tools/bench/bench_ode_threads.cpp — what ODE's own threads (its built-in thread pool:
// islands stepped in parallel, and QuickStep's stages split across threads) give on this
// machine, and whether the run stays the same bits.
//
// Plain ODE, no magnetics: piles of 5 mm balls dropped onto the ground plane, `--piles`
// islands of `--balls` each; contacts in a sorted order, up to 4 per pair, as magsim's bridge
// makes them (here μ = 0.5, ERP 0.2, CFM 1e-9, and ODE's RNG seeded per step). Each thread
// count runs the same scene from the same start; per run: ms per step (collide + QuickStep) over the last `--window`
// steps (median) and an FNV-1a hash of the final positions and velocities, compared with the one-thread run and with a
// second run at the same thread count.
#include <ode/ode.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "tools/bench/bench_common.hpp"

namespace {

struct Run {
  double median_ms = 0;
  std::uint64_t hash = 0;
  int contacts = 0;
};

struct World {
  dWorldID world = nullptr;
  dSpaceID space = nullptr;
  dJointGroupID group = nullptr;
  std::vector<dBodyID> bodies;  ///< their geoms go with the space
  int contacts = 0;
};

struct Candidate {
  dGeomID a, b;
  dContact c;
};

void near_callback(void* data, dGeomID a, dGeomID b) {
  auto* list = static_cast<std::vector<Candidate>*>(data);
  dContactGeom cg[4];
  const int n = dCollide(a, b, 4, cg, sizeof(dContactGeom));
  for (int i = 0; i < n; ++i) {
    Candidate k{a, b, {}};
    k.c.geom = cg[i];
    k.c.surface.mode = dContactApprox1;
    k.c.surface.mu = 0.5;
    list->push_back(k);
  }
}

// the contacts in a fixed order (by the bodies' indices, then the contact point), as magsim's
// bridge makes them: the space's own order is not part of the result
void step(World& w, int iterations, unsigned long seed) {
  std::vector<Candidate> list;
  dSpaceCollide(w.space, &list, near_callback);
  auto key = [](const Candidate& k) {
    const dBodyID ba = dGeomGetBody(k.a), bb = dGeomGetBody(k.b);
    const auto ia = ba ? reinterpret_cast<std::intptr_t>(dBodyGetData(ba)) : -1;
    const auto ib = bb ? reinterpret_cast<std::intptr_t>(dBodyGetData(bb)) : -1;
    return std::make_tuple(std::min(ia, ib), std::max(ia, ib), k.c.geom.pos[0], k.c.geom.pos[1], k.c.geom.pos[2]);
  };
  std::sort(list.begin(), list.end(), [&](const Candidate& x, const Candidate& y) { return key(x) < key(y); });
  for (Candidate& k : list) {
    dJointID j = dJointCreateContact(w.world, w.group, &k.c);
    dJointAttach(j, dGeomGetBody(k.a), dGeomGetBody(k.b));
  }
  w.contacts = static_cast<int>(list.size());
  dWorldSetQuickStepNumIterations(w.world, iterations);
  dRandSetSeed(seed);  // QuickStep's row reordering draws from ODE's global RNG: seeded per step, as magsim does
  dWorldQuickStep(w.world, 0.001);
  dJointGroupEmpty(w.group);
}

World make_world(int piles, int balls) {
  World w;
  w.world = dWorldCreate();
  dWorldSetGravity(w.world, 0, 0, -9.81);
  dWorldSetERP(w.world, 0.2);
  dWorldSetCFM(w.world, 1e-9);
  w.space = dHashSpaceCreate(nullptr);
  w.group = dJointGroupCreate(0);
  dCreatePlane(w.space, 0, 0, 1, 0);
  const double r = 0.005;
  const int side = 4;  // 4 × 4 per layer
  int index = 0;
  for (int p = 0; p < piles; ++p) {
    const double px = (p % 8) * 0.1, py = (p / 8) * 0.1;  // piles 10 cm apart: separate islands
    for (int k = 0; k < balls; ++k, ++index) {
      const int i = k % side, j = (k / side) % side, l = k / (side * side);
      dBodyID b = dBodyCreate(w.world);
      dMass m;
      dMassSetSphere(&m, 7870.0, r);
      dBodySetMass(b, &m);
      // a small offset per layer so the pile does not stand as a perfect column
      dBodySetPosition(b, px + i * 2.05 * r + 0.3 * r * (l % 2), py + j * 2.05 * r + 0.3 * r * (l % 3 == 1),
                       r + l * 2.05 * r + 0.001);
      dBodySetData(b, reinterpret_cast<void*>(static_cast<std::intptr_t>(index)));
      dGeomID g = dCreateSphere(w.space, r);
      dGeomSetBody(g, b);
      w.bodies.push_back(b);
    }
  }
  return w;
}

std::uint64_t hash_state(const World& w) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&](const dReal* v, int n) {
    unsigned char bytes[sizeof(dReal) * 4];
    std::memcpy(bytes, v, sizeof(dReal) * n);
    for (std::size_t i = 0; i < sizeof(dReal) * n; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  };
  for (dBodyID b : w.bodies) {
    mix(dBodyGetPosition(b), 3);
    mix(dBodyGetLinearVel(b), 3);
  }
  return h;
}

Run run(int piles, int balls, int threads, int steps, int window, int iterations) {
  World w = make_world(piles, balls);
  dThreadingImplementationID impl = nullptr;
  dThreadingThreadPoolID pool = nullptr;
  if (threads > 1) {
    impl = dThreadingAllocateMultiThreadedImplementation();
    pool = impl ? dThreadingAllocateThreadPool(threads, 0, dAllocateFlagBasicData, nullptr) : nullptr;
    if (!impl || !pool) throw std::runtime_error("ODE has no built-in threading here");
    dThreadingThreadPoolServeMultiThreadedImplementation(pool, impl);
    dWorldSetStepThreadingImplementation(w.world, dThreadingImplementationGetFunctions(impl), impl);
    dWorldSetStepIslandsProcessingMaxThreadCount(w.world, threads);
  }
  std::vector<double> ms;
  for (int k = 0; k < steps; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    step(w, iterations, static_cast<unsigned long>(k));
    const double dt = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (k >= steps - window) ms.push_back(dt);
  }
  Run r;
  r.median_ms = magsim::bench::median(ms);
  r.hash = hash_state(w);
  r.contacts = w.contacts;
  if (impl) {
    dThreadingImplementationShutdownProcessing(impl);
    dThreadingFreeThreadPool(pool);
    dWorldSetStepThreadingImplementation(w.world, nullptr, nullptr);
    dThreadingFreeImplementation(impl);
  }
  dJointGroupDestroy(w.group);
  dSpaceDestroy(w.space);
  dWorldDestroy(w.world);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "bench_ode_threads — ODE's built-in thread pool on ball piles (no magnetics): ms per step of "
      "collide + QuickStep with 1 and more threads, one island or many, and whether the bits stay the same"};
  std::string piles_text = "1,16";
  int balls = 256, steps = 1500, window = 500, iterations = 20, max_threads = 2;
  std::string out = "out/bench/ode_threads.json";
  app.add_option("--piles", piles_text, "comma list of island counts")->capture_default_str();
  app.add_option("--balls", balls, "balls per pile")->capture_default_str()->check(CLI::Range(1, 100000));
  app.add_option("--steps", steps, "1 ms steps per run")->capture_default_str()->check(CLI::Range(1, 1000000));
  app.add_option("--window", window, "last steps whose median is reported")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  app.add_option("--iterations", iterations, "QuickStep iterations")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000));
  app.add_option("--threads", max_threads, "most threads (runs 1..N)")->capture_default_str()->check(CLI::Range(1, 64));
  app.add_option("--json", out, "where to write the JSON")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (window > steps) {
    std::fprintf(stderr, "bench_ode_threads: --window %d is longer than --steps %d\n", window, steps);
    return 1;
  }
  std::vector<int> piles;
  try {
    for (const std::string& item : magsim::bench::split(piles_text)) {
      std::size_t used = 0;
      const int p = std::stoi(item, &used);
      if (used != item.size() || p < 1 || p > 64) throw std::out_of_range(item);
      piles.push_back(p);
    }
    if (piles.empty()) throw std::out_of_range(piles_text);
  } catch (const std::exception&) {
    std::fprintf(stderr, "bench_ode_threads: --piles '%s': expected a comma list of integers in [1, 64]\n",
                 piles_text.c_str());
    return 1;
  }
  dInitODE2(0);
  dAllocateODEDataForThread(dAllocateMaskAll);
  nlohmann::json doc = {{"balls_per_pile", balls},
                        {"steps", steps},
                        {"window", window},
                        {"iterations", iterations},
                        {"runs", nlohmann::json::array()}};
  std::printf("%6s %7s %8s %10s %9s %16s %-9s %-7s\n", "piles", "bodies", "threads", "ms/step", "contacts", "hash",
              "=1 thread", "repeats");
  int rc = 0;
  try {
    for (int p : piles) {
      std::uint64_t h1 = 0;
      double t1 = 0;
      for (int t = 1; t <= max_threads; ++t) {
        // each thread count twice: the second run says whether it repeats its own bits
        const Run r = run(p, balls, t, steps, window, iterations);
        const Run again = run(p, balls, t, steps, window, iterations);
        if (t == 1) h1 = r.hash, t1 = r.median_ms;
        std::printf("%6d %7d %8d %10.3f %9d %016llx %-9s %-7s (%.2fx of 1 thread; repeat %.3f ms)\n", p, p * balls, t,
                    r.median_ms, r.contacts, static_cast<unsigned long long>(r.hash), r.hash == h1 ? "yes" : "NO",
                    again.hash == r.hash ? "yes" : "NO", r.median_ms / t1, again.median_ms);
        std::fflush(stdout);
        doc["runs"].push_back({{"piles", p},
                               {"threads", t},
                               {"median_ms", r.median_ms},
                               {"median_ms_repeat", again.median_ms},
                               {"contacts", r.contacts},
                               {"same_bits_as_one_thread", r.hash == h1},
                               {"repeats_its_bits", again.hash == r.hash}});
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_ode_threads: %s\n", e.what());
    rc = 2;
  }
  dCloseODE();
  std::filesystem::path path(out);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream(out) << doc.dump(2) << "\n";
  std::printf("bench_ode_threads: wrote %s\n", out.c_str());
  return rc;
}
