#include "u4d/io/visualize.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {
namespace {

// The Middlebury colour wheel: 55 hues in six ramps (red-yellow 15,
// yellow-green 6, green-cyan 4, cyan-blue 11, blue-magenta 13, magenta-red 6).
std::vector<std::array<float, 3>> MakeColorWheel() {
  const int ry = 15, yg = 6, gc = 4, cb = 11, bm = 13, mr = 6;
  std::vector<std::array<float, 3>> w;
  w.reserve(ry + yg + gc + cb + bm + mr);
  for (int i = 0; i < ry; ++i) w.push_back({255.f, 255.f * i / ry, 0.f});
  for (int i = 0; i < yg; ++i) w.push_back({255.f - 255.f * i / yg, 255.f, 0.f});
  for (int i = 0; i < gc; ++i) w.push_back({0.f, 255.f, 255.f * i / gc});
  for (int i = 0; i < cb; ++i) w.push_back({0.f, 255.f - 255.f * i / cb, 255.f});
  for (int i = 0; i < bm; ++i) w.push_back({255.f * i / bm, 0.f, 255.f});
  for (int i = 0; i < mr; ++i) w.push_back({255.f, 0.f, 255.f - 255.f * i / mr});
  return w;
}

const std::vector<std::array<float, 3>>& ColorWheel() {
  static const std::vector<std::array<float, 3>> wheel = MakeColorWheel();
  return wheel;
}

}  // namespace

cv::Vec3b InstanceColor(int id) {
  static const std::array<cv::Vec3b, 10> kTableau = {
      cv::Vec3b(31, 119, 180),  cv::Vec3b(255, 127, 14),  cv::Vec3b(44, 160, 44),
      cv::Vec3b(214, 39, 40),   cv::Vec3b(148, 103, 189), cv::Vec3b(140, 86, 75),
      cv::Vec3b(227, 119, 194), cv::Vec3b(127, 127, 127), cv::Vec3b(188, 189, 34),
      cv::Vec3b(23, 190, 207)};
  if (id <= 0) return {0, 0, 0};
  if (id <= static_cast<int>(kTableau.size())) return kTableau[id - 1];
  // Golden-angle hues (OpenCV 8-bit HSV: hue in [0, 180)).
  const double hue = std::fmod(id * 137.50776405, 360.0) / 2.0;
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, 200, 230)), rgb;
  cv::cvtColor(hsv, rgb, cv::COLOR_HSV2RGB);
  return rgb.at<cv::Vec3b>(0, 0);
}

cv::Mat ColorizeInstances(const cv::Mat& ids16, const std::vector<cv::Vec3b>& palette_or_empty) {
  U4D_CHECK(!ids16.empty() && ids16.channels() == 1 &&
                (ids16.depth() == CV_16U || ids16.depth() == CV_8U),
            "ColorizeInstances: expected a non-empty 16-bit or 8-bit id image, found type {} "
            "size {}x{}",
            ids16.type(), ids16.cols, ids16.rows);
  cv::Mat ids;
  ids16.convertTo(ids, CV_32S);
  cv::Mat out(ids.size(), CV_8UC3);
  for (int y = 0; y < ids.rows; ++y)
    for (int x = 0; x < ids.cols; ++x) {
      const int id = ids.at<int>(y, x);
      cv::Vec3b rgb = (id >= 1 && id <= static_cast<int>(palette_or_empty.size()))
                          ? palette_or_empty[id - 1]
                          : InstanceColor(id);
      out.at<cv::Vec3b>(y, x) = {rgb[2], rgb[1], rgb[0]};
    }
  return out;
}

cv::Mat ColorizeDepth(const cv::Mat& z32, double near, double far) {
  U4D_CHECK(!z32.empty() && z32.type() == CV_32F,
            "ColorizeDepth: expected a non-empty CV_32F depth map, found type {}", z32.type());
  U4D_CHECK(near >= 0 && far > near && std::isfinite(far),
            "ColorizeDepth: expected 0 <= near < far, found near {} far {}", near, far);
  cv::Mat index(z32.size(), CV_8U), known(z32.size(), CV_8U);
  for (int y = 0; y < z32.rows; ++y)
    for (int x = 0; x < z32.cols; ++x) {
      const float z = z32.at<float>(y, x);
      const bool ok = std::isfinite(z) && z > 0;
      known.at<uint8_t>(y, x) = ok ? 255 : 0;
      const double t = ok ? std::clamp((z - near) / (far - near), 0.0, 1.0) : 0.0;
      index.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(255.0 * (1.0 - t));  // near = top
    }
  cv::Mat out;
  cv::applyColorMap(index, out, cv::COLORMAP_TURBO);
  out.setTo(cv::Scalar::all(0), known == 0);
  return out;
}

cv::Vec3b FlowColor(float u, float v, double max_magnitude) {
  U4D_CHECK(max_magnitude > 0 && std::isfinite(max_magnitude),
            "ColorizeFlow: expected max_magnitude > 0, found {}", max_magnitude);
  if (!std::isfinite(u) || !std::isfinite(v) || std::abs(u) > 1e9f || std::abs(v) > 1e9f)
    return {0, 0, 0};
  const auto& wheel = ColorWheel();
  const int ncols = static_cast<int>(wheel.size());
  const double fu = u / max_magnitude, fv = v / max_magnitude;
  const double rad = std::sqrt(fu * fu + fv * fv);
  const double a = std::atan2(-fv, -fu) / M_PI;  // in [-1, 1]
  const double fk = (a + 1.0) / 2.0 * (ncols - 1);
  const int k0 = static_cast<int>(std::floor(fk));
  const int k1 = (k0 + 1) % ncols;
  const double f = fk - k0;
  cv::Vec3b rgb;
  for (int c = 0; c < 3; ++c) {
    double col = ((1 - f) * wheel[k0][c] + f * wheel[k1][c]) / 255.0;
    if (rad <= 1)
      col = 1 - rad * (1 - col);
    else
      col *= 0.75;
    rgb[c] = cv::saturate_cast<uint8_t>(std::floor(255.0 * col));
  }
  return rgb;
}

cv::Mat ColorizeFlow(const cv::Mat& flow32fc2, double max_magnitude) {
  U4D_CHECK(!flow32fc2.empty() && flow32fc2.type() == CV_32FC2,
            "ColorizeFlow: expected a non-empty CV_32FC2 flow, found type {}", flow32fc2.type());
  cv::Mat out(flow32fc2.size(), CV_8UC3);
  for (int y = 0; y < flow32fc2.rows; ++y)
    for (int x = 0; x < flow32fc2.cols; ++x) {
      const cv::Vec2f& f = flow32fc2.at<cv::Vec2f>(y, x);
      const cv::Vec3b rgb = FlowColor(f[0], f[1], max_magnitude);
      out.at<cv::Vec3b>(y, x) = {rgb[2], rgb[1], rgb[0]};
    }
  return out;
}

cv::Mat DownscaleToWidth(const cv::Mat& image, int width, bool nearest) {
  if (width <= 0 || image.cols <= width) return image;
  const int height = std::max(
      1, static_cast<int>(std::lround(image.rows * static_cast<double>(width) / image.cols)));
  cv::Mat out;
  cv::resize(image, out, {width, height}, 0, 0, nearest ? cv::INTER_NEAREST : cv::INTER_AREA);
  return out;
}

std::pair<double, double> VisibleDepthRange(const cv::Mat& z32) {
  U4D_CHECK(z32.type() == CV_32FC1, "VisibleDepthRange: expected a CV_32FC1 depth map");
  std::vector<float> v;
  for (int y = 0; y < z32.rows; ++y)
    for (int x = 0; x < z32.cols; ++x) {
      const float z = z32.at<float>(y, x);
      if (std::isfinite(z) && z > 0) v.push_back(z);
    }
  if (v.size() < 2) return {0.0, 10.0};
  std::sort(v.begin(), v.end());
  const double lo = v[v.size() * 2 / 100], hi = v[v.size() * 98 / 100];
  const double pad = 0.05 * std::max(hi - lo, 0.1);
  return {std::max(0.0, lo - pad), hi + pad};
}

double MaxFlowMagnitude(const cv::Mat& flow32fc2, const cv::Mat& valid) {
  U4D_CHECK(flow32fc2.type() == CV_32FC2, "MaxFlowMagnitude: expected a CV_32FC2 flow map");
  double m = 1.0;
  for (int y = 0; y < flow32fc2.rows; ++y)
    for (int x = 0; x < flow32fc2.cols; ++x) {
      if (!valid.empty() && valid.at<uint8_t>(y, x) == 0) continue;
      const cv::Vec2f& f = flow32fc2.at<cv::Vec2f>(y, x);
      if (std::isfinite(f[0]) && std::isfinite(f[1]) && std::abs(f[0]) < 1e9f &&
          std::abs(f[1]) < 1e9f)
        m = std::max(m, static_cast<double>(std::hypot(f[0], f[1])));
    }
  return m;
}

}  // namespace u4d
