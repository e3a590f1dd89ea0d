// E_c against the paper's formula on a hand-built 3x3 grid (contrast.h).
#include "u4d/joint/contrast.h"

#include <vector>

#include <gtest/gtest.h>

#include "u4d/mrf/expansion.h"

namespace u4d {
namespace {

// λ_c (λ_ca c_pq + λ_cl s_pq) / (λ_ca + λ_cl) on every pair with l_p ≠ l_q,
// with c_pq = 0.1 (p + 1) and s_pq = 0.1 q. Labels: the left column 1, the rest 0:
//   1 0 0        pixels  0 1 2
//   1 0 0                3 4 5
//   1 0 0                6 7 8
// The 7 pairs across the boundary, by hand:
//   pair   (0,1) (3,4) (6,7) (0,4) (3,7) (1,3) (4,6)
//   c_pq    0.1   0.4   0.7   0.1   0.4   0.2   0.5   Σ = 2.4
//   s_pq    0.1   0.4   0.7   0.4   0.7   0.3   0.6   Σ = 3.2
// λ_c = 0.5, λ_ca = 3, λ_cl = 1: E = 0.5 (3 · 2.4 + 1 · 3.2) / 4 = 1.3.
TEST(ContrastTest, SumOverA3x3GridMatchesTheFormula) {
  mrf::GridGraph grid;
  grid.width = grid.height = 3;
  const std::vector<std::pair<int, int>> pairs = mrf::NeighbourPairs(grid);
  std::vector<float> colour, semantic;
  for (const auto& [p, q] : pairs) {
    colour.push_back(0.1f * (p + 1));
    semantic.push_back(0.1f * q);
  }
  JointWeights weights;
  weights.contrast = 0.5;
  weights.contrast_colour = 3;
  weights.contrast_label = 1;
  const ForwardPairValues costs = ContrastPairCosts(colour, semantic, pairs, 3, 9, weights);
  const std::vector<int> labels = {1, 0, 0, 1, 0, 0, 1, 0, 0};
  double sum = 0;
  int cut = 0;
  for (const auto& [p, q] : pairs) {
    const double e = ContrastCost(labels[p], labels[q], costs.At(p, q, 3));
    sum += e;
    cut += e > 0;
  }
  EXPECT_EQ(cut, 7);
  EXPECT_NEAR(sum, 1.3, 1e-6);
  // One pair alone: (4,8), c = 0.5, s = 0.8: 0.5 (1.5 + 0.8) / 4 = 0.2875.
  EXPECT_NEAR(ContrastCost(1, 2, costs.At(4, 8, 3)), 0.2875, 1e-6);
  EXPECT_EQ(ContrastCost(2, 2, costs.At(4, 8, 3)), 0.0);

  weights.contrast_colour = weights.contrast_label = 0;  // no contrast weights: no E_c
  const ForwardPairValues none = ContrastPairCosts(colour, semantic, pairs, 3, 9, weights);
  for (const auto& [p, q] : pairs) EXPECT_EQ(none.At(p, q, 3), 0.f);
}

}  // namespace
}  // namespace u4d
