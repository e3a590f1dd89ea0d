// Synthetic camera rigs: a ring (or arc) of cameras around a look-at point.
//
// World frame y up (docs/conventions.md); cameras are u4d::Camera (x right,
// y down, z forward), pinhole, square pixels, principal point at the image
// centre ((width - 1) / 2, (height - 1) / 2 in the pixel-centre convention),
// so the look-at point projects exactly to the image centre. No distortion:
// the renderer (render.h) rasterises pinhole cameras only.
//
// View v sits at angle a_v on a horizontal circle of radius `radius` around
// the vertical axis through the look-at point, at height `height`:
//   full ring (arc_deg = 360): a_v = start + 360 * v / num_views,
//   arc (arc_deg < 360):       a_v = start + arc * v / (num_views - 1),
//   position = look_at_xz + radius * (cos a, 0, sin a) + (0, height, 0).
// Moving rigs: at time t every camera has turned by angular_speed * t around
// the axis, and its height bobs by bob_amplitude * sin(2 pi bob_frequency t +
// phase_v) with a per-view phase. Cameras always look at the look-at point.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "u4d/geometry/camera.h"

namespace u4d::synth {

struct RigOptions {
  int num_views = 8;                       // number of cameras
  double radius = 4.5;                     // ring radius (m)
  double height = 1.6;                     // camera height above the floor (m)
  Eigen::Vector3d look_at{0.0, 1.0, 0.0};  // world point every camera looks at
  int image_width = 960;                   // pixels
  int image_height = 540;                  // pixels
  double horizontal_fov_deg = 60.0;        // horizontal field of view (degrees)
  double arc_deg = 360.0;                  // angular extent of the ring; < 360 for an arc
  double start_angle_deg = 0.0;            // angle of view 0 (degrees, from +x towards +z)
  double angular_speed_deg_per_s = 0.0;    // rotation of the whole rig around the axis
  double bob_amplitude = 0.0;              // vertical bobbing amplitude (m); 0 = none
  double bob_frequency_hz = 0.5;           // bobbing frequency

  void Check() const;  // throws u4d::Error on a non-positive size/count/fov or bad values
  // True when the cameras move over time (rotation or bobbing).
  bool IsMoving() const { return angular_speed_deg_per_s != 0 || bob_amplitude != 0; }
};

// A pinhole camera at `center` looking at `target` with world `up` pointing
// up in the image; horizontal field of view in degrees. Throws when center ==
// target or the view direction is parallel to up.
Camera MakeLookAtCamera(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                        const Eigen::Vector3d& up, int width, int height,
                        double horizontal_fov_deg);

// The rig's cameras at time `time` (seconds), one per view.
std::vector<Camera> RigCameras(const RigOptions& options, double time = 0.0);

// cameras[frame][view] for frames 0..num_frames-1 at times frame / fps.
std::vector<std::vector<Camera>> RigSequence(const RigOptions& options, int num_frames, double fps);

}  // namespace u4d::synth
