#include "u4d/joint/background_flow.h"

#include <algorithm>
#include <cmath>

#include "u4d/baselines/dense_flow.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

// The camera's motion t -> t+1 in the camera frame at t: X_t1 = R X_t + T.
struct CameraMotion {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
};

CameraMotion MotionOf(const Camera& cam_t, const Camera& cam_t1) {
  const Rigid3d t1_from_t = cam_t1.cam_from_world * cam_t.cam_from_world.Inverse();
  return {t1_from_t.rotation, t1_from_t.translation};
}

// The inverse depth ρ in [0, rho_max] whose point R [n; 1] + ρ T projects
// nearest to the normalised match m (see the header).
double SnapInverseDepth(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                        const Eigen::Vector2d& m, double rho_max) {
  const Eigen::Vector2d u0 = a.head<2>() / a.z();
  const Eigen::Vector2d dir = b.head<2>() * a.z() - a.head<2>() * b.z();
  const double len2 = dir.squaredNorm();
  if (len2 < 1e-18) return 0;  // no parallax: every depth gives the same image
  // The image at ρ is u0 + dir g(ρ), g(ρ) = ρ / (a_z (a_z + ρ b_z)).
  const double g = (m - u0).dot(dir) / len2;
  const double denominator = 1 - g * a.z() * b.z();
  double rho = (g <= 0) ? 0 : (denominator > 0 ? g * a.z() * a.z() / denominator : rho_max);
  if (b.z() < 0) rho = std::min(rho, 0.999 * -a.z() / b.z());  // in front of the camera at t+1
  return std::clamp(rho, 0.0, rho_max);
}

}  // namespace

void BackgroundFlowOptions::Check() const {
  U4D_CHECK(std::isfinite(min_depth_m) && min_depth_m > 0,
            "BackgroundFlowOptions.min_depth_m must be > 0, got {}", min_depth_m);
}

bool CameraMoved(const Camera& cam_t, const Camera& cam_t1) {
  return cam_t.width != cam_t1.width || cam_t.height != cam_t1.height || cam_t.K != cam_t1.K ||
         cam_t.dist != cam_t1.dist ||
         cam_t.cam_from_world.rotation != cam_t1.cam_from_world.rotation ||
         cam_t.cam_from_world.translation != cam_t1.cam_from_world.translation;
}

cv::Mat RigidFlowFromMatches(const Camera& cam_t, const Camera& cam_t1, const cv::Mat& matches,
                             const BackgroundFlowOptions& options) {
  options.Check();
  U4D_CHECK(cam_t.width == cam_t1.width && cam_t.height == cam_t1.height,
            "RigidFlowFromMatches: the cameras at t and t+1 differ in size ({}x{} and {}x{})",
            cam_t.width, cam_t.height, cam_t1.width, cam_t1.height);
  U4D_CHECK(
      matches.type() == CV_32FC2 && matches.cols == cam_t.width && matches.rows == cam_t.height,
      "RigidFlowFromMatches: the matches must be CV_32FC2 of {}x{}, got {}x{} type {}", cam_t.width,
      cam_t.height, matches.cols, matches.rows, matches.type());
  const CameraMotion motion = MotionOf(cam_t, cam_t1);
  const Rigid3d world_from_t = cam_t.cam_from_world.Inverse();
  const double rho_max = 1 / options.min_depth_m;
  cv::Mat flow(matches.size(), CV_32FC2);
  for (int y = 0; y < flow.rows; ++y) {
    const cv::Vec2f* q = matches.ptr<cv::Vec2f>(y);
    cv::Vec2f* out = flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < flow.cols; ++x) {
      const Eigen::Vector2d p(x, y);
      const Eigen::Vector3d ray = cam_t.PixelToNormalized(p).homogeneous();
      const Eigen::Vector3d a = motion.rotation * ray;
      double rho = 0;
      if (a.z() > 0 && std::isfinite(q[x][0]) && std::isfinite(q[x][1])) {
        const Eigen::Vector2d m = cam_t1.PixelToNormalized(p + Eigen::Vector2d(q[x][0], q[x][1]));
        rho = SnapInverseDepth(a, motion.translation, m, rho_max);
      }
      const double depth = rho > 0 ? 1 / rho : 1e6;  // ρ = 0: a point at infinity
      const Eigen::Vector2d x1 = cam_t1.Project(world_from_t * (ray * depth));
      out[x] = x1.allFinite() ? cv::Vec2f(x1.x() - x, x1.y() - y) : q[x];
    }
  }
  return flow;
}

cv::Mat BackgroundFlow(const Camera& cam_t, const Camera& cam_t1, const cv::Mat& grey_t,
                       const cv::Mat& grey_t1, const BackgroundFlowOptions& options) {
  options.Check();
  const cv::Size size(cam_t.width, cam_t.height);
  U4D_CHECK(grey_t.type() == CV_8UC1 && grey_t1.type() == CV_8UC1 && grey_t.size() == size &&
                grey_t1.size() == size,
            "BackgroundFlow: need two 8-bit grey images of {}x{} (got {}x{} type {} and {}x{} "
            "type {})",
            size.width, size.height, grey_t.cols, grey_t.rows, grey_t.type(), grey_t1.cols,
            grey_t1.rows, grey_t1.type());
  if (!CameraMoved(cam_t, cam_t1)) return cv::Mat::zeros(size, CV_32FC2);
  const cv::Mat matches =
      baselines::DenseFlow(baselines::DenseFlowMethod::kDisMedium, grey_t, grey_t1);
  return RigidFlowFromMatches(cam_t, cam_t1, matches, options);
}

}  // namespace u4d
