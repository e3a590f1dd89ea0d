#include "u4d/baselines/flow_baselines.h"

#include "u4d/baselines/dense_flow.h"
#include "u4d/util/check.h"

namespace u4d::baselines {

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
  switch (which) {
    case FlowBaseline::kDeepFlow:
      return DenseFlow(DenseFlowMethod::kDeepFlow, image_t, image_t1);
    case FlowBaseline::kDis:
      return DenseFlow(DenseFlowMethod::kDisMedium, image_t, image_t1);
    case FlowBaseline::kFarneback:
      return DenseFlow(DenseFlowMethod::kFarneback, image_t, image_t1);
  }
  ThrowError("BaselineFlow: unknown FlowBaseline");
}

}  // namespace u4d::baselines
