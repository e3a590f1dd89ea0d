// Per-pixel depth and optical-flow metrics.
//
// Depth (metres, z along the optical axis; io/image_io.h): a pixel is
// GT-valid when the GT depth is > 0, predicted-valid when the prediction is
// > 0. Evaluated pixels are those valid in both (and inside the optional
// mask). NaN, infinite or negative depth is a corrupt file and throws.
//   AbsRel      mean |d - d*| / d*
//   RMSE        sqrt(mean (d - d*)^2), metres
//   delta_1pct  share with |d - d*| / d* <= 0.01; delta_5pct likewise 0.05
//   completeness  evaluated pixels / GT-valid pixels (inside the mask)
// Flow (pixels, forward t -> t+1): a pixel is GT-valid when the valid mask is
// set (or, without one, the GT vector is finite and below 1e9 in magnitude);
// predicted-valid likewise. Evaluated pixels are valid in both.
//   EPE         mean ||f - f*||_2, pixels
//   within_1px / within_3px   share with EPE < 1 / < 3 pixels
//   motion_scale  sum f . u* / sum |f*| over the evaluated pixels whose true
//                 motion |f*| is at least kMovingPx (u* = f* / |f*|): the
//                 predicted motion's length along the true direction relative
//                 to the true length, pooled; 1 = unbiased, below 1 = the
//                 motion is under-estimated (a flow shrunk towards its
//                 neighbours' or the static background's motion). EPE does not
//                 tell a shrunk flow from a noisy one of the same size.
//   completeness  evaluated pixels / GT-valid pixels
// Results hold sums so that Add() pools pixels over many images: every average
// is over all evaluated pixels of the dataset (pixel-weighted), not a mean of
// per-image means.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace u4d::eval {

struct DepthMetrics {
  int64_t gt_valid = 0;   // GT-valid pixels inside the mask
  int64_t evaluated = 0;  // also predicted-valid
  double sum_abs_rel = 0, sum_sq = 0;
  int64_t within_1pct = 0, within_5pct = 0;

  void Add(const DepthMetrics& o);
  double AbsRel() const;  // NaN when nothing was evaluated (likewise below)
  double Rmse() const;
  double Delta1Pct() const;
  double Delta5Pct() const;
  double Completeness() const;
  nlohmann::json ToJson() const;
};

// `pred` and `gt` are CV_32FC1 of the same size; `mask` is empty (all pixels)
// or CV_8UC1 of the same size (non-zero = evaluate). A `pred` that is empty
// counts as no prediction anywhere (completeness 0). Throws u4d::Error naming
// `context` on mismatched sizes or types and on NaN, infinite or negative depth.
DepthMetrics EvaluateDepth(const cv::Mat& pred, const cv::Mat& gt, const cv::Mat& mask,
                           const std::string& context);

struct FlowMetrics {
  // True motions shorter than this (pixels) have no direction that
  // motion_scale could measure against.
  static constexpr double kMovingPx = 1.0;

  int64_t gt_valid = 0;
  int64_t evaluated = 0;
  double sum_epe = 0;
  int64_t within_1px = 0, within_3px = 0;
  int64_t beyond_10px = 0;     // gross errors: endpoint error above 10 px
  double sum_along = 0;        // f . u* over the moving pixels (motion_scale)
  double sum_true_length = 0;  // |f*| over the same pixels

  void Add(const FlowMetrics& o);
  double Epe() const;  // NaN when nothing was evaluated (likewise below)
  double Within1Px() const;
  double Within3Px() const;
  double Beyond10Px() const;   // share of the evaluated pixels off by more than 10 px
  double MotionScale() const;  // NaN when no evaluated pixel moves kMovingPx or more
  double Completeness() const;
  nlohmann::json ToJson() const;
};

// `pred` and `gt` are CV_32FC2; `gt_valid` empty or CV_8UC1 (non-zero = valid);
// `mask` empty or CV_8UC1. An empty `pred` counts as no prediction anywhere.
// Throws naming `context` on mismatched sizes or types.
FlowMetrics EvaluateFlow(const cv::Mat& pred, const cv::Mat& gt, const cv::Mat& gt_valid,
                         const cv::Mat& mask, const std::string& context);

// True when a flow vector is usable: finite and below 1e9 in each component
// (Middlebury's "unknown" marker is 1e10).
bool FlowValid(float u, float v);

}  // namespace u4d::eval
