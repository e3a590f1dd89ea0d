#include "u4d/eval/track_metrics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include <opencv2/core.hpp>

#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

// Bilinear flow at p (clamped to the image); NaN stays NaN.
cv::Vec2f SampleFlow(const cv::Mat& flow, const Eigen::Vector2d& p) {
  const double x = std::clamp(p.x(), 0.0, flow.cols - 1.0),
               y = std::clamp(p.y(), 0.0, flow.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), flow.cols - 2 < 0 ? 0 : flow.cols - 2);
  const int y0 = std::min(static_cast<int>(y), flow.rows - 2 < 0 ? 0 : flow.rows - 2);
  const int x1 = std::min(x0 + 1, flow.cols - 1), y1 = std::min(y0 + 1, flow.rows - 1);
  const float ax = static_cast<float>(x - x0), ay = static_cast<float>(y - y0);
  return (1 - ay) * ((1 - ax) * flow.at<cv::Vec2f>(y0, x0) + ax * flow.at<cv::Vec2f>(y0, x1)) +
         ay * ((1 - ax) * flow.at<cv::Vec2f>(y1, x0) + ax * flow.at<cv::Vec2f>(y1, x1));
}

}  // namespace

TrackPrecision EvaluateTracksWithGtFlow(const Capture& capture,
                                        const std::vector<TemporalTrack>& tracks,
                                        double max_error_px) {
  U4D_CHECK(max_error_px > 0, "EvaluateTracksWithGtFlow: max_error_px must be > 0, got {}",
            max_error_px);
  // GT flow and validity, loaded lazily per (view, frame).
  std::map<std::pair<int, int>, std::pair<cv::Mat, cv::Mat>> cache;
  auto flow_at = [&](int view, int frame) -> const std::pair<cv::Mat, cv::Mat>& {
    auto it = cache.find({view, frame});
    if (it != cache.end()) return it->second;
    const std::string& name = capture.views[view].name;
    cv::Mat flow = ReadFlo(capture.root / layout::GtFlow(name, frame));
    cv::Mat valid = ReadMaskImage(capture.root / layout::GtFlowValid(name, frame));
    return cache[{view, frame}] = {flow, valid};
  };
  TrackPrecision result;
  for (const TemporalTrack& t : tracks) {
    if (t.from_joint) continue;
    U4D_CHECK(t.view >= 0 && t.view < capture.NumViews(),
              "EvaluateTracksWithGtFlow: track view {} out of range", t.view);
    for (size_t q = 1; q < t.points.size(); ++q) {
      const auto& [t1, p1] = t.points[q - 1];
      const auto& [t2, p2] = t.points[q];
      Eigen::Vector2d p = p1;
      bool ok = true;
      for (int f = t1; f < t2 && ok; ++f) {
        const auto& [flow, valid] = flow_at(t.view, f);
        const int x = static_cast<int>(std::lround(p.x())),
                  y = static_cast<int>(std::lround(p.y()));
        if (x < 0 || y < 0 || x >= flow.cols || y >= flow.rows || !valid.at<uint8_t>(y, x)) {
          ok = false;
          break;
        }
        const cv::Vec2f d = SampleFlow(flow, p);
        if (!std::isfinite(d[0]) || !std::isfinite(d[1]) || std::abs(d[0]) > 1e9) {
          ok = false;
          break;
        }
        p += Eigen::Vector2d(d[0], d[1]);
      }
      if (!ok) continue;
      const bool correct = (p - p2).norm() <= max_error_px;
      ++result.evaluated;
      result.correct += correct;
      if (t2 == t1 + 1) {
        ++result.consecutive_evaluated;
        result.consecutive_correct += correct;
      }
    }
  }
  return result;
}

}  // namespace u4d
