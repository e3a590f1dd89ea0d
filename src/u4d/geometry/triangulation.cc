#include "u4d/geometry/triangulation.h"

#include <cmath>
#include <limits>

#include <Eigen/SVD>

#include "u4d/util/check.h"

namespace u4d {

Eigen::Vector3d TriangulateDlt(const std::vector<Observation>& observations) {
  U4D_CHECK(observations.size() >= 2, "triangulation needs at least two observations, got {}",
            observations.size());
  Eigen::MatrixXd a(2 * observations.size(), 4);
  for (size_t i = 0; i < observations.size(); ++i) {
    const Observation& obs = observations[i];
    const Eigen::Vector2d n = obs.camera->PixelToNormalized(obs.pixel);
    const Eigen::Matrix<double, 3, 4> p = obs.camera->cam_from_world.ToMatrix();
    a.row(2 * i) = obs.weight * (n.x() * p.row(2) - p.row(0));
    a.row(2 * i + 1) = obs.weight * (n.y() * p.row(2) - p.row(1));
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d x = svd.matrixV().col(3);
  if (std::abs(x(3)) < 1e-12) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan};
  }
  return x.head<3>() / x(3);
}

double ReprojectionRmse(const Eigen::Vector3d& point,
                        const std::vector<Observation>& observations) {
  double sum = 0;
  for (const Observation& obs : observations) {
    sum += (obs.camera->Project(point) - obs.pixel).squaredNorm();
  }
  return std::sqrt(sum / std::max<size_t>(1, observations.size()));
}

}  // namespace u4d
