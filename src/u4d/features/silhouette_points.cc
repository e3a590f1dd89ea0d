#include "u4d/features/silhouette_points.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {

void SilhouettePointOptions::Check() const {
  U4D_CHECK(max_side >= 16, "SilhouettePointOptions.max_side must be >= 16, got {}", max_side);
  U4D_CHECK(pixels_per_view >= 1, "SilhouettePointOptions.pixels_per_view must be >= 1");
  U4D_CHECK(depth_samples >= 2, "SilhouettePointOptions.depth_samples must be >= 2");
  U4D_CHECK(min_depth_m > 0, "SilhouettePointOptions.min_depth_m must be > 0");
  U4D_CHECK(min_views_seeing >= 1, "SilhouettePointOptions.min_views_seeing must be >= 1");
  U4D_CHECK(min_foreground_share > 0 && min_foreground_share <= 1,
            "SilhouettePointOptions.min_foreground_share must be in (0, 1], got {}",
            min_foreground_share);
}

std::vector<SparsePoint> SilhouettePoints(const std::vector<Camera>& cameras,
                                          const std::vector<cv::Mat>& masks,
                                          const SilhouettePointOptions& options,
                                          const std::vector<cv::Mat>* unknown) {
  options.Check();
  const int nv = static_cast<int>(cameras.size());
  U4D_CHECK(static_cast<int>(masks.size()) == nv, "SilhouettePoints: {} cameras but {} masks", nv,
            masks.size());
  U4D_CHECK(unknown == nullptr || static_cast<int>(unknown->size()) == nv,
            "SilhouettePoints: {} cameras but {} unknown masks", nv, unknown ? unknown->size() : 0);
  // Reduced, slightly dilated foreground per view (absent or empty mask: no
  // view), and the pixels where the view abstains (reduced, not dilated).
  std::vector<Camera> small(nv);
  std::vector<cv::Mat> fg(nv), abstain(nv);
  double baseline = 0;
  for (int v = 0; v < nv; ++v) {
    for (int w = 0; w < nv; ++w)
      baseline = std::max(baseline, (cameras[v].Center() - cameras[w].Center()).norm());
    // A view whose detector found nobody tells nothing of the hull.
    if (masks[v].empty() || cv::countNonZero(masks[v]) == 0) continue;
    const double s =
        std::min(1.0, double(options.max_side) / std::max(cameras[v].width, cameras[v].height));
    small[v] = ScaledCamera(cameras[v], s);
    cv::Mat m = masks[v] > 0, r;
    cv::resize(m, r, {small[v].width, small[v].height}, 0, 0, cv::INTER_AREA);
    cv::dilate(r > 0, fg[v], cv::Mat::ones(3, 3, CV_8U));
    if (unknown == nullptr || (*unknown)[v].empty()) continue;
    const cv::Mat& u = (*unknown)[v];
    U4D_CHECK(u.channels() == 1 && u.cols == cameras[v].width && u.rows == cameras[v].height,
              "SilhouettePoints: the unknown mask of view {} must be single-channel {}x{}", v,
              cameras[v].width, cameras[v].height);
    cv::resize(u > 0, r, {small[v].width, small[v].height}, 0, 0, cv::INTER_AREA);
    abstain[v] = (r > 127) & ~fg[v];  // where the view holds the object it still says so
  }
  const double far = std::max(5.0, 1.5 * baseline);
  const double inv_near = 1 / options.min_depth_m, inv_far = 1 / far;
  std::vector<SparsePoint> points;
  for (int v = 0; v < nv; ++v) {
    if (fg[v].empty()) continue;
    std::vector<cv::Point> pixels;
    cv::findNonZero(fg[v], pixels);
    const size_t step = std::max<size_t>(1, pixels.size() / options.pixels_per_view);
    for (size_t k = 0; k < pixels.size(); k += step) {
      const Eigen::Vector2d px(pixels[k].x, pixels[k].y);
      for (int d = 0; d < options.depth_samples; ++d) {
        const double inv = inv_near + (inv_far - inv_near) * d / (options.depth_samples - 1);
        const Eigen::Vector3d X = small[v].Unproject(px, 1 / inv);
        int seeing = 0, holding = 0;
        for (int w = 0; w < nv; ++w) {
          if (w == v || fg[w].empty() || small[w].Depth(X) <= 0) continue;
          const Eigen::Vector2d q = small[w].Project(X);
          if (!q.allFinite() || !small[w].InImage(q)) continue;
          const cv::Point at(int(std::lround(q.x())), int(std::lround(q.y())));
          if (!abstain[w].empty() && abstain[w].at<uint8_t>(at) > 0) continue;
          ++seeing;
          holding += fg[w].at<uint8_t>(at) > 0;
        }
        if (seeing < options.min_views_seeing ||
            holding < std::ceil(options.min_foreground_share * seeing - 1e-9))
          continue;
        SparsePoint p;
        p.position = X;
        for (int w = 0; w < nv; ++w) {
          if (masks[w].empty() || cameras[w].Depth(X) <= 0) continue;
          const Eigen::Vector2d q = cameras[w].Project(X);
          if (!q.allFinite() || !cameras[w].InImage(q)) continue;
          p.observations.emplace_back(w, -1);
          p.pixels.push_back(q);
        }
        points.push_back(std::move(p));
        break;  // the first consistent depth: the hull's surface along this ray
      }
    }
  }
  return points;
}

}  // namespace u4d
