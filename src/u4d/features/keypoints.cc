#include "u4d/features/keypoints.h"

#include <cmath>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {

void KeypointOptions::Check() const {
  U4D_CHECK(max_features >= 0, "KeypointOptions.max_features must be >= 0, got {}", max_features);
  U4D_CHECK(std::isfinite(contrast_threshold) && contrast_threshold > 0,
            "KeypointOptions.contrast_threshold must be > 0, got {}", contrast_threshold);
  U4D_CHECK(std::isfinite(edge_threshold) && edge_threshold > 0,
            "KeypointOptions.edge_threshold must be > 0, got {}", edge_threshold);
}

ViewKeypoints DetectKeypoints(const cv::Mat& image, const cv::Mat& mask,
                              const KeypointOptions& options) {
  options.Check();
  U4D_CHECK(!image.empty(), "DetectKeypoints: empty image");
  U4D_CHECK(image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3),
            "DetectKeypoints: image must be 8-bit grey or BGR, got type {}", image.type());
  U4D_CHECK(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == image.size()),
            "DetectKeypoints: mask must be empty or CV_8UC1 of size {}x{}, got type {} size {}x{}",
            image.cols, image.rows, mask.type(), mask.cols, mask.rows);
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image;
  }
  auto sift = cv::SIFT::create(options.max_features, 3, options.contrast_threshold,
                               options.edge_threshold, 1.6);
  ViewKeypoints out;
  sift->detectAndCompute(grey, mask, out.keypoints, out.descriptors);
  if (out.descriptors.empty()) out.descriptors = cv::Mat(0, 128, CV_32F);
  if (options.root_sift) {
    for (int i = 0; i < out.descriptors.rows; ++i) {
      cv::Mat row = out.descriptors.row(i);
      const double l1 = cv::norm(row, cv::NORM_L1);
      if (l1 > 0) row /= l1;
      cv::sqrt(row, row);
    }
  }
  return out;
}

cv::Mat MaskFromInstances(const cv::Mat& ids, int dilation_px) {
  U4D_CHECK(!ids.empty() && ids.channels() == 1,
            "MaskFromInstances: ids must be a non-empty "
            "single-channel image");
  U4D_CHECK(dilation_px >= 0, "MaskFromInstances: dilation_px must be >= 0, got {}", dilation_px);
  cv::Mat mask = ids != 0;
  if (dilation_px > 0) {
    const cv::Mat disk = cv::getStructuringElement(
        cv::MORPH_ELLIPSE, cv::Size(2 * dilation_px + 1, 2 * dilation_px + 1));
    cv::dilate(mask, mask, disk);
  }
  return mask;
}

}  // namespace u4d
