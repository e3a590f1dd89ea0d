// The set-up steps of SolveJointView: each fills part of a view's JointEnergy
// (joint_energy.h) from its JointViewInput, in the order SolveJointView runs them.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "u4d/joint/flow_cost.h"
#include "u4d/joint/joint_energy.h"
#include "u4d/joint/joint_view.h"
#include "u4d/joint/label_costs.h"

namespace u4d {

// Throws u4d::Error on inconsistent input (sizes, counts, label ids).
void CheckJointViewInput(const JointViewInput& in);

// `mask` (CV_8U) grown by a disc of radius `margin` pixels (0: unchanged).
cv::Mat GrowRegion(const cv::Mat& mask, int margin);
// The optimised pixels (CV_8U): the initial labels' objects and the objects'
// regions, grown by `margin`.
cv::Mat RegionOfInterest(const JointViewInput& in, int margin);

// The energy's settings (weights, switches, E_s and E_r parameters), the grid
// over `roi`, its neighbour pairs and the pixels' rays. No term data yet.
JointEnergy MakeJointEnergy(const JointViewInput& in, const JointViewOptions& options,
                            const cv::Mat& roi);

// The label-cost volumes the label unaries, E_c and E_r's weights read.
struct LabelTermVolumes {
  LabelCostVolume appearance;           // E_a (refitted by RefitAppearance)
  LabelCostVolume semantic;             // E_sem
  std::vector<LabelledImage> training;  // ψ_T for E_a's colour models
  cv::Mat appearance_where;             // where E_a is evaluated (the roi + 1 pixel)
};

// E_a, E_sem and E_p (the capsules; its label part e_2d^S + e_2d^L) into
// energy->label_unary.
LabelTermVolumes SetUpLabelUnaries(const JointViewInput& in, const JointViewOptions& options,
                                   const cv::Mat& roi, JointEnergy* energy);
// energy->label_unary from the volumes (and the pose map).
void FillLabelUnary(const JointViewOptions& options, const LabelTermVolumes& volumes,
                    JointEnergy* energy);
// E_c's pair costs, and E_r's colour-contrast weights c_pq when edge-aware.
void SetUpContrast(const JointViewInput& in, const JointViewOptions& options,
                   const LabelTermVolumes& volumes, JointEnergy* energy);
// The appearance refits (GrabCut's iteration, before the energy is fixed,
// JointViewOptions::appearance_refits): the label-only energy (label unaries +
// E_c) is minimised, frame t's colour models are re-learnt from that
// labelling, and the label unaries recomputed. Returns whether it ran.
bool RefitAppearance(const JointViewInput& in, const JointViewOptions& options,
                     LabelTermVolumes* volumes, JointEnergy* energy);
// E_r's per-pixel weights w_p (e_r^L, e_r^A at the initial labels).
void SetUpMotionRegWeights(const JointViewInput& in, const JointViewOptions& options,
                           const LabelTermVolumes& volumes, JointEnergy* energy);
// E_d over the objects' depth range, each pixel's allowed depths
// (depth_object_ranges) and the temporal E_s's previous depth labels.
// Throws when no object has a depth range.
void SetUpDepthTerms(const JointViewInput& in, const JointViewOptions& options, const cv::Mat& roi,
                     JointEnergy* energy);
// The motion labels M and E_f (a single zero motion on the last frame). Returns
// E_f's input (for the flow fusion); *plane_sweep_depth is the winner-take-all
// of E_d that E_f's cross-view part reads.
FlowCostInput SetUpFlowTerms(const JointViewInput& in, const JointViewOptions& options,
                             const cv::Mat& roi, JointEnergy* energy, cv::Mat* plane_sweep_depth);
// The initial labelling: the initial labels, then per pixel the best depth
// (at the zero motion), then the best motion.
JointLabelling InitialLabelling(const JointViewInput& in, const JointEnergy& energy);

}  // namespace u4d
