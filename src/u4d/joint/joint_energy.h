// The joint energy of one view (paper Eq. 1) as data: every term's weights and
// the volumes and maps it reads, and the energy of a labelling,
//
//   E(l,d,m) = λ_d E_d(d) + λ_a E_a(l) + λ_sem E_sem(l) + λ_f E_f(m)
//            + λ_s E_s(l,d) + λ_c E_c(l) + λ_r E_r(l,m) + λ_p E_p(l,d,m)
//
// Where each term lives (its formula in the file's header, its test beside it):
//   E_d              depth_cost.h       DepthCostVolume (U costs unknown_cost)
//   E_a, E_sem       label_costs.h      AppearanceCosts, SemanticCosts (in label_unary)
//   E_f              flow_cost.h        MotionCostVolume, FlowFieldCosts (× flow_scale)
//   E_s              smoothness.h       SmoothnessTerm (spatial pairs; temporal unary, off)
//   E_c              contrast.h         ContrastPairCosts, ContrastCost
//   E_r              motion_regularisation.h  MotionRegTerm, MotionRegPixelWeights
//   E_p              pose_prior.h       PoseLabelCost (e_2d^S + e_2d^L, in label_unary),
//                                       PoseMotion2dCost (e_2d^M), Pose3dCost (e_3d^S + e_3d^M)
// energy_setup.h fills a JointEnergy from a JointViewInput; block_schedule.h and
// flow_fusion.h minimise it.
//
// Only pixels of the region of interest (grid.active) carry unaries and E_s, E_r;
// a pair with a pixel outside has E_c only (E_s against the outside's placeholder
// depth U would cost the most at every region border, and made the border ring
// switch to a person label where contrast is low).
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "u4d/geometry/camera.h"
#include "u4d/joint/contrast.h"
#include "u4d/joint/depth_cost.h"
#include "u4d/joint/flow_cost.h"
#include "u4d/joint/motion_regularisation.h"
#include "u4d/joint/neighbour_pairs.h"
#include "u4d/joint/parameters.h"
#include "u4d/joint/pose_prior.h"
#include "u4d/joint/smoothness.h"
#include "u4d/mrf/expansion.h"

namespace u4d {

// A labelling (l, d, m) of one view, per pixel p = y * width + x.
struct JointLabelling {
  std::vector<int> labels;   // l: object id, 0 = background
  std::vector<int> depths;   // d: depth label, JointEnergy::unknown = U
  std::vector<int> motions;  // m: index into the motion labels M (the discrete blocks)
  // m as a vector (pixels) and its raw E_f (incl. e_F^S): the motion label's
  // vector and volume cost in the discrete blocks (SetMotionsFromLabels),
  // sub-pixel after the flow fusion.
  std::vector<Eigen::Vector2f> motion_vectors;
  std::vector<float> flow_costs;
};

struct JointEnergy {
  JointWeights weights;
  JointTerms terms;
  PosePriorOptions pose_options;

  int width = 0, height = 0, num_pixels = 0;
  int num_labels = 1;  // |L|
  const Camera* camera_t = nullptr;
  const Camera* camera_t1 = nullptr;       // camera_t on the last frame
  mrf::GridGraph grid;                     // active = the region of interest
  std::vector<std::pair<int, int>> pairs;  // mrf::NeighbourPairs(grid)
  std::vector<Eigen::Vector3d> rays;       // world direction per pixel with z = 1 in the camera
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();

  // Label unaries: λ_a E_a + λ_sem E_sem + λ_p λ_2d' (e_2d^S + e_2d^L), [p * num_labels + l].
  std::vector<float> label_unary;
  // E_d; the depth label U is `unknown` (= the number of depths).
  DepthCostVolume depth;
  int unknown = 0;
  // Per pixel, the depth labels it may take besides U: [depth_lo, depth_hi]; empty = all.
  std::vector<int16_t> depth_lo, depth_hi;
  // E_s; previous_depth_label: d^{t−1} per pixel (−1 = none; empty = the temporal part off).
  SmoothnessTerm smoothness;
  std::vector<int> previous_depth_label;
  ForwardPairValues contrast;  // λ_c E_c per pair with different labels (ContrastPairCosts)
  // E_r: w_p per pixel and c_pq per pair (read when motion_reg.edge_aware).
  MotionRegTerm motion_reg;
  std::vector<float> reg_pixel_weight;
  ForwardPairValues reg_edge;
  // E_f: the volume over M and the factor that normalises it to [0, 1].
  MotionCostVolume motion;
  float flow_scale = 1;
  // E_p: the capsules, and λ_p λ_2d / (λ_2d + λ_3d), λ_p λ_3d / (λ_2d + λ_3d).
  PosePriorMap pose;
  bool use_pose = false;
  double pose_2d_share = 0, pose_3d_share = 0;

  bool DepthAllowed(int p, int depth_label) const {
    return depth_label == unknown || depth_lo.empty() ||
           (depth_label >= depth_lo[p] && depth_label <= depth_hi[p]);
  }
  // Φ(p): the world point at depth label `depth_label` (not U).
  Eigen::Vector3d Point(int p, int depth_label) const {
    return centre + depth.depths[depth_label] * rays[p];
  }
  Eigen::Vector2d Moved(int p, const Eigen::Vector2f& motion_px) const {
    return Eigen::Vector2d(p % width + motion_px.x(), p / width + motion_px.y());
  }

  // ---- Unaries (terms of one pixel).
  double LabelUnary(int p, int label) const {
    return label_unary[static_cast<size_t>(p) * num_labels + label];
  }
  // λ_d E_d + the temporal E_s.
  double DepthOnlyUnary(int p, int depth_label) const;
  // λ_f E_f (raw cost `flow_cost`, incl. e_F^S) + λ_p λ_2d' e_2d^M; infinite when forbidden.
  double MotionOnlyUnary(int p, const Eigen::Vector2f& motion_px, float flow_cost) const;
  // λ_p λ_3d' (e_3d^S + e_3d^M): couples d and m (and l with shape_own_label_only).
  double Pose3d(int p, int label, int depth_label, const Eigen::Vector2f& motion_px) const;
  // One factor's unary with E_p's 3D part at the other factors' values.
  double DepthUnary(int p, int depth_label, int label, const Eigen::Vector2f& motion_px) const {
    return DepthOnlyUnary(p, depth_label) + Pose3d(p, label, depth_label, motion_px);
  }
  double MotionUnary(int p, const Eigen::Vector2f& motion_px, float flow_cost, int label,
                     int depth_label) const;
  double LabelUnaryWithPose3d(int p, int label, int depth_label,
                              const Eigen::Vector2f& motion_px) const {
    return LabelUnary(p, label) +
           (pose_options.shape_own_label_only ? Pose3d(p, label, depth_label, motion_px) : 0.0);
  }

  // ---- Pairwise terms of a pair p < q (8-neighbours).
  // E_c + E_s.
  double PairLabelDepth(int p, int q, int lp, int lq, int dp, int dq) const;
  // E_r.
  double PairMotion(int p, int q, int lp, int lq, const Eigen::Vector2f& mp,
                    const Eigen::Vector2f& mq) const;
  double Pair(int p, int q, int lp, int lq, int dp, int dq, const Eigen::Vector2f& mp,
              const Eigen::Vector2f& mq) const {
    return PairLabelDepth(p, q, lp, lq, dp, dq) + PairMotion(p, q, lp, lq, mp, mq);
  }
  // E_r's w_pq.
  double RegPairWeight(int p, int q) const {
    return motion_reg.PairWeight(reg_pixel_weight[p], reg_pixel_weight[q],
                                 motion_reg.edge_aware ? reg_edge.At(p, q, width) : 0.f);
  }
  // The weight of ρ_m in E_r's pair at labels lp, lq (0 where the pair's E_r
  // does not depend on the motions).
  double MotionRegWeight(int p, int q, int lp, int lq) const;

  // E(l, d, m) of `labelling` (motions as motion_vectors and flow_costs).
  double EnergyOf(const JointLabelling& labelling) const;
  // labelling.motion_vectors and flow_costs from labelling.motions.
  void SetMotionsFromLabels(JointLabelling* labelling) const;
};

// The terms the blocks evaluate per pixel and pair, inline for the solver's inner loops.

inline double JointEnergy::DepthOnlyUnary(int p, int depth_label) const {
  double e = 0;
  if (terms.depth)
    e += weights.depth * (depth_label == unknown ? depth.unknown_cost : depth.At(p, depth_label));
  if (terms.smooth && !previous_depth_label.empty())
    e += smoothness.Temporal(depth_label, previous_depth_label[p]);
  return e;
}

inline double JointEnergy::MotionOnlyUnary(int p, const Eigen::Vector2f& motion_px,
                                           float flow_cost) const {
  double e = 0;
  if (flow_cost >= kForbiddenMotion) return mrf::kInfiniteCost;
  if (terms.flow) e += weights.flow * flow_cost * flow_scale;
  if (use_pose) e += pose_2d_share * PoseMotion2dCost(pose, p, motion_px, pose_options);
  return e;
}

inline double JointEnergy::Pose3d(int p, int label, int depth_label,
                                  const Eigen::Vector2f& motion_px) const {
  if (!use_pose || depth_label == unknown) return 0;
  if (pose_options.shape_own_label_only && pose.object.ptr<uint16_t>()[p] != label) return 0;
  return pose_3d_share *
         Pose3dCost(pose, p, Point(p, depth_label), Moved(p, motion_px), *camera_t1, pose_options);
}

inline double JointEnergy::MotionUnary(int p, const Eigen::Vector2f& motion_px, float flow_cost,
                                       int label, int depth_label) const {
  const double e = MotionOnlyUnary(p, motion_px, flow_cost);
  return e >= mrf::kInfiniteCost ? e : e + Pose3d(p, label, depth_label, motion_px);
}

inline double JointEnergy::PairLabelDepth(int p, int q, int lp, int lq, int dp, int dq) const {
  double e = 0;
  if (lp != lq) {
    if (terms.contrast) e += ContrastCost(lp, lq, contrast.At(p, q, width));
  } else if (terms.smooth && grid.IsActive(p) && grid.IsActive(q)) {
    e += smoothness.Spatial(lp, lq, dp, dq);
  }
  return e;
}

inline double JointEnergy::PairMotion(int p, int q, int lp, int lq, const Eigen::Vector2f& mp,
                                      const Eigen::Vector2f& mq) const {
  double e = 0;
  if (terms.motion_reg && grid.IsActive(p) && grid.IsActive(q))
    e += motion_reg.Cost(RegPairWeight(p, q), lp, lq, mp, mq);
  return e;
}

inline double JointEnergy::MotionRegWeight(int p, int q, int lp, int lq) const {
  if (!terms.motion_reg || !grid.IsActive(p) || !grid.IsActive(q)) return 0;
  return motion_reg.MotionDependentWeight(RegPairWeight(p, q), lp, lq);
}

}  // namespace u4d
