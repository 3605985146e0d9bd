// tools/bench/bench_common.hpp — what the bench binaries share: comma lists and medians.
#pragma once

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

namespace magsim::bench {

/// "a,b,,c" → {"a", "b", "c"}: the items of a comma list, empty ones dropped.
inline std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string x;
  while (std::getline(ss, x, ','))
    if (!x.empty()) out.push_back(x);
  return out;
}

/// The median (the mean of the two middle values for an even count); 0 for none.
inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace magsim::bench
