// E_r against the paper's formula on a hand-built 3x3 grid (motion_regularisation.h).
#include "u4d/joint/motion_regularisation.h"

#include <vector>

#include <gtest/gtest.h>

#include "u4d/mrf/expansion.h"

namespace u4d {
namespace {

// Pixels p = 3 y + x, w_p = 0.1 (p + 1), every motion 0 but the centre's (4).
// Only the centre's 8 pairs have Δm ≠ 0; their weights w_pq = (w_4 + w_q) / 2 sum to
// Σ_{q ≠ 4} (0.5 + 0.1 (q + 1)) / 2 = (8 · 0.5 + 0.1 · 40) / 2 = 4.
struct Grid {
  std::vector<std::pair<int, int>> pairs;
  std::vector<float> pixel_weight;
  std::vector<Eigen::Vector2f> motion;
  std::vector<int> labels;
  Grid() {
    mrf::GridGraph grid;
    grid.width = grid.height = 3;
    pairs = mrf::NeighbourPairs(grid);
    for (int p = 0; p < 9; ++p) pixel_weight.push_back(0.1f * (p + 1));
    motion.assign(9, Eigen::Vector2f::Zero());
    labels.assign(9, 0);
  }
  double Energy(const MotionRegTerm& term, float colour_contrast = 1.f) const {
    double e = 0;
    for (const auto& [p, q] : pairs)
      e += term.Cost(term.PairWeight(pixel_weight[p], pixel_weight[q], colour_contrast), labels[p],
                     labels[q], motion[p], motion[q]);
    return e;
  }
};

TEST(MotionRegularisationTest, QuadraticAndLinearSumsMatchTheFormula) {
  Grid g;
  g.motion[4] = Eigen::Vector2f(2, 0);
  MotionRegTerm term;
  term.truncation_px = 4;
  term.edge_aware = false;
  term.quadratic = true;  // ρ = min(|Δm|², τ²) / τ² = 4 / 16
  EXPECT_NEAR(g.Energy(term), 4 * 0.25, 1e-6);
  term.quadratic = false;  // ρ = min(|Δm|, τ) / τ = 2 / 4
  EXPECT_NEAR(g.Energy(term), 4 * 0.5, 1e-6);

  g.motion[4] = Eigen::Vector2f(3, 4);  // |Δm| = 5 > τ: truncated, ρ = 1 either way
  EXPECT_NEAR(g.Energy(term), 4.0, 1e-6);
  term.quadratic = true;
  EXPECT_NEAR(g.Energy(term), 4.0, 1e-6);
}

TEST(MotionRegularisationTest, EdgeAwareWeightScalesByColourContrast) {
  Grid g;
  g.motion[4] = Eigen::Vector2f(0, 2);
  MotionRegTerm term;
  term.edge_aware = true;  // w_pq · c_pq with c_pq = 0.5
  EXPECT_NEAR(g.Energy(term, 0.5f), 0.5 * 4 * 0.25, 1e-6);
  EXPECT_NEAR(term.PairWeight(0.2f, 0.4f, 0.5f), 0.15, 1e-7);
  term.edge_aware = false;  // c_pq not read
  EXPECT_NEAR(term.PairWeight(0.2f, 0.4f, 0.5f), 0.3, 1e-7);
}

TEST(MotionRegularisationTest, LabelBoundaries) {
  Grid g;
  g.motion[4] = Eigen::Vector2f(2, 0);
  g.labels[4] = 1;  // the moving centre is another object: its 8 pairs cross a boundary
  MotionRegTerm term;
  term.edge_aware = false;
  term.boundary = MotionRegBoundary::kIgnoreLabels;  // w ρ whatever the labels
  EXPECT_NEAR(g.Energy(term), 1.0, 1e-6);
  term.boundary = MotionRegBoundary::kFree;  // [l_p = l_q] w ρ
  EXPECT_NEAR(g.Energy(term), 0.0, 1e-12);
  term.boundary = MotionRegBoundary::kDiscontinuity;  // a boundary pays w
  EXPECT_NEAR(g.Energy(term), 4.0, 1e-6);
  EXPECT_EQ(term.MotionDependentWeight(0.7, 0, 1), 0.0);
  EXPECT_EQ(term.MotionDependentWeight(0.7, 1, 1), 0.7);
  term.boundary = MotionRegBoundary::kIgnoreLabels;
  EXPECT_EQ(term.MotionDependentWeight(0.7, 0, 1), 0.7);
}

TEST(MotionRegularisationTest, RhoDecreaseBoundBoundsEveryDecrease) {
  MotionRegTerm term;
  const Eigen::Vector2f from(0, 0), to(1.5f, -2.f);
  const double bound = term.RhoDecreaseBound(from, to);
  for (float x = -6; x <= 6; x += 0.5f)
    for (float y = -6; y <= 6; y += 0.5f) {
      const Eigen::Vector2f other(x, y);
      EXPECT_LE(term.Rho(from, other) - term.Rho(to, other), bound + 1e-9);
    }
}

// e_r^X(p) = mean − min of E_X over p's 3x3 window at the labels. Label 0 costs p
// at pixel p, label 1 costs 100; pixel 8 is labelled 1:
//   (0,0): {0, 1, 3, 4}            mean 2,       min 0 -> 2
//   (1,1): {0 .. 7, 100}           mean 128 / 9, min 0 -> 128 / 9
//   (2,2): {4, 5, 7, 100}          mean 29,      min 4 -> 25
// w_p = λ_r (1 + λ_r^L e_r^L + λ_r^A e_r^A) with E_a = 0: 0.5 (1 + 0.4 · 2) at (0,0).
TEST(MotionRegularisationTest, WindowSpreadAndPixelWeights) {
  LabelCostVolume volume;
  volume.width = volume.height = 3;
  volume.num_labels = 2;
  volume.cost.resize(18);
  for (int p = 0; p < 9; ++p) volume.cost[p] = static_cast<float>(p), volume.cost[9 + p] = 100;
  cv::Mat labels = cv::Mat::zeros(3, 3, CV_16U);
  labels.at<uint16_t>(2, 2) = 1;
  const std::vector<float> spread = WindowSpread(volume, labels);
  EXPECT_NEAR(spread[0], 2.0, 1e-5);
  EXPECT_NEAR(spread[4], 128.0 / 9, 1e-5);
  EXPECT_NEAR(spread[8], 25.0, 1e-5);

  LabelCostVolume zero = volume;
  std::fill(zero.cost.begin(), zero.cost.end(), 0.f);
  JointWeights weights;
  weights.motion_reg = 0.5;
  weights.motion_reg_label = 0.4;
  weights.motion_reg_app = 0.4;
  const std::vector<float> w = MotionRegPixelWeights(volume, zero, labels, weights);
  EXPECT_NEAR(w[0], 0.5 * (1 + 0.4 * 2), 1e-6);
  EXPECT_NEAR(w[8], 0.5 * (1 + 0.4 * 25), 1e-5);
  const std::vector<float> swapped = MotionRegPixelWeights(zero, volume, labels, weights);
  EXPECT_NEAR(swapped[4], 0.5 * (1 + 0.4 * 128.0 / 9), 1e-5);
}

}  // namespace
}  // namespace u4d
