#include "u4d/baselines/dense_flow.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/optflow.hpp>
#include <opencv2/video/tracking.hpp>

#include "u4d/util/check.h"

namespace u4d::baselines {
namespace {

cv::Mat Grey(const cv::Mat& image, const char* what) {
  U4D_CHECK(!image.empty(), "DenseFlow: {} is empty", what);
  U4D_CHECK(image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3),
            "DenseFlow: {} must be 8-bit grey or BGR, got type {}", what, image.type());
  if (image.channels() == 1) return image;
  cv::Mat g;
  cv::cvtColor(image, g, cv::COLOR_BGR2GRAY);
  return g;
}

}  // namespace

cv::Mat DenseFlow(DenseFlowMethod method, const cv::Mat& image_t, const cv::Mat& image_t1) {
  const cv::Mat a = Grey(image_t, "image_t"), b = Grey(image_t1, "image_t1");
  U4D_CHECK(a.size() == b.size(), "DenseFlow: image_t is {}x{} but image_t1 is {}x{}", a.cols,
            a.rows, b.cols, b.rows);
  cv::Mat flow;
  switch (method) {
    case DenseFlowMethod::kDeepFlow:
      cv::optflow::createOptFlow_DeepFlow()->calc(a, b, flow);
      break;
    case DenseFlowMethod::kDisMedium:
      cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM)->calc(a, b, flow);
      break;
    case DenseFlowMethod::kDisFine: {
      const cv::Ptr<cv::DISOpticalFlow> dis =
          cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
      dis->setFinestScale(0);
      dis->setVariationalRefinementIterations(10);
      dis->calc(a, b, flow);
      break;
    }
    case DenseFlowMethod::kFarneback:
      cv::calcOpticalFlowFarneback(a, b, flow, 0.5, 3, 15, 3, 5, 1.2, 0);
      break;
  }
  U4D_ASSERT(flow.type() == CV_32FC2 && flow.size() == a.size());
  return flow;
}

}  // namespace u4d::baselines
