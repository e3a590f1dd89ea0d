// OpenCV semi-global matching (Hirschmüller 2008, cv::StereoSGBM) as a
// multi-view depth baseline for the joint optimisation's depth (paper Sec. 4,
// Table "Reconstruction evaluation": "SGBM on rectified pairs, fused").
//
// For a reference view, the `num_pairs` auxiliary views whose camera centres
// make the smallest angle with the reference's as seen from the scene (the
// angle between the two viewing directions, which sets the rectification
// distortion; views more than max_pair_angle_deg apart are skipped) are each
// paired with it. Per pair: cv::stereoRectify (distortion included; the
// partner's rectified principal point then moved along the baseline so that
// the searched disparities are centred on 0: converging cameras otherwise put
// them beyond the image width), cv::initUndistortRectifyMap + remap, the
// rectified pair turned so that the reference is the left image of a
// horizontal pair (transposed when the baseline is vertical, mirrored when
// the auxiliary camera is on the left), cv::StereoSGBM with left-right check,
// and each reference pixel's disparity (nearest rectified sample) converted to
// the point on its rectified ray, whose z in the ORIGINAL reference camera is
// the pair's depth. The pairs are fused by the median of their valid depths.
//
// Output: CV_32F z in the reference camera (metres), reference image size;
// 0 = unknown (the repository's depth convention, eval/dense_metrics.h):
// pixels no pair matched, outside [depth_near, depth_far] widened by
// range_margin, or rejected by SGBM's uniqueness / left-right / speckle
// filters, and every pixel of a view with no partner within
// max_pair_angle_deg (e.g. a 4-camera ring: 90 degree neighbours, which
// rectify into images with nothing in common).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"

namespace u4d::baselines {

struct StereoSgbmOptions {
  int num_pairs = 2;               // auxiliary views paired with the reference (>= 1)
  double max_pair_angle_deg = 60;  // skip auxiliary views farther apart than this (0, 180)
  int block_size = 5;              // SGBM matching block (odd, >= 1)
  int p1_per_px = 8;               // P1 = p1_per_px * channels * block_size^2 (>= 0)
  int p2_per_px = 32;              // P2 = p2_per_px * channels * block_size^2 (> p1_per_px)
  int uniqueness_ratio = 10;       // percent margin of the best over the second best (>= 0)
  int disp12_max_diff = 1;         // left-right check tolerance, pixels (< 0 = off)
  int speckle_window = 100;        // speckle filter region size (0 = off)
  int speckle_range = 2;           // max disparity variation inside a speckle (pixels)
  bool three_way = true;           // cv::StereoSGBM::MODE_SGBM_3WAY (else MODE_SGBM, 5 paths)
  int max_disparities = 384;       // cap on the disparity range searched (multiple of 16)
  double range_margin = 0.1;       // [near, far] widened by this fraction for the search
  void Check() const;              // throws u4d::Error naming the bad field
};

// The auxiliary views used for `ref_view`, best first (smallest angle between
// the viewing directions of the scene point at `scene_depth` on the
// reference's optical axis, i.e. the triangulation angle there).
std::vector<int> SelectStereoPairs(const std::vector<Camera>& cameras, int ref_view,
                                   double scene_depth, const StereoSgbmOptions& options = {});

// Depth of one rectified pair (reference, aux): CV_32F z in the reference
// camera, 0 = unknown. The disparity search covers depths in [depth_near,
// depth_far] (metres, 0 < near < far), widened by range_margin and capped at
// max_disparities. Throws u4d::Error on bad views, images (BGR or grey 8-bit,
// each its camera's size), or a bad range.
cv::Mat SgbmPairDepth(const Camera& ref_camera, const cv::Mat& ref_image, const Camera& aux_camera,
                      const cv::Mat& aux_image, double depth_near, double depth_far,
                      const StereoSgbmOptions& options = {});

// The fused depth of `ref_view` (median over the pairs of SelectStereoPairs,
// scene depth = the middle of [near, far]). `images[v]` BGR 8-bit for every
// view. Throws like SgbmPairDepth or when the counts differ.
cv::Mat SgbmFusedDepth(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& images,
                       int ref_view, double depth_near, double depth_far,
                       const StereoSgbmOptions& options = {});

}  // namespace u4d::baselines
