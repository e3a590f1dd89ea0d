// A calibrated pinhole camera with OpenCV's radial-tangential distortion.
//
// Conventions (docs/conventions.md): metres; the camera looks along +z of its
// own frame, x right, y down; pixel (x, y) has its origin at the CENTRE of the
// top-left pixel, so pixel (0, 0) covers [-0.5, 0.5]^2 — the same convention as
// OpenCV's projectPoints. Distortion is OpenCV's (k1, k2, p1, p2, k3).
#pragma once

#include <array>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "u4d/geometry/rigid3.h"

namespace u4d {

struct Camera {
  int width = 0;
  int height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  std::array<double, 5> dist = {0, 0, 0, 0, 0};  // k1, k2, p1, p2, k3
  Rigid3d cam_from_world;

  // Throws u4d::Error (prefixed with `context`) when the size is not
  // positive, K is not an upper-triangular intrinsic matrix with positive
  // focal lengths, a value is not finite, or the rotation is not a rotation.
  void Check(const std::string& context = "camera") const;

  bool HasDistortion() const;
  Eigen::Vector3d Center() const;         // camera centre in world coordinates
  Eigen::Vector3d ViewDirection() const;  // optical axis (+z of the camera) in world

  // World point to pixel, with distortion. Points behind the camera
  // (z <= 0 in the camera frame) give NaN.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_world) const;
  // Depth of a world point along the optical axis (z in the camera frame).
  double Depth(const Eigen::Vector3d& point_in_world) const;
  // Pixel to the normalised, undistorted image plane (x/z, y/z). Undistortion
  // is iterative (as cv::undistortPoints) and exact for distortion-free cameras.
  Eigen::Vector2d PixelToNormalized(const Eigen::Vector2d& pixel) const;
  // The world point seen at `pixel` at depth `depth` (z in the camera frame).
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel, double depth) const;
  // 3x4 projection matrix K [R | t] (ignores distortion).
  Eigen::Matrix<double, 3, 4> ProjectionMatrix() const;

  bool InImage(const Eigen::Vector2d& pixel) const {
    return pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() < width - 0.5 &&
           pixel.y() < height - 0.5;
  }
};

// The pixel (column, row) that `point_in_world` projects into: the nearest
// pixel centre, when the point is in front of the camera (Project is finite)
// and projects inside the image (InImage); std::nullopt otherwise. A
// projection on the image's outer half-pixel border rounds into the image.
// This is the one test of "does this view see the point, and where" behind
// the views' votes on 3D points (visual hulls, silhouette trims, occupancy).
std::optional<Eigen::Vector2i> NearestPixel(const Camera& camera,
                                            const Eigen::Vector3d& point_in_world);

// The same camera for an image resized by `scale` (> 0): size rounded to the
// nearest pixel, K scaled about the pixel-centre convention, i.e.
// x' = scale * (x + 0.5) - 0.5. Distortion and pose are unchanged.
Camera ScaledCamera(const Camera& camera, double scale);

// Applies / removes OpenCV radial-tangential distortion on normalised coordinates.
Eigen::Vector2d Distort(const std::array<double, 5>& dist, const Eigen::Vector2d& normalized);
Eigen::Vector2d Undistort(const std::array<double, 5>& dist, const Eigen::Vector2d& distorted);

}  // namespace u4d
