// Helpers shared by the init module's sources (not part of its API).
#pragma once

#include <cmath>

#include <opencv2/core.hpp>

#include "u4d/init/init.h"

namespace u4d {

inline double LabDistance(const cv::Vec3b& a, const cv::Vec3b& b) {
  const double d0 = static_cast<double>(a[0]) - b[0];
  const double d1 = static_cast<double>(a[1]) - b[1];
  const double d2 = static_cast<double>(a[2]) - b[2];
  return std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

// ForegroundMask (step 2) of an image already in 8-bit Lab (sizes checked by the caller).
cv::Mat ForegroundFromLab(const cv::Mat& lab, const BackgroundModel& background,
                          const InitOptions& options);
// Opening and closing, then components and holes below min_blob_fraction go.
cv::Mat CleanMask(const cv::Mat& mask, const InitOptions& options);
// Sets components (8-connected, of a 0/255 mask) smaller than min_area to 0.
void RemoveSmallComponents(cv::Mat& mask, double min_area);

}  // namespace u4d
