// Epipolar geometry between two calibrated cameras (distortion ignored: apply
// it to undistorted pixels, see Camera::PixelToNormalized).
#pragma once

#include <Eigen/Core>

#include "u4d/geometry/camera.h"

namespace u4d {

// Fundamental matrix F with x2^T F x1 = 0 for homogeneous undistorted pixels.
Eigen::Matrix3d FundamentalFromCameras(const Camera& cam1, const Camera& cam2);

// Distance in pixels from undistorted pixel x2 to the epipolar line of
// undistorted pixel x1 in camera 2.
double EpipolarDistance(const Eigen::Matrix3d& F, const Eigen::Vector2d& x1,
                        const Eigen::Vector2d& x2);

// Undistorted pixel: the pixel a distortion-free copy of `camera` would see.
Eigen::Vector2d UndistortPixel(const Camera& camera, const Eigen::Vector2d& pixel);

}  // namespace u4d
