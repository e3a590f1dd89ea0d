#include "u4d/eval/silhouette.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <open3d/geometry/TriangleMesh.h>
#include <opencv2/imgproc.hpp>

#include "u4d/eval/dense_metrics.h"
#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Twice the signed area of (a, b, p).
double Edge(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

}  // namespace

Rasterization RasterizeMeshes(const std::vector<const open3d::geometry::TriangleMesh*>& meshes,
                              const std::vector<int>& labels, const Camera& camera) {
  camera.Check("RasterizeMeshes");
  U4D_CHECK(meshes.size() == labels.size(), "RasterizeMeshes: {} meshes but {} labels",
            meshes.size(), labels.size());
  const int w = camera.width, h = camera.height;
  Rasterization out{cv::Mat::zeros(h, w, CV_16UC1), cv::Mat::zeros(h, w, CV_32FC1)};
  cv::Mat zbuf(h, w, CV_64FC1, cv::Scalar(std::numeric_limits<double>::infinity()));
  for (size_t m = 0; m < meshes.size(); ++m) {
    U4D_CHECK(meshes[m] != nullptr, "RasterizeMeshes: mesh {} is null", m);
    U4D_CHECK(labels[m] >= 1 && labels[m] <= 65535, "RasterizeMeshes: label {} out of 1..65535",
              labels[m]);
    const auto& verts = meshes[m]->vertices_;
    std::vector<Eigen::Vector2d> pix(verts.size());
    std::vector<double> z(verts.size());
    for (size_t i = 0; i < verts.size(); ++i) {
      z[i] = camera.Depth(verts[i]);
      pix[i] = z[i] > 1e-6 ? camera.Project(verts[i]) : Eigen::Vector2d::Constant(kNaN);
    }
    for (const Eigen::Vector3i& t : meshes[m]->triangles_) {
      for (int k = 0; k < 3; ++k)
        U4D_CHECK(t[k] >= 0 && t[k] < static_cast<int>(verts.size()),
                  "RasterizeMeshes: mesh {} names vertex {} of {}", m, t[k], verts.size());
      const Eigen::Vector2d &a = pix[t[0]], &b = pix[t[1]], &c = pix[t[2]];
      if (!a.allFinite() || !b.allFinite() || !c.allFinite()) continue;
      const double area = Edge(a, b, c);
      if (area == 0) continue;
      const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}))));
      const int x1 = std::min(w - 1, static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))));
      const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}))));
      const int y1 = std::min(h - 1, static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))));
      const double iz0 = 1 / z[t[0]], iz1 = 1 / z[t[1]], iz2 = 1 / z[t[2]];
      for (int y = y0; y <= y1; ++y) {
        uint16_t* lab = out.labels.ptr<uint16_t>(y);
        float* dep = out.depth.ptr<float>(y);
        double* zb = zbuf.ptr<double>(y);
        for (int x = x0; x <= x1; ++x) {
          const Eigen::Vector2d p(x, y);
          // Barycentric weights; all >= 0 inside whatever the winding.
          const double w0 = Edge(b, c, p) / area, w1 = Edge(c, a, p) / area,
                       w2 = Edge(a, b, p) / area;
          if (w0 < 0 || w1 < 0 || w2 < 0) continue;
          const double depth = 1 / (w0 * iz0 + w1 * iz1 + w2 * iz2);  // perspective-correct
          if (depth >= zb[x]) continue;
          zb[x] = depth;
          lab[x] = static_cast<uint16_t>(labels[m]);
          dep[x] = static_cast<float>(depth);
        }
      }
    }
  }
  return out;
}

cv::Mat RasterizeSilhouette(const open3d::geometry::TriangleMesh& mesh, const Camera& camera) {
  return RasterizeMeshes({&mesh}, {1}, camera).labels > 0;
}

double MaskOverlap::XorOverGt() const {
  return gt > 0 ? static_cast<double>(xor_) / static_cast<double>(gt) : kNaN;
}

double MaskOverlap::OneMinusIoU() const {
  return union_ > 0 ? 1.0 - static_cast<double>(intersection) / static_cast<double>(union_) : kNaN;
}

MaskOverlap CompareMasks(const cv::Mat& pred, const cv::Mat& gt, const std::string& context) {
  U4D_CHECK(pred.type() == CV_8UC1 && gt.type() == CV_8UC1, "{}: masks must be CV_8UC1", context);
  U4D_CHECK(pred.size() == gt.size(), "{}: mask sizes differ ({}x{} vs {}x{})", context, pred.cols,
            pred.rows, gt.cols, gt.rows);
  MaskOverlap o;
  for (int y = 0; y < gt.rows; ++y) {
    const uint8_t* p = pred.ptr<uint8_t>(y);
    const uint8_t* g = gt.ptr<uint8_t>(y);
    for (int x = 0; x < gt.cols; ++x) {
      const bool a = p[x] != 0, b = g[x] != 0;
      o.pred += a;
      o.gt += b;
      o.intersection += a && b;
      o.union_ += a || b;
      o.xor_ += a != b;
    }
  }
  return o;
}

cv::Mat PropagateMask(const cv::Mat& mask, const cv::Mat& flow, const PropagateOptions& options,
                      const std::string& context) {
  options.Check();
  U4D_CHECK(mask.type() == CV_8UC1, "{}: the mask must be CV_8UC1", context);
  U4D_CHECK(flow.type() == CV_32FC2, "{}: the flow must be CV_32FC2", context);
  U4D_CHECK(mask.size() == flow.size(), "{}: mask {}x{} but flow {}x{}", context, mask.cols,
            mask.rows, flow.cols, flow.rows);
  cv::Mat out = cv::Mat::zeros(mask.size(), CV_8UC1);
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y);
    const cv::Vec2f* f = flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (!m[x] || !FlowValid(f[x][0], f[x][1])) continue;
      const long tx = std::lround(x + static_cast<double>(f[x][0]));
      const long ty = std::lround(y + static_cast<double>(f[x][1]));
      if (tx < 0 || ty < 0 || tx >= mask.cols || ty >= mask.rows) continue;
      out.at<uint8_t>(static_cast<int>(ty), static_cast<int>(tx)) = 255;
    }
  }
  if (options.close_cracks)
    cv::morphologyEx(out, out, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  return out;
}

void RatioMean::Add(double ratio) {
  if (std::isnan(ratio)) return;
  sum += ratio;
  ++count;
}

double RatioMean::Mean() const { return count > 0 ? sum / static_cast<double>(count) : kNaN; }

}  // namespace u4d::eval
