// The flow of the static background (issue 23, "moving cameras"): a static
// scene point moves in the image only because the camera moves, so its flow
// t -> t+1 is the rigid flow of the camera's motion, fixed by the per-frame
// calibration up to the point's depth.
//
// With X_t = z [n; 1] the point in the camera at t (n: p undistorted and
// normalised, z its depth) and t1_from_t = (R, T) the camera's motion, the
// point at t+1 is, up to scale, R [n; 1] + ρ T with ρ = 1 / z. As ρ runs
// from 0 (infinity) to large (near), its normalised image runs along a
// straight segment of the epipolar line of p. A dense two-frame match q of p
// (OpenCV DIS) is snapped to that segment: the ρ whose image is nearest to q
// (in normalised coordinates, ρ clamped to [0, 1 / min_depth_m] and to points
// in front of the camera at t+1), and the flow is the projection of that
// point minus p. The match only chooses the depth along the line; the
// direction of the flow is the calibration's, so a match that slides along
// an edge or into a textureless patch costs at most its error along the line.
// A camera that does not move (same intrinsics and pose) has rigid flow 0
// everywhere, and then no match is computed.
#pragma once

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"

namespace u4d {

struct BackgroundFlowOptions {
  bool enabled = true;       // rigid flow outside the objects' regions (false: flow 0 there)
  double min_depth_m = 0.2;  // nearest depth a background point may take (> 0)
  void Check() const;        // throws u4d::Error naming the bad field
};

// True when the two cameras differ (intrinsics, distortion, size or pose).
bool CameraMoved(const Camera& cam_t, const Camera& cam_t1);

// The rigid flow (CV_32FC2, cam_t's size) of every pixel of a static scene
// seen by cam_t at t and cam_t1 at t+1, each pixel's depth chosen by its
// match in `matches` (CV_32FC2 flow t -> t+1, the same size; non-finite
// entries take depth infinity). Throws u4d::Error when the cameras differ in
// size or `matches` is not CV_32FC2 of their size.
cv::Mat RigidFlowFromMatches(const Camera& cam_t, const Camera& cam_t1, const cv::Mat& matches,
                             const BackgroundFlowOptions& options = {});

// The background flow of one view: 0 when the camera does not move, else
// RigidFlowFromMatches of OpenCV DIS (medium preset) between the grey
// (CV_8U) frames t and t+1 of the camera's size. Throws u4d::Error on images
// of the wrong type or size.
cv::Mat BackgroundFlow(const Camera& cam_t, const Camera& cam_t1, const cv::Mat& grey_t,
                       const cv::Mat& grey_t1, const BackgroundFlowOptions& options = {});

}  // namespace u4d
