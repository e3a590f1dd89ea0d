// E_s against the paper's formula on a hand-built 3x3 grid (smoothness.h).
#include "u4d/joint/smoothness.h"

#include <vector>

#include <gtest/gtest.h>

#include "u4d/joint/joint_energy.h"
#include "u4d/joint/term_test_grid.h"
#include "u4d/mrf/expansion.h"

namespace u4d {
namespace {

// Pixels p = 3 y + x:   labels   depths (U = 10, τ_d = 4)
//                       1 1 0    2  3 7
//                       1 1 0    4  U 1
//                       0 0 0    5  5 6
using term_test::kDepths;
using term_test::kLabels;
using term_test::kUnknown;

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

// The same grid through JointEnergy::EnergyOf with only E_s on: the spatial sum
// above; a pair with a pixel outside the region of interest has no E_s; the
// temporal part is a unary of every pixel in the region.
TEST(SmoothnessTest, JointEnergySumsSpatialAndTemporalSmoothness) {
  JointEnergy energy;
  energy.terms = {};
  energy.terms.depth = energy.terms.appearance = energy.terms.semantic = false;
  energy.terms.flow = energy.terms.contrast = energy.terms.motion_reg = false;
  energy.terms.pose = false;
  energy.width = energy.height = 3;
  energy.num_pixels = 9;
  energy.num_labels = 2;
  energy.grid = Grid3x3();
  energy.pairs = mrf::NeighbourPairs(energy.grid);
  energy.label_unary.assign(9 * 2, 0.f);
  energy.unknown = kUnknown;
  energy.smoothness = Term();
  JointLabelling labelling;
  labelling.labels = kLabels;
  labelling.depths = kDepths;
  labelling.motions.assign(9, 0);
  labelling.motion_vectors.assign(9, Eigen::Vector2f::Zero());
  labelling.flow_costs.assign(9, 0.f);
  EXPECT_NEAR(energy.EnergyOf(labelling), 0.2 * 7.25, 1e-12);

  // Pixel 8 outside the region: pairs (5,8) (ρ 1) and (7,8) (ρ 0.25) drop out.
  energy.grid.active = {1, 1, 1, 1, 1, 1, 1, 1, 0};
  EXPECT_NEAR(energy.EnergyOf(labelling), 0.2 * 6.0, 1e-12);

  // The temporal part (pixel 8, outside, does not count: its ρ is 0 anyway).
  energy.previous_depth_label = {2, -1, 5, 4, 6, -1, 9, 5, 6};
  EXPECT_NEAR(energy.EnergyOf(labelling), 0.2 * 6.0 + 0.15 * 2.5, 1e-12);
}

}  // namespace
}  // namespace u4d
