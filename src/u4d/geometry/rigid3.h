// A rigid transform target_from_source: x_in_target = rotation * x_in_source + translation.
// Naming convention (docs/conventions.md): variables are named by what they map,
// e.g. `cam_from_world`, and points by their frame, e.g. `point_in_cam`.
#pragma once

#include <Eigen/Geometry>

namespace u4d {

struct Rigid3d {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return rotation * x + translation; }
  // Composition: (a_from_b * b_from_c) maps c to a.
  Rigid3d operator*(const Rigid3d& b_from_c) const {
    return {rotation * b_from_c.rotation, rotation * b_from_c.translation + translation};
  }
  Rigid3d Inverse() const {
    const Eigen::Matrix3d rt = rotation.transpose();
    return {rt, -rt * translation};
  }
  Eigen::Matrix<double, 3, 4> ToMatrix() const {
    Eigen::Matrix<double, 3, 4> m;
    m << rotation, translation;
    return m;
  }
};

// True when `r` is a rotation matrix to within `tol` (orthonormal, det +1).
bool IsRotation(const Eigen::Matrix3d& r, double tol = 1e-6);

// Nearest rotation in the Frobenius sense (SVD projection); used to clean up
// rotations read from text files with few digits.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m);

}  // namespace u4d
