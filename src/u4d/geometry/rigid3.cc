#include "u4d/geometry/rigid3.h"

#include <Eigen/SVD>

namespace u4d {

bool IsRotation(const Eigen::Matrix3d& r, double tol) {
  if (!r.allFinite()) return false;
  return (r * r.transpose() - Eigen::Matrix3d::Identity()).norm() < tol &&
         std::abs(r.determinant() - 1.0) < tol;
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

}  // namespace u4d
