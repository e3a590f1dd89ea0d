// The flow unary term E_f of the joint optimisation (paper Sec. 2.1, "Motion
// constraints - E_f(m) and E_r(l,m)", after Tao et al. 2012):
//   E_f(p, m) = e_F^T(p, m) + e_F^V(p, m) + e_F^S(p, m)
// evaluated for every pixel p of the reference view at frame t and every
// motion label m of the discrete set M (joint/motion_labels.h), into a cost
// volume that the solver (and WinnerTakeAllFlow below) minimises.
//
// Terms, with colours in [0, 1] per channel and d(a, b) = ||a - b||^2 / 3 (the
// squared colour distance averaged over the channels):
//  - e_F^T (brightness constancy in time, same view): d(I_ref(p, t),
//    I_ref(p + m, t + 1)), sampled bilinearly; a p + m outside the image costs
//    `truncation`.
//  - e_F^V (appearance across views): the 3D point X = Unproject(p, z) with z
//    = depth_t(p) is moved to the ray of the reference camera at t+1 through
//    p + m, at the same depth z (small-depth-change approximation: the flow
//    does not tell the depth at t+1; the error is second order for motion
//    parallel to the image plane, which dominates for people seen side-on),
//    projected into every other view i at t+1 and d(I_ref(p, t), I_i(x_i,
//    t + 1)) averaged over the views where x_i lands inside the image, among
//    the views within max_view_angle_deg of the reference view's optical axis
//    (the only visibility test: no depth of the other views is needed). 0 where the depth is
//    unknown (0) or no view sees X.
//  - e_F^S (sparse constraint): 0 when m is within `window` (Chebyshev) of the
//    displacement of some sparse correspondence within support_radius of p,
//    or (dense_support) of p's dense match, kForbiddenMotion otherwise; pixels
//    with no correspondence allow every label, as do pixels where the
//    constraint would forbid every label (a displacement whose window was not
//    kept in M).
// The robust version: the per-pixel colour costs of e_F^T and e_F^V are
// averaged over a (2r+1)^2 patch centred at p (e_F^V over the pixels of the
// patch with a defined cost) and then truncated at `truncation`. The paper
// sums e_F^T over all views; here the reference view carries e_F^T and the
// other views enter through e_F^V (they are what e_F^V compares with), so no
// view is counted twice.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"
#include "u4d/joint/motion_labels.h"
#include "u4d/joint/roi_slots.h"

namespace u4d {

struct FlowCostOptions {
  bool temporal = true;    // e_F^T: brightness constancy, same view, t -> t+1
  bool cross_view = true;  // e_F^V: consistency with the other views at t+1 (needs depth_t)
  bool sparse = true;      // e_F^S: labels farther than `window` from every nearby sparse
                           // displacement are forbidden
  // e_F^S also allows, at every pixel, the motions within `window` of the
  // pixel's dense match (FlowCostInput::dense_matches). Tracks are few and
  // a limb's motion varies by more than a window within support_radius, so
  // the tracks alone forbid the true motion where the body bends or turns;
  // and a pixel far from every track would otherwise allow every motion.
  bool dense_support = true;
  // e_F^V uses only the views whose optical axis is within this angle of the
  // reference view's (degrees, in (0, 180]): a crude visibility test, since a
  // surface seen by the reference is mostly hidden from cameras facing it.
  double max_view_angle_deg = 75;
  int patch_radius = 1;     // colour differences averaged over a (2r+1)^2 patch (>= 0)
  double truncation = 0.1;  // per-term costs truncated at this (> 0)
  void Check() const;       // throws u4d::Error naming the bad field
};

// Cost of a forbidden label (e_F^S); finite so that sums stay ordered.
inline constexpr float kForbiddenMotion = 1e9f;

struct MotionCostVolume {
  int width = 0, height = 0;
  std::vector<Eigen::Vector2f> motions;  // label -> (dx, dy), pixels
  RoiSlots slots;                        // the stored pixels: the roi's (roi_slots.h)
  // cost[label * slots.count + slots.slot[pixel]], pixel = y * width + x.
  // Pixels outside the roi are not stored and cost 0 for every label (At).
  std::vector<float> cost;
  float At(int pixel, int label) const {
    const int s = slots.slot[pixel];
    return s < 0 ? 0.0f : cost[static_cast<size_t>(label) * slots.count + s];
  }
  int NumLabels() const { return static_cast<int>(motions.size()); }
};

struct FlowCostInput {
  int ref_view = 0;
  std::vector<Camera> cameras_t, cameras_t1;  // all views at t and t+1 (working resolution)
  std::vector<cv::Mat> images_t, images_t1;   // BGR 8-bit, all views, working resolution
  cv::Mat depth_t;                   // CV_32F z of the reference view at t (0 = unknown); empty
                                     // -> no e_F^V
  std::vector<SparseMotion> sparse;  // sparse correspondences of the reference view t -> t+1
  // A dense correspondence per pixel (CV_32FC2 flow t -> t+1, e.g. OpenCV DIS);
  // empty = none. e_F^S counts it as one more correspondence at every pixel
  // (FlowCostOptions::dense_support).
  cv::Mat dense_matches;
  cv::Mat roi;  // CV_8U nonzero = compute; empty = all
};

// The cost volume of E_f over `motions` (usually BuildMotionLabels of
// input.sparse). Uses label_options.window and support_radius for e_F^S.
// Parallel over labels (TBB). Throws u4d::Error when the reference view is
// out of range, the images or cameras are missing or differ in size from the
// reference camera, an image is not BGR 8-bit, depth or roi have the wrong type
// or size, the motion set is empty, or an option is bad. images_t of views
// other than the reference are not needed and may be empty.
MotionCostVolume ComputeFlowCostVolume(const FlowCostInput& input,
                                       const std::vector<Eigen::Vector2f>& motions,
                                       const MotionLabelOptions& label_options,
                                       const FlowCostOptions& options = {});

// E_f's photometric part e_F^T + e_F^V for a dense, sub-pixel flow field
// (CV_32FC2 (dx, dy), the reference view's size): per roi pixel p the cost of
// the motion flow(p), computed exactly as the cost volume computes the cost of
// a label (patch of radius patch_radius sharing p's motion, bilinear samples,
// same borders, truncation), so an integer motion costs what its label costs
// in ComputeFlowCostVolume up to float rounding. e_F^S is not included (it
// depends on the label set; the caller applies it). CV_32F, 0 outside roi.
// Throws like ComputeFlowCostVolume (naming FlowFieldCosts), or on a flow of
// the wrong type or size, or a non-finite flow in the roi.
cv::Mat FlowFieldCosts(const FlowCostInput& input, const cv::Mat& flow,
                       const FlowCostOptions& options = {});

// e_F^S of a continuous motion m at pixel p for the flow fusion: allowed
// (false) when the nearest integer motion in M (`label`, -1 = none) is allowed
// by `volume`, or when m is within `window` of p's dense match (with
// dense_support and input.dense_matches given).
bool ForbiddenMotion(const MotionCostVolume& volume, const FlowCostInput& input,
                     const FlowCostOptions& options, int window, int p, int label,
                     const Eigen::Vector2f& m);

// Winner-take-all flow: per pixel the cheapest label, with parabolic sub-pixel
// refinement per axis where the labels one pixel either side exist and are not
// forbidden. CV_32FC2 (dx, dy), 0 outside roi (empty roi = all pixels).
cv::Mat WinnerTakeAllFlow(const MotionCostVolume& volume, const cv::Mat& roi);
// The same refinement for a given label map (width * height entries, one label
// per pixel; -1 -> flow 0). Throws on a wrong size or a label out of range.
cv::Mat RefineFlowLabels(const MotionCostVolume& volume, const std::vector<int>& labels);

}  // namespace u4d
