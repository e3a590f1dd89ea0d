// Cross-view silhouette consistency (init.h, step 3): a visual-hull test.
#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include "u4d/init/init.h"
#include "u4d/init/init_internal.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {
constexpr int kMaxSteps = 20000;  // bound on the march per ray
}  // namespace

ReducedMasks ReduceMasks(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& masks,
                         int max_side, int dilation_px) {
  const size_t nv = cameras.size();
  ReducedMasks r{std::vector<Camera>(nv), std::vector<cv::Mat>(nv), std::vector<cv::Mat>(nv)};
  for (size_t v = 0; v < nv; ++v) {
    const double s = std::min(
        1.0, static_cast<double>(max_side) / std::max(cameras[v].width, cameras[v].height));
    r.cameras[v] = ScaledCamera(cameras[v], s);
    cv::Mat area;
    cv::resize(masks[v], area, cv::Size(r.cameras[v].width, r.cameras[v].height), 0, 0,
               cv::INTER_AREA);
    r.source[v] = area >= 128;
    r.target[v] = area > 0;
    if (dilation_px > 0)
      cv::dilate(r.target[v], r.target[v],
                 cv::getStructuringElement(cv::MORPH_ELLIPSE,
                                           cv::Size(2 * dilation_px + 1, 2 * dilation_px + 1)));
  }
  return r;
}

std::vector<cv::Mat> CrossViewConsistentMasks(const std::vector<Camera>& cameras,
                                              const std::vector<cv::Mat>& masks,
                                              const InitOptions& options,
                                              std::vector<double>* consistent_share) {
  options.Check();
  const int nv = static_cast<int>(cameras.size());
  U4D_CHECK(nv >= 2, "CrossViewConsistentMasks: needs at least 2 views, found {}", nv);
  U4D_CHECK(masks.size() == cameras.size(), "CrossViewConsistentMasks: {} masks for {} cameras",
            masks.size(), cameras.size());
  for (int v = 0; v < nv; ++v) {
    cameras[v].Check(fmt::format("CrossViewConsistentMasks: camera {}", v));
    U4D_CHECK(!masks[v].empty() && masks[v].type() == CV_8UC1,
              "CrossViewConsistentMasks: mask {} must be a non-empty CV_8UC1 image", v);
    U4D_CHECK(masks[v].cols == cameras[v].width && masks[v].rows == cameras[v].height,
              "CrossViewConsistentMasks: mask {} is {}x{}, its camera {}x{}", v, masks[v].cols,
              masks[v].rows, cameras[v].width, cameras[v].height);
  }
  double far = options.cross_view.max_depth_m;
  if (far <= 0) {
    double baseline = 0;
    for (int a = 0; a < nv; ++a)
      for (int b = a + 1; b < nv; ++b)
        baseline = std::max(baseline, (cameras[a].Center() - cameras[b].Center()).norm());
    U4D_CHECK(baseline > 0, "CrossViewConsistentMasks: all cameras share one centre");
    far = 1.5 * baseline;
  }
  U4D_CHECK(far > options.cross_view.min_depth_m,
            "CrossViewConsistentMasks: max depth {} m must exceed min_depth_m {} m", far,
            options.cross_view.min_depth_m);

  const ReducedMasks reduced = ReduceMasks(cameras, masks, options.cross_view.consistency_max_side,
                                           options.cross_view.consistency_dilation_px);
  const std::vector<Camera>& small = reduced.cameras;
  const std::vector<cv::Mat>&source = reduced.source, &target = reduced.target;
  // With few views the requirement is capped at what exists.
  const int min_seeing = std::min(options.cross_view.min_views_seeing, nv - 1);
  std::vector<cv::Mat> consistent(nv);
  for (int v = 0; v < nv; ++v) {
    consistent[v] = cv::Mat::zeros(source[v].size(), CV_8UC1);
    const Camera& cam = small[v];
    const Rigid3d world_from_cam = cam.cam_from_world.Inverse();
    tbb::parallel_for(0, source[v].rows, [&](int y) {
      for (int x = 0; x < source[v].cols; ++x) {
        if (!source[v].at<uint8_t>(y, x)) continue;
        const Eigen::Vector2d n = cam.PixelToNormalized(Eigen::Vector2d(x, y));
        const Eigen::Vector3d dir(n.x(), n.y(), 1.0);
        // March along the ray with steps that move its projection in the
        // other views by about step_px (adapted from the previous step).
        bool ok = false;
        double z = options.cross_view.min_depth_m, step = 0.01 * z;
        std::vector<Eigen::Vector2d> prev(nv);
        bool have_prev = false;
        for (int it = 0; it < kMaxSteps && z <= far && !ok; ++it) {
          const Eigen::Vector3d X = world_from_cam * (z * dir);
          int inside = 0, fg = 0;
          double moved = 0;
          for (int o = 0; o < nv; ++o) {
            if (o == v) continue;
            const Eigen::Vector2d p = small[o].Project(X);
            if (!std::isfinite(p.x())) continue;
            if (have_prev && std::isfinite(prev[o].x()))
              moved = std::max(moved, (p - prev[o]).norm());
            prev[o] = p;
            if (!small[o].InImage(p)) continue;
            ++inside;
            const int px = std::clamp(static_cast<int>(std::lround(p.x())), 0, small[o].width - 1);
            const int py = std::clamp(static_cast<int>(std::lround(p.y())), 0, small[o].height - 1);
            if (target[o].at<uint8_t>(py, px)) ++fg;
          }
          ok = inside >= min_seeing &&
               fg >= std::ceil(options.cross_view.min_view_fraction * inside - 1e-9) && fg > 0;
          if (have_prev && moved > 0)
            step *= std::clamp(options.cross_view.step_px / moved, 0.5, 2.0);
          step = std::clamp(step, 1e-3, 0.25);
          have_prev = true;
          z += step;
        }
        if (ok) consistent[v].at<uint8_t>(y, x) = 255;
      }
    });
  }

  std::vector<cv::Mat> out(nv);
  if (consistent_share != nullptr) consistent_share->assign(nv, 0.0);
  for (int v = 0; v < nv; ++v) {
    const int src = cv::countNonZero(source[v]);
    if (consistent_share != nullptr && src > 0)
      (*consistent_share)[v] = static_cast<double>(cv::countNonZero(consistent[v])) / src;
    cv::Mat up;
    cv::resize(consistent[v], up, masks[v].size(), 0, 0, cv::INTER_NEAREST);
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(masks[v], labels, stats, centroids, 8, CV_32S);
    std::vector<long> good(n, 0);
    for (int y = 0; y < labels.rows; ++y) {
      const int* l = labels.ptr<int>(y);
      const uint8_t* u = up.ptr<uint8_t>(y);
      for (int x = 0; x < labels.cols; ++x)
        if (l[x] > 0 && u[x]) ++good[l[x]];
    }
    std::vector<uint8_t> keep(n, 0);
    for (int i = 1; i < n; ++i)
      keep[i] = good[i] >=
                options.cross_view.min_consistent_fraction * stats.at<int>(i, cv::CC_STAT_AREA);
    cv::Mat carve;
    if (options.cross_view.carve_pixels) {
      const double s = static_cast<double>(masks[v].cols) / small[v].width;
      const int r = std::max(1, static_cast<int>(std::ceil(s)));
      cv::dilate(up, carve,
                 cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)));
    }
    out[v] = cv::Mat::zeros(masks[v].size(), CV_8UC1);
    for (int y = 0; y < labels.rows; ++y) {
      const int* l = labels.ptr<int>(y);
      uint8_t* o = out[v].ptr<uint8_t>(y);
      for (int x = 0; x < labels.cols; ++x) {
        if (l[x] <= 0 || !keep[l[x]]) continue;
        if (options.cross_view.carve_pixels && !carve.at<uint8_t>(y, x)) continue;
        o[x] = 255;
      }
    }
  }
  return out;
}

}  // namespace u4d
