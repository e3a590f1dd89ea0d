#include "u4d/features/object_appearance.h"

#include <algorithm>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {
namespace {

struct Band {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double count = 0;
};

struct ViewBands {
  int top = INT32_MAX, bottom = -1;
  Band upper, lower;
};

// OpenCV's 8-bit L*a*b* (L scaled to 0..255, a and b offset by 128) in
// CIE units.
Eigen::Vector3d CieLab(const cv::Vec3b& lab8) {
  return {lab8[0] * 100.0 / 255.0, lab8[1] - 128.0, lab8[2] - 128.0};
}

void CheckInputs(const std::vector<cv::Mat>& images, const std::vector<cv::Mat>& ids) {
  U4D_CHECK(images.size() == ids.size(), "ObjectAppearances: {} images and {} id maps",
            images.size(), ids.size());
  for (size_t v = 0; v < ids.size(); ++v) {
    if (ids[v].empty()) continue;
    U4D_CHECK(ids[v].type() == CV_16UC1, "ObjectAppearances: view {}: the id map is not CV_16UC1",
              v);
    U4D_CHECK(images[v].type() == CV_8UC3 && images[v].size() == ids[v].size(),
              "ObjectAppearances: view {}: the image is not CV_8UC3 of its id map's size {}x{}", v,
              ids[v].cols, ids[v].rows);
  }
}

// The bands of every object in one view.
std::map<int, ViewBands> BandsOfView(const cv::Mat& image, const cv::Mat& ids) {
  std::map<int, ViewBands> bands;
  for (int y = 0; y < ids.rows; ++y)
    for (int x = 0; x < ids.cols; ++x)
      if (const int id = ids.at<uint16_t>(y, x)) {
        ViewBands& b = bands[id];
        b.top = std::min(b.top, y);
        b.bottom = std::max(b.bottom, y);
      }
  if (bands.empty()) return bands;
  cv::Mat lab;
  cv::cvtColor(image, lab, cv::COLOR_BGR2Lab);
  for (int y = 0; y < ids.rows; ++y)
    for (int x = 0; x < ids.cols; ++x)
      if (const int id = ids.at<uint16_t>(y, x)) {
        ViewBands& b = bands[id];
        Band& band = 2 * y <= b.top + b.bottom ? b.upper : b.lower;
        band.sum += CieLab(lab.at<cv::Vec3b>(y, x));
        band.count += 1;
      }
  return bands;
}

}  // namespace

std::map<int, ObjectAppearance> ObjectAppearances(const std::vector<cv::Mat>& images,
                                                  const std::vector<cv::Mat>& ids) {
  CheckInputs(images, ids);
  std::map<int, Band> upper, lower;
  for (size_t v = 0; v < ids.size(); ++v) {
    if (ids[v].empty()) continue;
    for (const auto& [id, b] : BandsOfView(images[v], ids[v])) {
      upper[id].sum += b.upper.sum;
      upper[id].count += b.upper.count;
      lower[id].sum += b.lower.sum;
      lower[id].count += b.lower.count;
    }
  }
  std::map<int, ObjectAppearance> out;
  for (const auto& [id, u] : upper) {
    const Band& l = lower[id];
    ObjectAppearance& a = out[id];
    a.upper = u.sum / std::max(1.0, u.count);
    a.lower = l.count > 0 ? Eigen::Vector3d(l.sum / l.count) : a.upper;
    a.pixels = u.count + l.count;
  }
  return out;
}

double AppearanceDistance(const ObjectAppearance& a, const ObjectAppearance& b) {
  return 0.5 * ((a.upper - b.upper).norm() + (a.lower - b.lower).norm());
}

ObjectAppearance MeanAppearance(const ObjectAppearance& a, const ObjectAppearance& b) {
  const double n = a.pixels + b.pixels;
  if (n <= 0) return a;
  ObjectAppearance m;
  m.upper = (a.pixels * a.upper + b.pixels * b.upper) / n;
  m.lower = (a.pixels * a.lower + b.pixels * b.lower) / n;
  m.pixels = n;
  return m;
}

}  // namespace u4d
