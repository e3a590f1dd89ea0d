// JointEnergy::EnergyOf sums every term of Eq. 1 once (joint_energy.h), on a
// hand-built 3x3 view whose terms are all known by hand.
#include "u4d/joint/joint_energy.h"

#include <vector>

#include <gtest/gtest.h>

#include "u4d/joint/roi_slots.h"
#include "u4d/joint/term_test_grid.h"
#include "u4d/mrf/expansion.h"

namespace u4d {
namespace {

// Pixels p = 3 y + x:   labels   depths (U = 10, τ_d = 4)   motion
//                       1 1 0    2  3 7                     0 everywhere but
//                       1 1 0    4  U 1                     (2, 0) at the centre
//                       0 0 0    5  5 6
using term_test::kDepths;
using term_test::kLabels;
using term_test::kUnknown;

JointEnergy Energy() {
  JointEnergy energy;
  energy.weights = {};  // λ_d = 1, λ_f = 0.4, λ_s = 0.5, λ_s^s = 0.4, ...
  energy.terms = {};    // all on
  energy.width = energy.height = 3;
  energy.num_pixels = 9;
  energy.num_labels = 2;
  energy.grid.width = energy.grid.height = 3;
  energy.pairs = mrf::NeighbourPairs(energy.grid);
  // Label unaries (E_a + E_sem + E_p's label part together): 0.1 l + 0.01 p.
  for (int p = 0; p < 9; ++p)
    for (int l = 0; l < 2; ++l) energy.label_unary.push_back(0.1f * l + 0.01f * p);
  // E_d: every depth costs 0.05, U costs 0.6.
  energy.depth.width = energy.depth.height = 3;
  energy.depth.depths.assign(kUnknown, 1.f);
  energy.depth.slots = MakeRoiSlots(cv::Mat(), 3, 3);
  energy.depth.cost.assign(kUnknown * 9, 0.05f);
  energy.depth.unknown_cost = 0.6f;
  energy.unknown = kUnknown;
  energy.smoothness.spatial_weight = 0.5 * 0.4;
  energy.smoothness.truncation = 4;
  energy.smoothness.unknown = kUnknown;
  energy.contrast.Assign(9, 0.3f);  // λ_c E_c of every pair with two labels
  energy.motion_reg.truncation_px = 4;
  energy.motion_reg.quadratic = true;
  energy.motion_reg.edge_aware = false;
  energy.reg_pixel_weight.assign(9, 1.f);  // w_pq = 1
  energy.flow_scale = 0.25f;
  return energy;
}

JointLabelling Labelling() {
  JointLabelling labelling;
  labelling.labels = kLabels;
  labelling.depths = kDepths;
  labelling.motions.assign(9, 0);
  labelling.motion_vectors.assign(9, Eigen::Vector2f::Zero());
  labelling.motion_vectors[4] = Eigen::Vector2f(2, 0);
  labelling.flow_costs.assign(9, 0.5f);  // raw E_f
  return labelling;
}

// By hand:
//   label unaries  Σ 0.1 l_p + 0.01 p = 0.4 + 0.36                          = 0.76
//   λ_d E_d        8 depths · 0.05 + U · 0.6                                = 1.0
//   λ_f E_f        9 · 0.4 · 0.5 · 0.25                                     = 0.45
//   λ_s E_s        0.2 · 7.25 (smoothness_test.cc, the same grid)           = 1.45
//   λ_c E_c        9 of the 20 pairs join labels 0 and 1: 9 · 0.3           = 2.7
//   λ_r E_r        the centre's 8 pairs: 8 · 1 · min(2², 4²) / 4²            = 2.0
//   E_p            no pose                                                  = 0
TEST(JointEnergyTest, EnergyOfSumsEveryTermOnce) {
  const JointEnergy energy = Energy();
  const JointLabelling labelling = Labelling();
  EXPECT_NEAR(energy.EnergyOf(labelling), 0.76 + 1.0 + 0.45 + 1.45 + 2.7 + 2.0, 1e-5);
}

// Pixel 8 outside the region of interest: its unaries go (0.1 · 0 + 0.08, 0.05,
// 0.05), its pairs keep E_c only: (5,8) and (7,8) lose E_s (ρ 1 and 0.25), (4,8)
// (labels 1, 0) keeps its E_c and loses its E_r (0.25).
TEST(JointEnergyTest, PixelsOutsideTheRegionKeepOnlyContrast) {
  JointEnergy energy = Energy();
  energy.grid.active = {1, 1, 1, 1, 1, 1, 1, 1, 0};
  const JointLabelling labelling = Labelling();
  const double expected =
      (0.76 - 0.08) + (1.0 - 0.05) + (0.45 - 0.05) + 0.2 * (7.25 - 1.25) + 2.7 + (2.0 - 0.25);
  EXPECT_NEAR(energy.EnergyOf(labelling), expected, 1e-5);
}

// Terms switched off drop out; a forbidden motion (e_F^S = ∞) makes the energy infinite.
TEST(JointEnergyTest, SwitchesAndForbiddenMotion) {
  JointEnergy energy = Energy();
  energy.terms.contrast = energy.terms.motion_reg = false;
  JointLabelling labelling = Labelling();
  EXPECT_NEAR(energy.EnergyOf(labelling), 0.76 + 1.0 + 0.45 + 1.45, 1e-5);
  energy.terms.flow = false;
  EXPECT_NEAR(energy.EnergyOf(labelling), 0.76 + 1.0 + 1.45, 1e-5);
  labelling.flow_costs[3] = kForbiddenMotion;
  EXPECT_GE(energy.EnergyOf(labelling), mrf::kInfiniteCost);
}

}  // namespace
}  // namespace u4d
