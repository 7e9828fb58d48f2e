// The statistic the sogmm-perf benchmarks report over repeated runs: the
// median, which one run slowed by another process on the machine cannot move.
#pragma once

#include <algorithm>
#include <vector>

namespace sogmm::perf {

/// The upper median of `v` (element n / 2 once sorted); `v` must not be empty.
inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace sogmm::perf
