#include "u4d/eval/dense_metrics.h"

#include <cmath>
#include <limits>

#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double Ratio(double num, int64_t den) { return den > 0 ? num / static_cast<double>(den) : kNaN; }

nlohmann::json Num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

void CheckSameSize(const cv::Mat& a, const cv::Mat& b, const char* what,
                   const std::string& context) {
  U4D_CHECK(a.size() == b.size(), "{}: {} is {}x{} but the ground truth is {}x{}", context, what,
            a.cols, a.rows, b.cols, b.rows);
}

void CheckMask(const cv::Mat& mask, const cv::Mat& gt, const std::string& context) {
  if (mask.empty()) return;
  U4D_CHECK(mask.type() == CV_8UC1, "{}: the evaluation mask must be CV_8UC1", context);
  CheckSameSize(mask, gt, "the evaluation mask", context);
}

void CheckDepthValues(const cv::Mat& depth, const char* which, const std::string& context) {
  for (int y = 0; y < depth.rows; ++y) {
    const float* d = depth.ptr<float>(y);
    for (int x = 0; x < depth.cols; ++x)
      U4D_CHECK(std::isfinite(d[x]) && d[x] >= 0,
                "{}: {} depth at pixel ({}, {}) is {}; expected a finite value >= 0 (0 = unknown)",
                context, which, x, y, d[x]);
  }
}

}  // namespace

bool FlowValid(float u, float v) {
  return std::isfinite(u) && std::isfinite(v) && std::abs(u) < 1e9f && std::abs(v) < 1e9f;
}

void DepthMetrics::Add(const DepthMetrics& o) {
  gt_valid += o.gt_valid;
  evaluated += o.evaluated;
  sum_abs_rel += o.sum_abs_rel;
  sum_sq += o.sum_sq;
  within_1pct += o.within_1pct;
  within_5pct += o.within_5pct;
}
double DepthMetrics::AbsRel() const { return Ratio(sum_abs_rel, evaluated); }
double DepthMetrics::Rmse() const { return std::sqrt(Ratio(sum_sq, evaluated)); }
double DepthMetrics::Delta1Pct() const { return Ratio(within_1pct, evaluated); }
double DepthMetrics::Delta5Pct() const { return Ratio(within_5pct, evaluated); }
double DepthMetrics::Completeness() const { return Ratio(evaluated, gt_valid); }
nlohmann::json DepthMetrics::ToJson() const {
  return {{"abs_rel", Num(AbsRel())},
          {"rmse_m", Num(Rmse())},
          {"delta_1pct", Num(Delta1Pct())},
          {"delta_5pct", Num(Delta5Pct())},
          {"completeness", Num(Completeness())},
          {"gt_valid_pixels", gt_valid},
          {"evaluated_pixels", evaluated}};
}

DepthMetrics EvaluateDepth(const cv::Mat& pred, const cv::Mat& gt, const cv::Mat& mask,
                           const std::string& context) {
  U4D_CHECK(gt.type() == CV_32FC1, "{}: ground-truth depth must be single-channel float", context);
  CheckDepthValues(gt, "ground-truth", context);
  if (!pred.empty()) {
    U4D_CHECK(pred.type() == CV_32FC1, "{}: predicted depth must be single-channel float", context);
    CheckSameSize(pred, gt, "the predicted depth", context);
    CheckDepthValues(pred, "predicted", context);
  }
  CheckMask(mask, gt, context);
  DepthMetrics m;
  for (int y = 0; y < gt.rows; ++y) {
    const float* g = gt.ptr<float>(y);
    const float* p = pred.empty() ? nullptr : pred.ptr<float>(y);
    const uint8_t* k = mask.empty() ? nullptr : mask.ptr<uint8_t>(y);
    for (int x = 0; x < gt.cols; ++x) {
      if ((k && !k[x]) || !(g[x] > 0)) continue;
      ++m.gt_valid;
      if (!p || !(p[x] > 0)) continue;
      ++m.evaluated;
      const double diff = static_cast<double>(p[x]) - static_cast<double>(g[x]);
      const double rel = std::abs(diff) / g[x];
      m.sum_abs_rel += rel;
      m.sum_sq += diff * diff;
      if (rel <= 0.01) ++m.within_1pct;
      if (rel <= 0.05) ++m.within_5pct;
    }
  }
  return m;
}

void FlowMetrics::Add(const FlowMetrics& o) {
  gt_valid += o.gt_valid;
  evaluated += o.evaluated;
  sum_epe += o.sum_epe;
  within_1px += o.within_1px;
  within_3px += o.within_3px;
  beyond_10px += o.beyond_10px;
  sum_along += o.sum_along;
  sum_true_length += o.sum_true_length;
}
double FlowMetrics::Epe() const { return Ratio(sum_epe, evaluated); }
double FlowMetrics::Within1Px() const { return Ratio(within_1px, evaluated); }
double FlowMetrics::Within3Px() const { return Ratio(within_3px, evaluated); }
double FlowMetrics::Beyond10Px() const { return Ratio(beyond_10px, evaluated); }
double FlowMetrics::MotionScale() const {
  return sum_true_length > 0 ? sum_along / sum_true_length : kNaN;
}
double FlowMetrics::Completeness() const { return Ratio(evaluated, gt_valid); }
nlohmann::json FlowMetrics::ToJson() const {
  return {{"epe_px", Num(Epe())},
          {"within_1px", Num(Within1Px())},
          {"within_3px", Num(Within3Px())},
          {"beyond_10px", Num(Beyond10Px())},
          {"motion_scale", Num(MotionScale())},
          {"completeness", Num(Completeness())},
          {"gt_valid_pixels", gt_valid},
          {"evaluated_pixels", evaluated}};
}

FlowMetrics EvaluateFlow(const cv::Mat& pred, const cv::Mat& gt, const cv::Mat& gt_valid,
                         const cv::Mat& mask, const std::string& context) {
  U4D_CHECK(gt.type() == CV_32FC2, "{}: ground-truth flow must be two-channel float", context);
  if (!pred.empty()) {
    U4D_CHECK(pred.type() == CV_32FC2, "{}: predicted flow must be two-channel float", context);
    CheckSameSize(pred, gt, "the predicted flow", context);
  }
  if (!gt_valid.empty()) {
    U4D_CHECK(gt_valid.type() == CV_8UC1, "{}: the flow validity mask must be CV_8UC1", context);
    CheckSameSize(gt_valid, gt, "the flow validity mask", context);
  }
  CheckMask(mask, gt, context);
  FlowMetrics m;
  for (int y = 0; y < gt.rows; ++y) {
    const cv::Vec2f* g = gt.ptr<cv::Vec2f>(y);
    const cv::Vec2f* p = pred.empty() ? nullptr : pred.ptr<cv::Vec2f>(y);
    const uint8_t* v = gt_valid.empty() ? nullptr : gt_valid.ptr<uint8_t>(y);
    const uint8_t* k = mask.empty() ? nullptr : mask.ptr<uint8_t>(y);
    for (int x = 0; x < gt.cols; ++x) {
      if (k && !k[x]) continue;
      if (v ? !v[x] : !FlowValid(g[x][0], g[x][1])) continue;
      U4D_CHECK(FlowValid(g[x][0], g[x][1]),
                "{}: ground-truth flow at pixel ({}, {}) is marked valid but is not finite",
                context, x, y);
      ++m.gt_valid;
      if (!p || !FlowValid(p[x][0], p[x][1])) continue;
      ++m.evaluated;
      const double du = static_cast<double>(p[x][0]) - g[x][0];
      const double dv = static_cast<double>(p[x][1]) - g[x][1];
      const double epe = std::sqrt(du * du + dv * dv);
      m.sum_epe += epe;
      if (epe < 1.0) ++m.within_1px;
      if (epe < 3.0) ++m.within_3px;
      if (epe > 10.0) ++m.beyond_10px;
      const double length = std::hypot(static_cast<double>(g[x][0]), g[x][1]);
      if (length >= FlowMetrics::kMovingPx) {
        m.sum_along +=
            (p[x][0] * static_cast<double>(g[x][0]) + p[x][1] * static_cast<double>(g[x][1])) /
            length;
        m.sum_true_length += length;
      }
    }
  }
  return m;
}

}  // namespace u4d::eval
