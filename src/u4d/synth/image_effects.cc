#include "u4d/synth/image_effects.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d::synth {

void ImageEffectsOptions::Check() const {
  U4D_CHECK(
      std::isfinite(motion_blur_shutter) && motion_blur_shutter >= 0 && motion_blur_shutter <= 1,
      "ImageEffectsOptions.motion_blur_shutter: expected 0-1, got {}", motion_blur_shutter);
  U4D_CHECK(motion_blur_samples >= 2 && motion_blur_samples <= 64,
            "ImageEffectsOptions.motion_blur_samples: expected 2-64, got {}", motion_blur_samples);
  U4D_CHECK(std::isfinite(shadow_strength) && shadow_strength >= 0 && shadow_strength <= 1,
            "ImageEffectsOptions.shadow_strength: expected 0-1, got {}", shadow_strength);
  U4D_CHECK(std::isfinite(shadow_softness) && shadow_softness >= 0,
            "ImageEffectsOptions.shadow_softness: expected >= 0 metres, got {}", shadow_softness);
  U4D_CHECK(std::isfinite(shadow_cell) && shadow_cell >= 0.001 && shadow_cell <= 0.2,
            "ImageEffectsOptions.shadow_cell: expected 0.001-0.2 metres, got {}", shadow_cell);
  U4D_CHECK(std::isfinite(spill_strength) && spill_strength >= 0 && spill_strength <= 1,
            "ImageEffectsOptions.spill_strength: expected 0-1, got {}", spill_strength);
  U4D_CHECK(std::isfinite(spill_width_px) && spill_width_px > 0,
            "ImageEffectsOptions.spill_width_px: expected > 0, got {}", spill_width_px);
  U4D_CHECK(
      spill_colour.minCoeff() >= 0 && spill_colour.maxCoeff() <= 255 && spill_colour.sum() > 0,
      "ImageEffectsOptions.spill_colour: expected 8-bit BGR, not black");
}

void ApplySpill(const cv::Mat& instance, const ImageEffectsOptions& options, cv::Mat* color) {
  if (options.spill_strength <= 0) return;
  U4D_CHECK(color != nullptr && color->type() == CV_8UC3 && instance.type() == CV_16UC1 &&
                instance.size() == color->size(),
            "ApplySpill: expected a BGR image and a CV_16UC1 instance image of its size");
  cv::Mat person = instance > 0, distance;
  cv::distanceTransform(person, distance, cv::DIST_L2, 3);
  const Eigen::Vector3f key = options.spill_colour / options.spill_colour.sum();
  for (int y = 0; y < color->rows; ++y) {
    cv::Vec3b* c = color->ptr<cv::Vec3b>(y);
    const float* d = distance.ptr<float>(y);
    const uint8_t* p = person.ptr<uint8_t>(y);
    for (int x = 0; x < color->cols; ++x) {
      if (!p[x]) continue;
      const float s = static_cast<float>(options.spill_strength) *
                      (0.4f + 0.6f * std::exp(-d[x] / static_cast<float>(options.spill_width_px)));
      const float sum = static_cast<float>(c[x][0]) + c[x][1] + c[x][2];
      for (int k = 0; k < 3; ++k)
        c[x][k] = cv::saturate_cast<uint8_t>(c[x][k] + s * (key[k] * sum - c[x][k]));
    }
  }
}

double FloorShadowMap::CoverageAt(double x, double z) const {
  if (coverage.empty()) return 0;
  const double u = (x - origin.x()) / cell, v = (z - origin.y()) / cell;
  const int u0 = static_cast<int>(std::floor(u)), v0 = static_cast<int>(std::floor(v));
  if (u0 < 0 || v0 < 0 || u0 + 1 >= coverage.cols || v0 + 1 >= coverage.rows) return 0;
  const double a = u - u0, b = v - v0;
  const float* r0 = coverage.ptr<float>(v0);
  const float* r1 = coverage.ptr<float>(v0 + 1);
  return (1 - b) * ((1 - a) * r0[u0] + a * r0[u0 + 1]) + b * ((1 - a) * r1[u0] + a * r1[u0 + 1]);
}

FloorShadowMap MakeFloorShadowMap(const SceneFrame& frame, const Eigen::Vector3d& light_direction,
                                  const ImageEffectsOptions& options) {
  options.Check();
  U4D_CHECK(light_direction.allFinite() && light_direction.y() < 0,
            "MakeFloorShadowMap: the light must travel downwards (y < 0)");
  FloorShadowMap map;
  map.cell = options.shadow_cell;
  std::vector<Eigen::Vector2d> points;
  for (const SceneObject& person : frame.people)
    for (const Eigen::Vector3f& v : person.mesh.vertices) {
      const Eigen::Vector3d p = v.cast<double>();
      const Eigen::Vector3d on_floor = p - (p.y() / light_direction.y()) * light_direction;
      points.emplace_back(on_floor.x(), on_floor.z());
    }
  if (points.empty() || options.shadow_strength == 0) return map;
  Eigen::Vector2d lo = points.front(), hi = points.front();
  for (const Eigen::Vector2d& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double margin = 4 * options.shadow_softness + 0.05;
  map.origin = lo - Eigen::Vector2d::Constant(margin);
  const Eigen::Vector2d size = (hi - lo + Eigen::Vector2d::Constant(2 * margin)) / map.cell;
  cv::Mat hits(static_cast<int>(std::ceil(size.y())) + 1, static_cast<int>(std::ceil(size.x())) + 1,
               CV_8U, cv::Scalar(0));
  for (const Eigen::Vector2d& p : points) {
    const int u = static_cast<int>(std::lround((p.x() - map.origin.x()) / map.cell));
    const int v = static_cast<int>(std::lround((p.y() - map.origin.y()) / map.cell));
    if (u >= 0 && v >= 0 && u < hits.cols && v < hits.rows) hits.at<uint8_t>(v, u) = 255;
  }
  // Vertices of the captured and procedural meshes lie a few cm apart: a
  // closing over 5 cm fills the shadow's inside.
  const int k = std::max(3, static_cast<int>(std::lround(0.05 / map.cell)) | 1);
  cv::morphologyEx(hits, hits, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
  hits.convertTo(map.coverage, CV_32F, 1.0 / 255);
  const double sigma = options.shadow_softness / map.cell;
  if (sigma > 0.3) cv::GaussianBlur(map.coverage, map.coverage, cv::Size(), sigma);
  return map;
}

namespace {

// The pixels where the shadow map's rectangle on the floor can appear: the
// bounding box of its projected corners, or the whole image when a corner is
// behind the camera.
cv::Rect ShadowRoi(const Camera& camera, const FloorShadowMap& shadows) {
  const cv::Rect image(0, 0, camera.width, camera.height);
  const Eigen::Vector2d size(shadows.coverage.cols * shadows.cell,
                             shadows.coverage.rows * shadows.cell);
  cv::Rect roi;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d xz =
        shadows.origin + Eigen::Vector2d((k & 1) ? size.x() : 0, (k & 2) ? size.y() : 0);
    const Eigen::Vector2d px = camera.Project(Eigen::Vector3d(xz.x(), 0, xz.y()));
    if (!px.allFinite()) return image;
    const cv::Rect corner(static_cast<int>(std::floor(px.x())) - 1,
                          static_cast<int>(std::floor(px.y())) - 1, 3, 3);
    roi = k == 0 ? corner : (roi | corner);
  }
  return roi & image;
}

}  // namespace

void ApplyFloorShadows(const Camera& camera, const cv::Mat& depth, const cv::Mat& instance,
                       const FloorShadowMap& shadows, const ImageEffectsOptions& options,
                       cv::Mat* color) {
  if (shadows.coverage.empty() || options.shadow_strength == 0) return;
  U4D_CHECK(color != nullptr && color->type() == CV_8UC3 && depth.type() == CV_32FC1 &&
                instance.type() == CV_16UC1 && depth.size() == color->size() &&
                instance.size() == color->size(),
            "ApplyFloorShadows: colour, depth and instance images must match");
  const cv::Rect roi = ShadowRoi(camera, shadows);
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    const float* z = depth.ptr<float>(y);
    const uint16_t* id = instance.ptr<uint16_t>(y);
    cv::Vec3b* c = color->ptr<cv::Vec3b>(y);
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      if (id[x] != 0 || !(z[x] > 0) || !std::isfinite(z[x])) continue;
      const Eigen::Vector3d world = camera.Unproject(Eigen::Vector2d(x, y), z[x]);
      if (std::abs(world.y()) > 0.01) continue;
      const double cover = shadows.CoverageAt(world.x(), world.z());
      if (cover <= 0) continue;
      const double factor = 1 - options.shadow_strength * std::min(1.0, cover);
      for (int ch = 0; ch < 3; ++ch)
        c[x][ch] = cv::saturate_cast<uint8_t>(std::lround(c[x][ch] * factor));
    }
  }
}

void ApplyMotionBlur(const cv::Mat& flow, const cv::Mat& instance,
                     const ImageEffectsOptions& options, cv::Mat* color) {
  if (options.motion_blur_shutter == 0 || flow.empty()) return;
  U4D_CHECK(color != nullptr && color->type() == CV_8UC3 && flow.type() == CV_32FC2 &&
                instance.type() == CV_16UC1 && flow.size() == color->size() &&
                instance.size() == color->size(),
            "ApplyMotionBlur: colour, flow and instance images must match");
  const cv::Mat sharp = color->clone();
  cv::Mat sum(color->size(), CV_32FC3, cv::Scalar::all(0));
  cv::Mat map_x(color->size(), CV_32F), map_y(color->size(), CV_32F), tap;
  const int n = options.motion_blur_samples;
  for (int k = 0; k < n; ++k) {
    const float s =
        static_cast<float>(options.motion_blur_shutter * (k / static_cast<double>(n - 1) - 0.5));
    for (int y = 0; y < flow.rows; ++y) {
      const cv::Vec2f* f = flow.ptr<cv::Vec2f>(y);
      float* mx = map_x.ptr<float>(y);
      float* my = map_y.ptr<float>(y);
      for (int x = 0; x < flow.cols; ++x) {
        const bool ok = std::isfinite(f[x][0]) && std::isfinite(f[x][1]);
        mx[x] = x + (ok ? s * f[x][0] : 0.f);
        my[x] = y + (ok ? s * f[x][1] : 0.f);
      }
    }
    cv::remap(sharp, tap, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    cv::accumulate(tap, sum);
  }
  cv::Mat blurred;
  sum.convertTo(blurred, CV_8UC3, 1.0 / n);
  blurred.copyTo(*color, instance != 0);
}

}  // namespace u4d::synth
