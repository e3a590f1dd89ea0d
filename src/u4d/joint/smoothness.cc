#include "u4d/joint/smoothness.h"

#include <algorithm>
#include <cstdlib>

namespace u4d {

double SmoothnessTerm::Distance(int a, int b) const {
  if (a == unknown || b == unknown) return a == b ? 0.0 : 1.0;
  return std::min<double>(std::abs(a - b), truncation) / truncation;
}

double SmoothnessTerm::Spatial(int label_p, int label_q, int depth_p, int depth_q) const {
  return label_p == label_q ? spatial_weight * Distance(depth_p, depth_q) : 0.0;
}

double SmoothnessTerm::Temporal(int depth, int previous_depth) const {
  return previous_depth >= 0 ? temporal_weight * Distance(depth, previous_depth) : 0.0;
}

}  // namespace u4d
