// Image-side realism applied to rendered views after the renderer: motion blur
// on moving people and soft shadows of the people on the floor. Neither
// changes any ground truth (instances, depth, flow stay those of the sharp,
// unshadowed render), as a real camera's blur and shadows do not move the
// surfaces.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"
#include "u4d/synth/scene.h"

namespace u4d::synth {

struct ImageEffectsOptions {
  // Motion blur: a person pixel averages the image along its forward flow
  // over this fraction of the frame interval, centred on the frame time (a
  // shutter open for shutter / fps seconds), with motion_blur_samples taps.
  // 0 disables. Pixels without a forward flow (the last frame) stay sharp.
  double motion_blur_shutter = 0;
  int motion_blur_samples = 9;
  // Soft shadows: floor pixels (world y = 0, no person) under a person's
  // shadow, cast along the light direction, are darkened by up to
  // shadow_strength (a factor on the 8-bit value); the shadow's edge is
  // blurred over shadow_softness metres (Gaussian sigma). 0 disables.
  double shadow_strength = 0;
  double shadow_softness = 0.08;
  double shadow_cell = 0.01;  // metres per cell of the floor's shadow map
  // Spill (a keyed stage: the backdrop's light reflected on the people): a
  // person pixel's colour c moves towards spill_colour scaled to c's
  // brightness (r + g + b), by spill_strength x (0.4 + 0.6 exp(-d /
  // spill_width_px)), d its distance in pixels to the nearest pixel that is
  // not a person: strongest at the silhouette's edge. 0 disables.
  double spill_strength = 0;
  double spill_width_px = 6.0;
  Eigen::Vector3f spill_colour{65, 177, 81};  // 8-bit BGR of the lit backdrop
  void Check() const;                         // throws u4d::Error naming the field
};

// The people's shadow on the floor y = 0 at one instant: coverage in [0, 1]
// on a grid of `cell` metres whose cell (0, 0) is centred at world
// (origin.x(), 0, origin.y()); x along world x, rows along world z.
struct FloorShadowMap {
  cv::Mat coverage;  // CV_32FC1; empty when no person casts a shadow
  Eigen::Vector2d origin{0, 0};
  double cell = 0.01;
  double CoverageAt(double x, double z) const;  // bilinear; 0 outside
};

// Splats every person vertex onto the floor along `light_direction` (the
// direction light travels, y < 0), closes the gaps and blurs by the softness.
FloorShadowMap MakeFloorShadowMap(const SceneFrame& frame, const Eigen::Vector3d& light_direction,
                                  const ImageEffectsOptions& options);

// Darkens the floor pixels of `color` (CV_8UC3) by the shadow map: a pixel
// whose depth (CV_32FC1, z in metres) puts it on y = 0 (within 1 cm) and
// whose `instance` (CV_16UC1) is 0.
void ApplyFloorShadows(const Camera& camera, const cv::Mat& depth, const cv::Mat& instance,
                       const FloorShadowMap& shadows, const ImageEffectsOptions& options,
                       cv::Mat* color);

// Adds the backdrop's spill (above) to the person pixels (instance != 0) of
// `color`. No-op when spill_strength is 0.
void ApplySpill(const cv::Mat& instance, const ImageEffectsOptions& options, cv::Mat* color);

// Blurs the person pixels (instance != 0) of `color` along `flow` (CV_32FC2,
// pixels to t+1; non-finite = none). No-op when the shutter is 0 or the flow
// is empty.
void ApplyMotionBlur(const cv::Mat& flow, const cv::Mat& instance,
                     const ImageEffectsOptions& options, cv::Mat* color);

}  // namespace u4d::synth
