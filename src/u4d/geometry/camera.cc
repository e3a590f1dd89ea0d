#include "u4d/geometry/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "u4d/util/check.h"

namespace u4d {

void Camera::Check(const std::string& context) const {
  U4D_CHECK(width > 0 && height > 0, "{}: image size must be positive, got {}x{}", context, width,
            height);
  U4D_CHECK(K.allFinite(), "{}: K has a non-finite value", context);
  U4D_CHECK(K(0, 0) > 0 && K(1, 1) > 0, "{}: focal lengths must be positive, got fx={} fy={}",
            context, K(0, 0), K(1, 1));
  U4D_CHECK(K(1, 0) == 0 && K(2, 0) == 0 && K(2, 1) == 0 && K(2, 2) == 1,
            "{}: K must be upper triangular with K(2,2)=1", context);
  for (double d : dist)
    U4D_CHECK(std::isfinite(d), "{}: distortion has a non-finite value", context);
  U4D_CHECK(cam_from_world.translation.allFinite(), "{}: translation has a non-finite value",
            context);
  U4D_CHECK(IsRotation(cam_from_world.rotation, 1e-4),
            "{}: cam_from_world rotation is not a rotation matrix (R R^T != I or det != 1)",
            context);
}

bool Camera::HasDistortion() const {
  for (double d : dist)
    if (d != 0.0) return true;
  return false;
}

Eigen::Vector3d Camera::Center() const {
  return -cam_from_world.rotation.transpose() * cam_from_world.translation;
}

Eigen::Vector3d Camera::ViewDirection() const { return cam_from_world.rotation.transpose().col(2); }

Eigen::Vector2d Distort(const std::array<double, 5>& d, const Eigen::Vector2d& n) {
  const double x = n.x(), y = n.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + d[0] * r2 + d[1] * r2 * r2 + d[4] * r2 * r2 * r2;
  return {x * radial + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x),
          y * radial + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y};
}

Eigen::Vector2d Undistort(const std::array<double, 5>& d, const Eigen::Vector2d& distorted) {
  // Fixed-point iteration as in cv::undistortPoints.
  Eigen::Vector2d n = distorted;
  for (int it = 0; it < 20; ++it) {
    const double x = n.x(), y = n.y();
    const double r2 = x * x + y * y;
    const double radial = 1 + d[0] * r2 + d[1] * r2 * r2 + d[4] * r2 * r2 * r2;
    const Eigen::Vector2d tangential(2 * d[2] * x * y + d[3] * (r2 + 2 * x * x),
                                     d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y);
    n = (distorted - tangential) / radial;
  }
  return n;
}

Eigen::Vector2d Camera::Project(const Eigen::Vector3d& point_in_world) const {
  const Eigen::Vector3d p = cam_from_world * point_in_world;
  if (p.z() <= 0) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan};
  }
  Eigen::Vector2d n(p.x() / p.z(), p.y() / p.z());
  if (HasDistortion()) n = Distort(dist, n);
  return {K(0, 0) * n.x() + K(0, 1) * n.y() + K(0, 2), K(1, 1) * n.y() + K(1, 2)};
}

double Camera::Depth(const Eigen::Vector3d& point_in_world) const {
  return (cam_from_world * point_in_world).z();
}

Eigen::Vector2d Camera::PixelToNormalized(const Eigen::Vector2d& pixel) const {
  const double y = (pixel.y() - K(1, 2)) / K(1, 1);
  const double x = (pixel.x() - K(0, 2) - K(0, 1) * y) / K(0, 0);
  Eigen::Vector2d n(x, y);
  if (HasDistortion()) n = Undistort(dist, n);
  return n;
}

Eigen::Vector3d Camera::Unproject(const Eigen::Vector2d& pixel, double depth) const {
  const Eigen::Vector2d n = PixelToNormalized(pixel);
  const Eigen::Vector3d point_in_cam(n.x() * depth, n.y() * depth, depth);
  return cam_from_world.Inverse() * point_in_cam;
}

Eigen::Matrix<double, 3, 4> Camera::ProjectionMatrix() const {
  return K * cam_from_world.ToMatrix();
}

std::optional<Eigen::Vector2i> NearestPixel(const Camera& camera,
                                            const Eigen::Vector3d& point_in_world) {
  const Eigen::Vector2d p = camera.Project(point_in_world);
  if (!p.allFinite() || !camera.InImage(p)) return std::nullopt;
  // lround(-0.5) is -1: the clamp keeps the border's half-pixel in the image.
  return Eigen::Vector2i(std::clamp(static_cast<int>(std::lround(p.x())), 0, camera.width - 1),
                         std::clamp(static_cast<int>(std::lround(p.y())), 0, camera.height - 1));
}

Camera ScaledCamera(const Camera& camera, double scale) {
  U4D_CHECK(std::isfinite(scale) && scale > 0, "ScaledCamera: scale must be positive, got {}",
            scale);
  Camera scaled = camera;
  scaled.width = std::max(1, static_cast<int>(std::lround(camera.width * scale)));
  scaled.height = std::max(1, static_cast<int>(std::lround(camera.height * scale)));
  scaled.K.row(0) *= scale;
  scaled.K.row(1) *= scale;
  scaled.K(0, 2) = scale * (camera.K(0, 2) + 0.5) - 0.5;
  scaled.K(1, 2) = scale * (camera.K(1, 2) + 0.5) - 0.5;
  return scaled;
}

}  // namespace u4d
