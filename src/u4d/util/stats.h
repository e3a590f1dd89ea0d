// Small statistics shared by evaluations, tests and benchmarks.
#pragma once

#include <algorithm>
#include <vector>

namespace u4d {

// The median of `v` (the upper one for an even count); 0 for an empty vector.
inline double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace u4d
