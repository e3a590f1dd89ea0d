// The depth unary term E_d of the joint optimisation (paper Sec. 2.1.4,
// "Unary terms", depth term) and the winner-take-all plane-sweep baseline.
//
//   e_d(p, d_p) = M(p, q) = mean over i in O_k of m(p, q_i)   if d_p != U
//               = M_U                                          if d_p = U
//
// where q_i is the projection into auxiliary view i of the point on the ray of
// reference pixel p at depth d_p, and O_k are the k auxiliary views with the
// lowest m at that pixel and depth (the k most photo-consistent ones). The
// paper sums over O_k; we average so that M stays on the scale of m, in
// [0, 1], and M_U is comparable whatever k is.
//
// m(p, q) = (1 - ZNCC) / 2 over a (2r+1)^2 patch (BGR, or grey) between the
// reference image and the auxiliary image sampled at the projections of the
// patch's pixels at the hypothesised depth (fronto-parallel plane sweep). The
// auxiliary image is warped into the reference view once per depth label
// (per pixel: the point at z on the pixel's ray, projected with the auxiliary
// camera, bilinear sampling; for distortion-free cameras this is the
// plane-induced homography, with distortion it is the exact mapping) and the
// ZNCC of every pixel is then read from box-filtered moments, so the cost per
// pixel and label does not depend on the patch size. Patches whose
// standard deviation per channel is below `min_patch_std` in the reference (textureless)
// get m = 0.5, the value of uncorrelated patches. Auxiliary views where the
// point falls outside the image or behind the camera are not candidates for
// O_k; when fewer than k views see the point the available ones are
// averaged, when none does the cost is 1.
//
// Depth labels are sampled uniformly in inverse depth (uniform in disparity
// for a rectified pair), label i meaning z = depths[i] in the reference
// camera, in metres.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"
#include "u4d/joint/roi_slots.h"

namespace u4d {

struct DepthCostOptions {
  int num_depths = 64;     // depth labels sampled uniformly in INVERSE depth over [near, far]
  int patch_radius = 2;    // NCC window (2r+1)^2
  int num_best_views = 3;  // k of O_k: the k most photo-consistent auxiliary views are averaged
  int max_aux_views = 4;   // auxiliary views considered: the ones whose optical axes are
                           // closest in angle to the reference's (excluding views > 90 deg apart)
  double unknown_cost = 0.6;   // M_U, the cost of the unknown label (same scale as m, in [0, 1])
  double min_patch_std = 2.0;  // reference patches with a std below this (0..255 scale, per
                               // channel: summed variance < nc * std^2) are textureless: m = 0.5
  bool use_color = true;       // ZNCC over the three BGR channels (else over grey values)
  double smooth_sigma = 0.0;   // Gaussian pre-smoothing of the images (pixels, 0 = none); it
                               // blurs the texture ZNCC relies on (docs/depth.md)
  void Check() const;          // throws u4d::Error naming the field on a bad value
};

// Per-pixel matching cost for a set of depth labels of one reference view;
// label i means z = depths[i] (metres, z in the reference camera).
struct DepthCostVolume {
  int width = 0, height = 0;
  std::vector<float> depths;  // label -> z
  RoiSlots slots;             // the stored pixels: the roi's (roi_slots.h)
  // cost[label * slots.count + slots.slot[pixel]] in [0, 1]; 1 where no
  // auxiliary view sees the point. Pixels outside the roi are not stored and
  // cost 1 (At).
  std::vector<float> cost;
  float unknown_cost = 0.6f;
  float At(int pixel, int label) const {
    const int s = slots.slot[pixel];
    return s < 0 ? 1.0f : cost[static_cast<size_t>(label) * slots.count + s];
  }
  int NumLabels() const { return static_cast<int>(depths.size()); }
};

// n (>= 2) depths from `near` to `far` (0 < near < far, metres), uniform in 1/z:
// samples[0] = near, samples[n-1] = far. Throws u4d::Error on bad arguments.
std::vector<float> InverseDepthSamples(double near, double far, int n);

// The auxiliary views of `ref_view` used by ComputeDepthCostVolume: at most
// `max_aux_views` other views whose optical axes make less than 90 degrees
// with the reference's, closest in angle first.
std::vector<int> SelectAuxViews(const std::vector<Camera>& cameras, int ref_view,
                                int max_aux_views);

// Cost volume for `ref_view` at one time instant. `images[v]` (BGR 8-bit) and
// `cameras[v]` for every view (same order), all of one frame, at the working
// resolution (the solver passes ScaledCamera'd cameras and resized images).
// `roi` CV_8U of the reference size (nonzero = compute), empty = all; only the
// bounding box of the ROI (plus the patch radius) is warped and only the ROI's
// pixels are stored, so a small ROI is proportionally cheaper. Parallel over depth labels (TBB).
// Throws u4d::Error on mismatched sizes/counts, an image that is not CV_8UC3,
// a bad ref_view, or a bad depth range (need 0 < near < far).
DepthCostVolume ComputeDepthCostVolume(const std::vector<Camera>& cameras,
                                       const std::vector<cv::Mat>& images, int ref_view,
                                       const cv::Mat& roi, double depth_near, double depth_far,
                                       const DepthCostOptions& options = {});

// Winner-take-all over the volume (the plane-sweep baseline): per pixel the
// cheapest label's depth, with parabolic sub-sample refinement of the cost
// around the minimum (in inverse depth); 0 where outside roi (empty = all) or
// where the best cost is >= unknown_cost. CV_32F z in metres.
cv::Mat WinnerTakeAllDepth(const DepthCostVolume& volume, const cv::Mat& roi);

// Sub-sample refinement of a given label map (the solver's result): the same
// parabola fit at each pixel's label. labels: one per pixel (row-major,
// width * height), -1 = unknown -> 0. CV_32F z. Throws u4d::Error on a wrong
// count or a label outside [-1, NumLabels()).
cv::Mat RefineDepthLabels(const DepthCostVolume& volume, const std::vector<int>& labels);

// The refined depth of `pixel` at `label`: a parabola through the costs of
// labels label-1, label, label+1 in inverse depth, its vertex used when it is
// a minimum within half a label step; otherwise (and at the first/last label)
// depths[label].
float RefinedDepth(const DepthCostVolume& volume, int pixel, int label);

}  // namespace u4d
