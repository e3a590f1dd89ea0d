#include "u4d/pipeline/camera_flow.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "u4d/baselines/dense_flow.h"
#include "u4d/util/check.h"

namespace u4d {

namespace {

// |I_t1(p + f(p)) − I_t(p)| summed over the channels, then over the window,
// for the pixels of `roi` (`flow` holds the roi's flow; `t_roi` is I_t in
// the roi and `t1` the whole I_t1, so a match leaving the roi is still
// measured; both CV_32FC3).
cv::Mat WindowError(const cv::Mat& t_roi, const cv::Mat& t1, const cv::Rect& roi,
                    const cv::Mat& flow, int window_px) {
  cv::Mat map(flow.size(), CV_32FC2);
  for (int y = 0; y < flow.rows; ++y)
    for (int x = 0; x < flow.cols; ++x) {
      const cv::Vec2f f = flow.at<cv::Vec2f>(y, x);
      map.at<cv::Vec2f>(y, x) = cv::Vec2f(roi.x + x + f[0], roi.y + y + f[1]);
    }
  cv::Mat warped, diff, summed, window;
  cv::remap(t1, warped, map, cv::Mat(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  cv::absdiff(warped, t_roi, diff);
  cv::transform(diff, summed, cv::Matx13f(1, 1, 1));
  cv::boxFilter(summed, window, CV_32F, cv::Size(window_px, window_px));
  return window;
}

// The objects' bounding box grown by `margin` on every side, inside the image.
cv::Rect ObjectBox(const cv::Mat& labels, int margin) {
  const cv::Rect box = cv::boundingRect(labels > 0);
  const cv::Rect grown(box.x - margin, box.y - margin, box.width + 2 * margin,
                       box.height + 2 * margin);
  return grown & cv::Rect(0, 0, labels.cols, labels.rows);
}

// OpenCV's DIS needs an image side of at least 12 pixels; the crop's
// margin is at least this, and a smaller image is not matched.
constexpr int kMinMatchSide = 16;

}  // namespace

void RefineFlowAtCameraSize(const cv::Mat& labels, const cv::Mat& image_t, const cv::Mat& image_t1,
                            int window_px, cv::Mat* flow) {
  U4D_CHECK(window_px > 0 && window_px % 2 == 1,
            "RefineFlowAtCameraSize: the window must be odd and positive, got {}", window_px);
  U4D_CHECK(labels.type() == CV_16U && image_t.type() == CV_8UC3 && image_t1.type() == CV_8UC3 &&
                flow->type() == CV_32FC2,
            "RefineFlowAtCameraSize: expected CV_16U labels, BGR images and a CV_32FC2 flow");
  U4D_CHECK(labels.size() == image_t.size() && labels.size() == image_t1.size() &&
                labels.size() == flow->size(),
            "RefineFlowAtCameraSize: the labels ({}x{}), images and flow must have one size",
            labels.cols, labels.rows);
  if (cv::countNonZero(labels) == 0) return;
  if (labels.cols < kMinMatchSide && labels.rows < kMinMatchSide) return;
  // The dense match is computed around the objects only: a margin of a
  // tenth of the width (at least the window) keeps the match's own border
  // effects and the objects' motion inside the crop.
  const cv::Rect roi = ObjectBox(labels, std::max({window_px, labels.cols / 10, kMinMatchSide}));
  const cv::Mat dense =
      baselines::DenseFlow(baselines::DenseFlowMethod::kDisFine, image_t(roi), image_t1(roi));
  cv::Mat t_roi, t1;
  image_t(roi).convertTo(t_roi, CV_32F);
  image_t1.convertTo(t1, CV_32F);
  cv::Mat solved = (*flow)(roi);
  const cv::Mat take = (WindowError(t_roi, t1, roi, dense, window_px) <
                        WindowError(t_roi, t1, roi, solved, window_px)) &
                       (labels(roi) > 0);
  dense.copyTo(solved, take);
}

}  // namespace u4d
