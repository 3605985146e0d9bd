// tools/cli/cpu_share.hpp — how many threads the magnetics should use on a machine that other
// processes share ("busy machines").
//
// OpenMP's parallel regions end in barriers: when another process holds one of the cores,
// a descheduled team member stalls every barrier by a scheduler slice, and two threads run
// 5–10x slower than one (sakura_tree, 2 cores, two busy processes: T_i 29 ms with 2 threads,
// 2.7 ms with 1). ThreadGovernor watches what the *other* processes take of the cores this
// process may run on and answers with a thread count that fits into the rest:
//
//   others = (busy time of our cores in /proc/stat − this process's CPU time) / window
//   more threads:  up to clamp(floor(cores − others + 0.25), 1, max_threads)
//   fewer threads: down to clamp(floor(cores − others + 0.6), 1, max_threads)
//
// so on 2 cores two threads need the others below 0.25 of a core to start and above 0.4 to
// stop (one busy process measures 0.67 while we run two threads: it always stops them; the
// gap keeps the tick-sampled estimate's ±0.2 from flapping on a quiet machine). The estimate is taken over
// windows of at least `period` of wall time (0.25 s by default; the first window starts when
// the governor is made, so a scene's set-up time counts, and may be as short as 0.1 s); fewer threads are taken at once,
// more only after two windows in a row allow them. Where /proc/stat cannot be read
// (not Linux) the governor answers max_threads.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace magsim::engine {

/// One reading of the CPU time spent on this process's cores and by this process.
struct CpuSample {
  bool ok = false;
  double busy_s = 0.0;  ///< non-idle time of the cores in our affinity mask, all processes (s)
  double own_s = 0.0;   ///< this process's CPU time, all threads (s)
  int cores = 0;        ///< cores in our affinity mask that /proc/stat lists
  std::chrono::steady_clock::time_point when;
};

/// Reads /proc/stat (or `stat_text` when given: the file's contents, for tests) and the
/// process's CPU clock.
CpuSample sample_cpu(const std::string* stat_text = nullptr);

/// The thread count for `cores` cores of which other processes use `others` (in cores):
/// floor(cores − others + slack), at least 1, at most max_threads.
int threads_for_load(double others, int cores, int max_threads, double slack = 0.25);

class ThreadGovernor {
 public:
  explicit ThreadGovernor(int max_threads, double period_s = 0.25);
  /// The thread count to use for the next step (re-measured at most once per period).
  int threads();
  /// Other processes' use of our cores in the last complete window (cores; −1 before one).
  double others() const { return others_; }
  bool measuring() const { return last_.ok; }

 private:
  int max_threads_;
  double period_s_;
  int current_;
  int raise_votes_ = 0;
  double others_ = -1.0;
  CpuSample last_;
};

}  // namespace magsim::engine
