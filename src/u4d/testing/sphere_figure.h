// Figures made of spheres, rendered exactly into a camera: silhouettes for
// the tests of the multi-view hull steps (features/silhouette_points.h,
// joint/hull_support.h), where the true surface is known in closed form.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"

namespace u4d::testing {

struct Sphere {
  Eigen::Vector3d centre;  // world, metres
  double radius = 0;
};

// Whether the ray of pixel (x, y) meets any of the spheres.
bool RayHitsSpheres(const Camera& camera, int x, int y, const std::vector<Sphere>& spheres);

// The silhouette of the spheres in the camera: CV_8U, 255 on them.
cv::Mat RenderSpheres(const Camera& camera, const std::vector<Sphere>& spheres);

// Distance from a point to the nearest sphere's surface (negative inside).
double DistanceToSpheres(const Eigen::Vector3d& x, const std::vector<Sphere>& spheres);

}  // namespace u4d::testing
