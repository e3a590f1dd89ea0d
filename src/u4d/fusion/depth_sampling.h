// Sampling per-view depth and flow maps at sub-pixel positions, shared by
// the fusion, the scene-flow tracking and the flow consensus. Internal to
// the fusion module.
//
// Depth maps are CV_32FC1 z in metres in the camera frame (0 = unknown);
// instance maps are CV_16UC1 ids (0 = background). Pixel (x, y) has its
// origin at the centre of the top-left pixel (docs/conventions.md).
#pragma once

#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace u4d::fusion_internal {

// Depth of the surface of `object_id` at `pixel`: bilinear over the four
// neighbouring pixels when all four are known, belong to the object (when
// `ids` is non-empty) and span less than `max_depth_jump` metres; otherwise
// the nearest pixel when it qualifies; otherwise 0.
double SampleObjectDepth(const cv::Mat& depth, const cv::Mat& ids, int object_id,
                         const Eigen::Vector2d& pixel, double max_depth_jump);

// Flow (CV_32FC2) at `pixel`: bilinear when the four neighbouring pixels
// are inside and belong to `object_id` (any pixel when `ids` is empty);
// otherwise the nearest pixel's, clamped to the image.
Eigen::Vector2d SampleObjectFlow(const cv::Mat& flow, const cv::Mat& ids, int object_id,
                                 const Eigen::Vector2d& pixel);

// Instance id at the nearest pixel; -1 outside the image, 0 when ids is empty.
int SampleId(const cv::Mat& ids, const Eigen::Vector2d& pixel);

// Throws u4d::Error naming `what` unless `m` is `type` with the given size.
void CheckMap(const cv::Mat& m, int type, int width, int height, const std::string& what);

}  // namespace u4d::fusion_internal
