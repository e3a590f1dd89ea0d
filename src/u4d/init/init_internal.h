// Helpers shared by the init module's sources (not part of its API).
#pragma once

#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/init/init.h"
#include "u4d/util/check.h"

namespace u4d {

inline double LabDistance(const cv::Vec3b& a, const cv::Vec3b& b) {
  const double d0 = static_cast<double>(a[0]) - b[0];
  const double d1 = static_cast<double>(a[1]) - b[1];
  const double d2 = static_cast<double>(a[2]) - b[2];
  return std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

// The input check of the steps that take an image and its foreground mask:
// `function` names the caller in the error.
inline void CheckImageAndForeground(const char* function, const cv::Mat& image_bgr,
                                    const cv::Mat& foreground) {
  U4D_CHECK(!image_bgr.empty() && image_bgr.type() == CV_8UC3,
            "{}: expected a non-empty BGR image (CV_8UC3)", function);
  U4D_CHECK(
      !foreground.empty() && foreground.type() == CV_8UC1 && foreground.size() == image_bgr.size(),
      "{}: foreground must be CV_8UC1 of the image's size {}x{}", function, image_bgr.cols,
      image_bgr.rows);
}

// ForegroundMask (step 2) of an image already in 8-bit Lab (sizes checked by the caller).
cv::Mat ForegroundFromLab(const cv::Mat& lab, const BackgroundModel& background,
                          const InitOptions& options);
// Opening and closing, then components and holes below min_blob_fraction go.
cv::Mat CleanMask(const cv::Mat& mask, const InitOptions& options);
// Masks at a reduced resolution (longest side at most max_side) for the
// multi-view steps (3 and 6): per view the scaled camera, the source mask
// (pixels at least half covered) and the target mask (any coverage, dilated
// by dilation_px).
struct ReducedMasks {
  std::vector<Camera> cameras;
  std::vector<cv::Mat> source, target;
};
ReducedMasks ReduceMasks(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& masks,
                         int max_side, int dilation_px);
// GrabCut's k-means draws from the thread's RNG, whose state depends on
// what ran on that thread before: while one of these lives, the thread's
// RNG has a fixed seed, so that a cut is reproducible; the caller's RNG
// state comes back at the end of the scope.
class FixedGrabCutSeed {
 public:
  FixedGrabCutSeed() : saved_(cv::theRNG()) { cv::theRNG() = cv::RNG(0x5eed); }
  ~FixedGrabCutSeed() { cv::theRNG() = saved_; }
  FixedGrabCutSeed(const FixedGrabCutSeed&) = delete;
  FixedGrabCutSeed& operator=(const FixedGrabCutSeed&) = delete;

 private:
  cv::RNG saved_;
};

// Whether AddDetectedPeople fills boxes in a view with this foreground (box_fill).
bool FillsBoxes(const cv::Mat& foreground, const InitOptions& options);
// Sets components (8-connected, of a 0/255 mask) smaller than min_area to 0.
void RemoveSmallComponents(cv::Mat& mask, double min_area);

}  // namespace u4d
