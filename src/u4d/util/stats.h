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

// The median of `v`, the mean of the middle two for an even count; 0 for
// an empty vector.
inline double MedianOfMiddle(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + h, v.end());
  if (v.size() % 2) return v[h];
  return 0.5 * (*std::max_element(v.begin(), v.begin() + h) + v[h]);
}

}  // namespace u4d
