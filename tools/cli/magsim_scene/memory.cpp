// tools/cli/magsim_scene/memory.cpp — what the run shares with the command line: number
// formatting, the registry's names and the memory estimate that refuses a run which will not
// fit (magsim_scene.hpp).
#include "scenes/registry.hpp"
#include "tools/cli/magsim_scene/magsim_scene.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include <sys/resource.h>

namespace magsim::scene_tool {

namespace scenes = magsim::scenes;

std::string fmt(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", x);
  return b;
}


bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}


std::string registry_names() {
  std::string names;
  for (const scenes::SceneEntry& e : scenes::registry()) names += (names.empty() ? "" : ", ") + std::string(e.name);
  return names;
}


MemoryNeed memory_need(const engine::SceneDesc& s) {
  MemoryNeed n;
  n.bodies = static_cast<double>(s.bodies.size());
  for (const engine::BodyDesc& b : s.bodies) {
    n.moments += static_cast<double>(b.moments.size());
    n.shapes += static_cast<double>(b.shapes.size());
  }
  return n;
}

double memory_available(std::string* source) {
  double avail = -1;
  if (std::FILE* f = std::fopen("/proc/meminfo", "r")) {
    char line[256];
    while (std::fgets(line, sizeof line, f)) {
      unsigned long long kb = 0;
      if (std::sscanf(line, "MemAvailable: %llu kB", &kb) == 1) {
        avail = static_cast<double>(kb) * 1024.0;
        *source = "MemAvailable";
        break;
      }
    }
    std::fclose(f);
  }
  struct rlimit rl {};
  if (::getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    double mapped = 0;  // VmSize: what the address-space limit already counts
    if (std::FILE* f = std::fopen("/proc/self/status", "r")) {
      char line[256];
      unsigned long long kb = 0;
      while (std::fgets(line, sizeof line, f))
        if (std::sscanf(line, "VmSize: %llu kB", &kb) == 1) mapped = static_cast<double>(kb) * 1024.0;
      std::fclose(f);
    }
    const double left = std::max(0.0, static_cast<double>(rl.rlim_cur) - mapped);
    if (avail < 0 || left < avail) {
      avail = left;
      *source = "the address-space limit (ulimit -v)";
    }
  }
  return avail;
}

void check_memory(const std::string& what, const MemoryNeed& need) {
  std::string source;
  const double avail = memory_available(&source);
  const double gb = 1e9;
  char detail[256];
  std::snprintf(detail, sizeof detail, "%.0f bodies, %.0f moments, %.0f shapes", need.bodies, need.moments, need.shapes);
  if (need.steps > 0) std::snprintf(detail + std::strlen(detail), sizeof detail - std::strlen(detail), ", %.0f steps", need.steps);
  if (avail >= 0 && need.bytes() > avail) {
    char msg[512];
    std::snprintf(msg, sizeof msg, "%s: needs about %.2f GB of memory (%s; estimated, magsim_scene.hpp MemoryNeed), "
                  "more than the %.2f GB available (%s)", what.c_str(), need.bytes() / gb, detail, avail / gb, source.c_str());
    throw UsageError(msg);
  }
  if (need.bodies >= kProgressBodies)
    std::fprintf(stderr, "%s: %s; about %.2f GB of memory estimated%s\n", what.c_str(), detail, need.bytes() / gb,
                 avail >= 0 ? (", " + fmt(avail / gb) + " GB available").c_str() : "");
}

void check_registry_memory(const scenes::SceneEntry& e, const scenes::SceneParams& p, const std::string& what) {
  // registry scenes above this count are sized from builds of 1 and of this many first
  constexpr int kSampleCount = 100;
  if (p.count <= kSampleCount) return;
  // the scene's own description would take memory in proportion to the count (1e8 balls:
  // tens of GB before any check): its size is extrapolated from two small builds first
  scenes::SceneParams small = p;
  small.count = 1;
  const MemoryNeed one = memory_need(e.build(small));
  small.count = kSampleCount;
  const MemoryNeed many = memory_need(e.build(small));
  const double k = static_cast<double>(p.count - 1) / (kSampleCount - 1);
  MemoryNeed need;
  need.bodies = one.bodies + k * (many.bodies - one.bodies);
  need.moments = one.moments + k * (many.moments - one.moments);
  need.shapes = one.shapes + k * (many.shapes - one.shapes);
  check_memory(what, need);
}

}  // namespace magsim::scene_tool
