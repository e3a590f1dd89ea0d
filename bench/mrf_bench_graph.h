// The 480x270 stereo-like problems shared by mrf_bench and
// mrf_libmaxflow_bench, so both solve exactly the same graphs.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>

#include "u4d/mrf/max_flow.h"

namespace u4d::mrf::bench {

constexpr int kWidth = 480, kHeight = 270, kLabels = 32;

// A smooth "true disparity" with a step, in [0, kLabels).
inline double TrueDisparity(int x, int y) {
  const double d = 10 + 6 * std::sin(x / 60.0) + 3 * std::cos(y / 45.0) + (x > 240 ? 10 : 0);
  return std::clamp(d, 0.0, kLabels - 1.0);
}

// Binary stereo-like graph: the terminal weights are the cost difference of
// two disparity hypotheses (truncated linear matching cost + noise); edges
// are a Potts-like smoothness with a random contrast weight.
inline FlowGraph StereoGraph(int connectivity) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  FlowGraph g(kWidth * kHeight);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const double d = TrueDisparity(x, y);
      const double c0 = std::min(std::abs(d - 12), 5.0) + 2 * u(rng);
      const double c1 = std::min(std::abs(d - 20), 5.0) + 2 * u(rng);
      g.AddTerminalWeights(y * kWidth + x, std::max(c1 - c0, 0.0), std::max(c0 - c1, 0.0));
    }
  }
  const int dx[] = {1, -1, 0, 1}, dy[] = {0, 1, 1, 1};
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      for (int k = 0; k < 4; ++k) {
        if (connectivity == 4 && (k == 1 || k == 3)) continue;
        const int qx = x + dx[k], qy = y + dy[k];
        if (qx < 0 || qx >= kWidth || qy >= kHeight) continue;
        const double w = (k == 1 || k == 3 ? 0.7 : 1.0) * (0.5 + 1.5 * u(rng));
        g.AddEdge(y * kWidth + x, qy * kWidth + qx, w, w);
      }
    }
  }
  return g;
}

}  // namespace u4d::mrf::bench
