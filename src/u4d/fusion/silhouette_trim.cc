#include "u4d/fusion/silhouette_trim.h"

#include <optional>

#include <opencv2/imgproc.hpp>

#include "u4d/fusion/depth_sampling.h"
#include "u4d/util/check.h"

namespace u4d {

void SilhouetteTrimOptions::Check() const {
  U4D_CHECK(min_views >= 0, "SilhouetteTrimOptions.min_views must be >= 0 (0 = off), found {}",
            min_views);
  U4D_CHECK(margin_px >= 0, "SilhouetteTrimOptions.margin_px must be >= 0, found {}", margin_px);
  U4D_CHECK(support_factor >= 0, "SilhouetteTrimOptions.support_factor must be >= 0, found {}",
            support_factor);
  U4D_CHECK(occlusion_tolerance > 0,
            "SilhouetteTrimOptions.occlusion_tolerance must be > 0, found {}", occlusion_tolerance);
}

namespace {

void CheckInputs(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& depths,
                 const std::vector<cv::Mat>& ids) {
  U4D_CHECK(depths.size() == cameras.size() && ids.size() == cameras.size(),
            "OutsideSilhouettes: expected one depth and instance map per camera ({}), found {} "
            "depths, {} instance maps",
            cameras.size(), depths.size(), ids.size());
  for (size_t v = 0; v < cameras.size(); ++v) {
    const int w = cameras[v].width, h = cameras[v].height;
    fusion_internal::CheckMap(ids[v], CV_16UC1, w, h, fmt::format("instance ids of view {}", v));
    if (!depths[v].empty())
      fusion_internal::CheckMap(depths[v], CV_32FC1, w, h, fmt::format("depth of view {}", v));
  }
}

// Distance (pixels) from every pixel to the nearest pixel of `object_id`;
// empty when the view holds none of it.
cv::Mat DistanceToObject(const cv::Mat& ids, int object_id) {
  const cv::Mat not_object = ids != object_id;
  if (cv::countNonZero(not_object) == static_cast<int>(ids.total())) return {};
  cv::Mat distance;
  cv::distanceTransform(not_object, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return distance;
}

// What view `camera` says of `x`: +1 off the object (outside its silhouette
// by more than the margin and not behind a nearer object), -1 on it (within
// the margin), 0 nothing (not in the image, or hidden).
int Vote(const Eigen::Vector3d& x, const Camera& camera, const cv::Mat& distance,
         const cv::Mat& depth, const cv::Mat& ids, const SilhouetteTrimOptions& options) {
  const std::optional<Eigen::Vector2i> q = NearestPixel(camera, x);
  if (!q) return 0;
  if (distance.at<float>(q->y(), q->x()) <= options.margin_px) return -1;
  const float there = depth.empty() ? 0.f : depth.at<float>(q->y(), q->x());
  const bool hidden = ids.at<uint16_t>(q->y(), q->x()) != 0 && there > 0 &&
                      there < camera.Depth(x) - options.occlusion_tolerance;
  return hidden ? 0 : 1;
}

}  // namespace

std::vector<bool> OutsideSilhouettes(const std::vector<Eigen::Vector3d>& vertices,
                                     const std::vector<bool>& supported,
                                     const std::vector<Camera>& cameras,
                                     const std::vector<cv::Mat>& depths,
                                     const std::vector<cv::Mat>& instance_ids, int object_id,
                                     const SilhouetteTrimOptions& options) {
  std::vector<bool> outside(vertices.size(), false);
  if (options.min_views <= 0) return outside;
  CheckInputs(cameras, depths, instance_ids);
  U4D_CHECK(supported.empty() || supported.size() == vertices.size(),
            "OutsideSilhouettes: {} support flags for {} vertices", supported.size(),
            vertices.size());
  std::vector<int> off(vertices.size(), 0), on(vertices.size(), 0);
  for (size_t v = 0; v < cameras.size(); ++v) {
    const cv::Mat distance = DistanceToObject(instance_ids[v], object_id);
    if (distance.empty()) continue;
    for (size_t i = 0; i < vertices.size(); ++i) {
      const int vote = Vote(vertices[i], cameras[v], distance, depths[v], instance_ids[v], options);
      off[i] += vote > 0;
      on[i] += vote < 0;
    }
  }
  for (size_t i = 0; i < vertices.size(); ++i)
    outside[i] =
        off[i] >= options.min_views && (supported.empty() || !supported[i] || off[i] > on[i]);
  return outside;
}

}  // namespace u4d
