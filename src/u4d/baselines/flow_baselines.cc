#include "u4d/baselines/flow_baselines.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/optflow.hpp>
#include <opencv2/video/tracking.hpp>

#include "u4d/util/check.h"

namespace u4d::baselines {
namespace {

cv::Mat Grey(const cv::Mat& image, const char* what) {
  U4D_CHECK(!image.empty(), "BaselineFlow: {} is empty", what);
  U4D_CHECK(image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3),
            "BaselineFlow: {} must be 8-bit grey or BGR, got type {}", what, image.type());
  if (image.channels() == 1) return image;
  cv::Mat g;
  cv::cvtColor(image, g, cv::COLOR_BGR2GRAY);
  return g;
}

}  // namespace

std::string ToString(FlowBaseline which) {
  switch (which) {
    case FlowBaseline::kDeepFlow:
      return "deepflow";
    case FlowBaseline::kDis:
      return "dis";
    case FlowBaseline::kFarneback:
      return "farneback";
  }
  ThrowError("ToString: unknown FlowBaseline");
}

FlowBaseline FlowBaselineFromString(const std::string& name) {
  for (FlowBaseline b : AllFlowBaselines())
    if (ToString(b) == name) return b;
  ThrowError(fmt::format("unknown flow baseline '{}' (known: deepflow, dis, farneback)", name));
}

const std::vector<FlowBaseline>& AllFlowBaselines() {
  static const std::vector<FlowBaseline> all = {FlowBaseline::kDeepFlow, FlowBaseline::kDis,
                                                FlowBaseline::kFarneback};
  return all;
}

cv::Mat BaselineFlow(FlowBaseline which, const cv::Mat& image_t, const cv::Mat& image_t1) {
  const cv::Mat a = Grey(image_t, "image_t"), b = Grey(image_t1, "image_t1");
  U4D_CHECK(a.size() == b.size(), "BaselineFlow: image_t is {}x{} but image_t1 is {}x{}", a.cols,
            a.rows, b.cols, b.rows);
  cv::Mat flow;
  switch (which) {
    case FlowBaseline::kDeepFlow:
      cv::optflow::createOptFlow_DeepFlow()->calc(a, b, flow);
      break;
    case FlowBaseline::kDis:
      cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM)->calc(a, b, flow);
      break;
    case FlowBaseline::kFarneback:
      // OpenCV's sample parameters (fback.cpp): pyramid 0.5, 3 levels, window
      // 15, 3 iterations, poly_n 5, poly_sigma 1.2.
      cv::calcOpticalFlowFarneback(a, b, flow, 0.5, 3, 15, 3, 5, 1.2, 0);
      break;
  }
  U4D_ASSERT(flow.type() == CV_32FC2 && flow.size() == a.size());
  return flow;
}

}  // namespace u4d::baselines
