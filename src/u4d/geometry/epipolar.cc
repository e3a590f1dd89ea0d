#include "u4d/geometry/epipolar.h"

namespace u4d {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

}  // namespace

Eigen::Matrix3d FundamentalFromCameras(const Camera& cam1, const Camera& cam2) {
  const Rigid3d cam2_from_cam1 = cam2.cam_from_world * cam1.cam_from_world.Inverse();
  const Eigen::Matrix3d essential = Skew(cam2_from_cam1.translation) * cam2_from_cam1.rotation;
  return cam2.K.inverse().transpose() * essential * cam1.K.inverse();
}

double EpipolarDistance(const Eigen::Matrix3d& F, const Eigen::Vector2d& x1,
                        const Eigen::Vector2d& x2) {
  const Eigen::Vector3d line = F * x1.homogeneous();
  return std::abs(line.dot(x2.homogeneous())) / line.head<2>().norm();
}

Eigen::Vector2d UndistortPixel(const Camera& camera, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d n = camera.PixelToNormalized(pixel);
  return (camera.K * n.homogeneous()).hnormalized();
}

}  // namespace u4d
