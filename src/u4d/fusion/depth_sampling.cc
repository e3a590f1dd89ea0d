#include "u4d/fusion/depth_sampling.h"

#include <algorithm>
#include <cmath>

#include "u4d/util/check.h"

namespace u4d::fusion_internal {

namespace {
std::string TypeName(int type) {
  switch (type) {
    case CV_32FC1:
      return "CV_32FC1";
    case CV_32FC2:
      return "CV_32FC2";
    case CV_16UC1:
      return "CV_16UC1";
    case CV_8UC3:
      return "CV_8UC3";
    default:
      return "type " + std::to_string(type);
  }
}
}  // namespace

void CheckMap(const cv::Mat& m, int type, int width, int height, const std::string& what) {
  U4D_CHECK(!m.empty(), "{}: expected a {} map of {}x{}, found an empty image", what,
            TypeName(type), width, height);
  U4D_CHECK(m.type() == type, "{}: expected {}, found {}", what, TypeName(type),
            TypeName(m.type()));
  U4D_CHECK(m.cols == width && m.rows == height,
            "{}: expected size {}x{} (the camera's), found {}x{}", what, width, height, m.cols,
            m.rows);
}

int SampleId(const cv::Mat& ids, const Eigen::Vector2d& pixel) {
  const int x = static_cast<int>(std::lround(pixel.x()));
  const int y = static_cast<int>(std::lround(pixel.y()));
  if (!std::isfinite(pixel.x()) || !std::isfinite(pixel.y())) return -1;
  if (ids.empty()) return 0;
  if (x < 0 || y < 0 || x >= ids.cols || y >= ids.rows) return -1;
  return ids.at<uint16_t>(y, x);
}

double SampleObjectDepth(const cv::Mat& depth, const cv::Mat& ids, int object_id,
                         const Eigen::Vector2d& pixel, double max_depth_jump) {
  if (!std::isfinite(pixel.x()) || !std::isfinite(pixel.y())) return 0;
  auto ok = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= depth.cols || y >= depth.rows) return false;
    if (!ids.empty() && ids.at<uint16_t>(y, x) != object_id) return false;
    const float d = depth.at<float>(y, x);
    return d > 0 && std::isfinite(d);
  };
  const int x0 = static_cast<int>(std::floor(pixel.x()));
  const int y0 = static_cast<int>(std::floor(pixel.y()));
  if (ok(x0, y0) && ok(x0 + 1, y0) && ok(x0, y0 + 1) && ok(x0 + 1, y0 + 1)) {
    const double d00 = depth.at<float>(y0, x0), d10 = depth.at<float>(y0, x0 + 1);
    const double d01 = depth.at<float>(y0 + 1, x0), d11 = depth.at<float>(y0 + 1, x0 + 1);
    const double lo = std::min({d00, d10, d01, d11}), hi = std::max({d00, d10, d01, d11});
    if (hi - lo < max_depth_jump) {
      const double ax = pixel.x() - x0, ay = pixel.y() - y0;
      return (1 - ay) * ((1 - ax) * d00 + ax * d10) + ay * ((1 - ax) * d01 + ax * d11);
    }
  }
  const int xn = static_cast<int>(std::lround(pixel.x()));
  const int yn = static_cast<int>(std::lround(pixel.y()));
  return ok(xn, yn) ? depth.at<float>(yn, xn) : 0.0;
}

Eigen::Vector2d SampleObjectFlow(const cv::Mat& flow, const cv::Mat& ids, int object_id,
                                 const Eigen::Vector2d& pixel) {
  const int x0 = static_cast<int>(std::floor(pixel.x()));
  const int y0 = static_cast<int>(std::floor(pixel.y()));
  auto ok = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < flow.cols && y < flow.rows &&
           (ids.empty() || ids.at<uint16_t>(y, x) == object_id);
  };
  auto f = [&](int x, int y) {
    const cv::Vec2f& v = flow.at<cv::Vec2f>(y, x);
    return Eigen::Vector2d(v[0], v[1]);
  };
  if (ok(x0, y0) && ok(x0 + 1, y0) && ok(x0, y0 + 1) && ok(x0 + 1, y0 + 1)) {
    const double ax = pixel.x() - x0, ay = pixel.y() - y0;
    return (1 - ay) * ((1 - ax) * f(x0, y0) + ax * f(x0 + 1, y0)) +
           ay * ((1 - ax) * f(x0, y0 + 1) + ax * f(x0 + 1, y0 + 1));
  }
  const int xn = std::clamp(static_cast<int>(std::lround(pixel.x())), 0, flow.cols - 1);
  const int yn = std::clamp(static_cast<int>(std::lround(pixel.y())), 0, flow.rows - 1);
  return f(xn, yn);
}

}  // namespace u4d::fusion_internal
