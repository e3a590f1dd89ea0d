// Dense optical-flow baselines the joint optimisation's flow is compared
// against (paper Sec. 4, "Flow" comparison): DeepFlow (Weinzaepfel et al.,
// OpenCV contrib optflow), DIS (Kroeger et al., cv::DISOpticalFlow, MEDIUM
// preset) and Farneback (cv::calcOpticalFlowFarneback, OpenCV's example
// parameters). All run on the grey images with OpenCV's defaults otherwise,
// through DenseFlow (dense_flow.h).
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace u4d::baselines {

enum class FlowBaseline { kDeepFlow, kDis, kFarneback };

std::string ToString(FlowBaseline which);  // "deepflow", "dis", "farneback"
FlowBaseline FlowBaselineFromString(
    const std::string& name);  // throws u4d::Error listing the names
const std::vector<FlowBaseline>& AllFlowBaselines();

// Forward flow image_t -> image_t1 (CV_32FC2, (dx, dy) pixels, pixel (x, y) of
// image_t moves to (x, y) + flow(x, y)). Images are BGR or grey 8-bit of the
// same size. Throws u4d::Error on empty, mismatched or non-8-bit images.
// DenseFlow with kDeepFlow, kDisMedium or kFarneback.
cv::Mat BaselineFlow(FlowBaseline which, const cv::Mat& image_t, const cv::Mat& image_t1);

}  // namespace u4d::baselines
