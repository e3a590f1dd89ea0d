#include "u4d/joint/motion_regularisation.h"

#include <algorithm>

#include "u4d/mrf/expansion.h"

namespace u4d {

double MotionRegTerm::RhoDecreaseBound(const Eigen::Vector2f& from,
                                       const Eigen::Vector2f& to) const {
  const double distance = (from - to).norm() / truncation_px;
  return quadratic ? mrf::TruncatedQuadraticDecreaseBound(distance)
                   : mrf::TruncatedLinearDecreaseBound(distance);
}

std::vector<float> WindowSpread(const LabelCostVolume& volume, const cv::Mat& labels) {
  const int w = volume.width, h = volume.height;
  std::vector<float> spread(static_cast<size_t>(w) * h, 0.f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double sum = 0, lo = 1e30;
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const double c = volume.At(qy * w + qx, labels.at<uint16_t>(qy, qx));
          sum += c;
          lo = std::min(lo, c);
          ++count;
        }
      spread[static_cast<size_t>(y) * w + x] = static_cast<float>(sum / count - lo);
    }
  return spread;
}

std::vector<float> MotionRegPixelWeights(const LabelCostVolume& semantic,
                                         const LabelCostVolume& appearance, const cv::Mat& labels,
                                         const JointWeights& weights) {
  const std::vector<float> spread_l = WindowSpread(semantic, labels);
  const std::vector<float> spread_a = WindowSpread(appearance, labels);
  std::vector<float> pixel_weights(spread_l.size());
  for (size_t p = 0; p < pixel_weights.size(); ++p)
    pixel_weights[p] =
        static_cast<float>(weights.motion_reg * (1.0 + weights.motion_reg_label * spread_l[p] +
                                                 weights.motion_reg_app * spread_a[p]));
  return pixel_weights;
}

}  // namespace u4d
