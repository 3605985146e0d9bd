// tests/tools/cli/cpu_share_test.cpp — the busy-machine thread count.
#include "engine/simulation.hpp"
#include "tests/engine/fixtures.hpp"
#include "tools/cli/cpu_share.hpp"

#include <catch2/catch.hpp>
#include <omp.h>

#include <sched.h>
#include <unistd.h>

using namespace magsim::engine;

TEST_CASE("threads_for_load leaves other processes their cores", "[cpu_share][reliability]") {
  // 2 cores: two threads only while the others use less than a quarter of a core
  CHECK(threads_for_load(0.0, 2, 2) == 2);
  CHECK(threads_for_load(0.2, 2, 2) == 2);
  CHECK(threads_for_load(0.3, 2, 2) == 1);
  // one busy process: 0.67 of a core while we run 2 threads, 1.0 while we run 1 — 1 either way
  CHECK(threads_for_load(2.0 / 3.0, 2, 2) == 1);
  CHECK(threads_for_load(1.0, 2, 2) == 1);
  // two busy processes, and more load than cores: never below one
  CHECK(threads_for_load(1.33, 2, 2) == 1);
  CHECK(threads_for_load(7.0, 2, 2) == 1);
  // never above the caller's maximum; 8 cores with one busy process: 7
  CHECK(threads_for_load(0.0, 8, 4) == 4);
  CHECK(threads_for_load(1.0, 8, 8) == 7);
  CHECK(threads_for_load(-1.0, 2, 2) == 2);  // clamped
  // the governor's slack for going down (0.6): a stray 0.3 of a core keeps two threads,
  // one busy process (0.67 while we run two) does not
  CHECK(threads_for_load(0.3, 2, 2, 0.6) == 2);
  CHECK(threads_for_load(2.0 / 3.0, 2, 2, 0.6) == 1);
}

TEST_CASE("sample_cpu reads the cores of the affinity mask from /proc/stat text", "[cpu_share][reliability]") {
  cpu_set_t mask;
  CPU_ZERO(&mask);
  REQUIRE(sched_getaffinity(0, sizeof mask, &mask) == 0);
  int first = -1;
  for (int c = 0; c < CPU_SETSIZE && first < 0; ++c)
    if (CPU_ISSET(c, &mask)) first = c;
  REQUIRE(first >= 0);
  const long hz = sysconf(_SC_CLK_TCK);
  // the aggregate line and a cpu outside any mask (99999 > CPU_SETSIZE) are not counted;
  // busy = user + nice + system + irq + softirq + steal, idle and iowait are not
  const std::string text = "cpu  9999 9999 9999 9999 0 0 0 0 0 0\n"
                           "cpu" + std::to_string(first) + " 100 20 30 5000 700 4 6 40 0 0\n"
                           "cpu99999 5000 0 0 0 0 0 0 0 0 0\nintr 1 2 3\n";
  const CpuSample s = sample_cpu(&text);
  REQUIRE(s.ok);
  CHECK(s.cores == 1);
  CHECK(s.busy_s == Approx(200.0 / static_cast<double>(hz)));
  CHECK(s.own_s > 0.0);

  const std::string none = "intr 1 2 3\n";
  CHECK_FALSE(sample_cpu(&none).ok);
}

TEST_CASE("limit_default_threads caps only the simulation's own choice", "[cpu_share][reliability]") {
  SceneDesc s = magsim::test::pile_under_magnet(7);  // 344 moments: all threads by default
  s.options.threads = 3;  // the user's count is kept
  Simulation fixed(s);
  fixed.limit_default_threads(1);
  CHECK(fixed.threads() == 3);

  s.options.threads = 0;
  Simulation own(s);
  const int chosen = own.threads();
  REQUIRE(chosen == omp_get_max_threads());
  own.limit_default_threads(1);
  CHECK(own.threads() == 1);
  own.limit_default_threads(chosen + 5);  // back up to its choice, never above
  CHECK(own.threads() == chosen);
  own.limit_default_threads(0);
  CHECK(own.threads() == 1);
}
