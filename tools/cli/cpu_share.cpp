// tools/cli/cpu_share.cpp — see cpu_share.hpp.
#include "tools/cli/cpu_share.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include <sched.h>
#include <time.h>
#include <unistd.h>

namespace magsim::engine {

namespace {

double process_cpu_seconds() {
  timespec ts{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

CpuSample sample_cpu(const std::string* stat_text) {
  CpuSample s;
  s.when = std::chrono::steady_clock::now();
  s.own_s = process_cpu_seconds();
  std::string text;
  if (stat_text) {
    text = *stat_text;
  } else {
    std::ifstream f("/proc/stat");
    if (!f) return s;
    std::ostringstream o;
    o << f.rdbuf();
    text = o.str();
  }
  cpu_set_t mask;
  CPU_ZERO(&mask);
  const bool have_mask = sched_getaffinity(0, sizeof mask, &mask) == 0;
  const long hz = sysconf(_SC_CLK_TCK);
  if (hz <= 0) return s;
  std::istringstream in(text);
  std::string line;
  double busy_ticks = 0.0;
  while (std::getline(in, line)) {
    // "cpuN user nice system idle iowait irq softirq steal guest guest_nice" (guest time is
    // already inside user); the aggregate "cpu " line is skipped
    if (line.size() < 4 || line.compare(0, 3, "cpu") != 0 || !std::isdigit(static_cast<unsigned char>(line[3])))
      continue;
    std::istringstream l(line.substr(3));
    int cpu = -1;
    double user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0, steal = 0;
    if (!(l >> cpu >> user >> nice >> system >> idle)) continue;
    l >> iowait >> irq >> softirq >> steal;  // older kernels list fewer columns
    if (cpu < 0 || (have_mask && (cpu >= CPU_SETSIZE || !CPU_ISSET(cpu, &mask)))) continue;
    busy_ticks += user + nice + system + irq + softirq + steal;
    ++s.cores;
  }
  if (s.cores == 0) return s;
  s.busy_s = busy_ticks / static_cast<double>(hz);
  s.ok = true;
  return s;
}

int threads_for_load(double others, int cores, int max_threads, double slack) {
  const double room = static_cast<double>(cores) - std::clamp(others, 0.0, static_cast<double>(cores));
  const int n = static_cast<int>(std::floor(room + slack));
  return std::clamp(n, 1, std::max(1, max_threads));
}

ThreadGovernor::ThreadGovernor(int max_threads, double period_s)
    : max_threads_(std::max(1, max_threads)), period_s_(period_s), current_(max_threads_),
      last_(sample_cpu()) {}

int ThreadGovernor::threads() {
  if (!last_.ok || max_threads_ == 1) return current_;
  const auto now = std::chrono::steady_clock::now();
  const double window = std::chrono::duration<double>(now - last_.when).count();
  // the first window (from the governor's creation, e.g. a scene's set-up) may be shorter:
  // two threads on a busy machine cost most in the first steps
  if (window < (others_ < 0 ? std::min(period_s_, 0.1) : period_s_)) return current_;
  const CpuSample s = sample_cpu();
  if (!s.ok || s.cores != last_.cores) {  // cores came or went: start a new window
    last_ = s;
    return current_;
  }
  others_ = std::max(0.0, ((s.busy_s - last_.busy_s) - (s.own_s - last_.own_s)) / window);
  last_ = s;
  const int down = threads_for_load(others_, s.cores, max_threads_, 0.6);
  const int want = threads_for_load(others_, s.cores, max_threads_, 0.25);
  if (down < current_) {
    current_ = down;
    raise_votes_ = 0;
  } else if (want > current_) {
    if (++raise_votes_ >= 2) {
      current_ = want;
      raise_votes_ = 0;
    }
  } else {
    raise_votes_ = 0;
  }
  return current_;
}

}  // namespace magsim::engine
