#include "u4d/testing/sphere_figure.h"

#include <algorithm>
#include <limits>

namespace u4d::testing {

bool RayHitsSpheres(const Camera& camera, int x, int y, const std::vector<Sphere>& spheres) {
  const Eigen::Vector3d c = camera.Center();
  const Eigen::Vector3d d = (camera.Unproject(Eigen::Vector2d(x, y), 1.0) - c).normalized();
  for (const Sphere& s : spheres) {
    const Eigen::Vector3d to = s.centre - c;
    if ((to - to.dot(d) * d).norm() < s.radius) return true;
  }
  return false;
}

cv::Mat RenderSpheres(const Camera& camera, const std::vector<Sphere>& spheres) {
  cv::Mat m = cv::Mat::zeros(camera.height, camera.width, CV_8U);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x)
      m.at<uint8_t>(y, x) = RayHitsSpheres(camera, x, y, spheres) ? 255 : 0;
  return m;
}

double DistanceToSpheres(const Eigen::Vector3d& x, const std::vector<Sphere>& spheres) {
  double best = std::numeric_limits<double>::infinity();
  for (const Sphere& s : spheres) best = std::min(best, (x - s.centre).norm() - s.radius);
  return best;
}

}  // namespace u4d::testing
