// Per-view SIFT keypoints for the sparse reconstruction (paper Sec. 2.1,
// "sparse reconstruction": sparse features are matched across the calibrated
// views of one frame and triangulated). Detection may be restricted to a mask,
// e.g. the dilated union of the initial instance masks (MaskFromInstances), so
// that features concentrate on the dynamic objects.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace u4d {

struct KeypointOptions {
  int max_features = 4000;           // keep at most this many (strongest) per view; 0 = all
  double contrast_threshold = 0.01;  // SIFT contrast threshold (OpenCV default 0.04)
  double edge_threshold = 10.0;      // SIFT edge threshold (OpenCV default)
  bool root_sift = true;             // RootSIFT: L1-normalise, then square-root descriptors

  void Check() const;  // throws u4d::Error naming the field on a bad value
};

struct ViewKeypoints {
  std::vector<cv::KeyPoint> keypoints;  // pixel (x, y), origin at the centre of pixel (0, 0)
  cv::Mat descriptors;                  // CV_32F, one 128-vector per keypoint
  int size() const { return static_cast<int>(keypoints.size()); }
};

// SIFT on `image` (BGR or grey, 8-bit). `mask` is empty (whole image) or
// CV_8U of the image's size, non-zero where features may be detected.
// Throws u4d::Error on an empty image or a mask of the wrong size/type.
ViewKeypoints DetectKeypoints(const cv::Mat& image, const cv::Mat& mask,
                              const KeypointOptions& options = {});

// CV_8U mask (255/0): non-zero pixels of the id image `ids` (any integer
// type), dilated by a disk of radius `dilation_px` (>= 0).
cv::Mat MaskFromInstances(const cv::Mat& ids, int dilation_px);

}  // namespace u4d
