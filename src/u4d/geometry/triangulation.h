// Multi-view triangulation of one point from its observations.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "u4d/geometry/camera.h"

namespace u4d {

struct Observation {
  const Camera* camera = nullptr;
  Eigen::Vector2d pixel;  // distorted pixel as seen in the image
  double weight = 1.0;
};

// Linear (DLT) triangulation on undistorted normalised coordinates, weighted.
// Needs at least two observations; returns NaN when the system is degenerate.
Eigen::Vector3d TriangulateDlt(const std::vector<Observation>& observations);

// Root-mean-square reprojection error in pixels of `point` over observations.
double ReprojectionRmse(const Eigen::Vector3d& point, const std::vector<Observation>& observations);

}  // namespace u4d
