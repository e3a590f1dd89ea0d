// E_s against the paper's formula on a hand-built 3x3 grid (smoothness.h).
#include "u4d/joint/smoothness.h"

#include <vector>

#include <gtest/gtest.h>

#include "u4d/mrf/expansion.h"

namespace u4d {
namespace {

// Pixels p = 3 y + x:   labels   depths (U = 10, τ_d = 4)
//                       1 1 0    2  3 7
//                       1 1 0    4  U 1
//                       0 0 0    5  5 6
const std::vector<int> kLabels = {1, 1, 0, 1, 1, 0, 0, 0, 0};
const std::vector<int> kDepths = {2, 3, 7, 4, 10, 1, 5, 5, 6};
constexpr int kUnknown = 10;

SmoothnessTerm Term() {
  SmoothnessTerm term;
  term.spatial_weight = 0.5 * 0.4;   // λ_s λ_s^s
  term.temporal_weight = 0.5 * 0.3;  // λ_s λ_s^t
  term.truncation = 4;
  term.unknown = kUnknown;
  return term;
}

mrf::GridGraph Grid3x3() {
  mrf::GridGraph grid;
  grid.width = grid.height = 3;
  grid.connectivity = 8;
  return grid;
}

TEST(SmoothnessTest, DistanceIsTruncatedLabelStepsAndUnknownCostsOne) {
  const SmoothnessTerm term = Term();
  EXPECT_DOUBLE_EQ(term.Distance(2, 3), 0.25);
  EXPECT_DOUBLE_EQ(term.Distance(3, 2), 0.25);
  EXPECT_DOUBLE_EQ(term.Distance(1, 4), 0.75);
  EXPECT_DOUBLE_EQ(term.Distance(1, 9), 1.0);  // |Δ| = 8 truncated at τ_d = 4
  EXPECT_DOUBLE_EQ(term.Distance(5, 5), 0.0);
  EXPECT_DOUBLE_EQ(term.Distance(kUnknown, 5), 1.0);
  EXPECT_DOUBLE_EQ(term.Distance(0, kUnknown), 1.0);
  EXPECT_DOUBLE_EQ(term.Distance(kUnknown, kUnknown), 0.0);
}

// Σ over the 20 8-neighbour pairs of [l_p = l_q] λ_s λ_s^s min(|d_p − d_q|, τ_d) / τ_d.
// The pairs with one label, by hand:
//   (0,1) |2−3| = 1 -> 0.25     (3,4) 4 vs U -> 1     (6,7) |5−5| -> 0
//   (7,8) |5−6| -> 0.25         (0,3) |2−4| -> 0.5    (1,4) 3 vs U -> 1
//   (2,5) |7−1| = 6 -> 1        (5,8) |1−6| = 5 -> 1  (0,4) 2 vs U -> 1
//   (1,3) |3−4| -> 0.25         (5,7) |1−5| = 4 -> 1
// the other 9 pairs join labels 0 and 1 and cost nothing: Σ ρ = 7.25, E = 0.2 · 7.25.
TEST(SmoothnessTest, SpatialSumOverA3x3GridMatchesTheFormula) {
  const SmoothnessTerm term = Term();
  double sum = 0;
  int pairs = 0;
  for (const auto& [p, q] : mrf::NeighbourPairs(Grid3x3())) {
    sum += term.Spatial(kLabels[p], kLabels[q], kDepths[p], kDepths[q]);
    ++pairs;
  }
  EXPECT_EQ(pairs, 20);
  EXPECT_NEAR(sum, 0.2 * 7.25, 1e-12);
  EXPECT_DOUBLE_EQ(term.Spatial(0, 1, 2, 9), 0.0);  // a label boundary: E_c's, not E_s's
}

// λ_s λ_s^t min(|d_p − d^{t−1}_p|, τ_d) / τ_d per pixel with a previous depth.
// previous:  2 − 5  /  4 6 −  /  9 5 6  (− = none)
//   ρ:       0 · 0.5 /  0 1 ·  /  1 0 0  (|7−5| = 2 -> 0.5, U vs 6 -> 1, |5−9| = 4 -> 1)
// Σ ρ = 2.5, E = 0.15 · 2.5.
TEST(SmoothnessTest, TemporalPartMatchesTheFormula) {
  const SmoothnessTerm term = Term();
  const std::vector<int> previous = {2, -1, 5, 4, 6, -1, 9, 5, 6};
  double sum = 0;
  for (int p = 0; p < 9; ++p) sum += term.Temporal(kDepths[p], previous[p]);
  EXPECT_NEAR(sum, 0.15 * 2.5, 1e-12);
  EXPECT_DOUBLE_EQ(term.Temporal(3, -1), 0.0);
  EXPECT_DOUBLE_EQ(term.Temporal(1, 8), 0.15);  // truncated
}

}  // namespace
}  // namespace u4d
