#include "u4d/synth/rig.h"

#include <cmath>

#include <Eigen/Geometry>

#include "u4d/util/check.h"

namespace u4d::synth {

void RigOptions::Check() const {
  U4D_CHECK(num_views >= 1, "RigOptions: num_views must be >= 1, got {}", num_views);
  U4D_CHECK(std::isfinite(radius) && radius > 0, "RigOptions: radius must be > 0, got {}", radius);
  U4D_CHECK(std::isfinite(height), "RigOptions: height must be finite");
  U4D_CHECK(look_at.allFinite(), "RigOptions: look_at must be finite");
  U4D_CHECK(image_width > 0 && image_height > 0,
            "RigOptions: image size must be positive, got {}x{}", image_width, image_height);
  U4D_CHECK(horizontal_fov_deg > 0 && horizontal_fov_deg < 179,
            "RigOptions: horizontal_fov_deg must be in (0, 179), got {}", horizontal_fov_deg);
  U4D_CHECK(arc_deg > 0 && arc_deg <= 360, "RigOptions: arc_deg must be in (0, 360], got {}",
            arc_deg);
  U4D_CHECK(std::isfinite(start_angle_deg) && std::isfinite(angular_speed_deg_per_s),
            "RigOptions: angles must be finite");
  U4D_CHECK(std::isfinite(bob_amplitude) && bob_amplitude >= 0,
            "RigOptions: bob_amplitude must be >= 0, got {}", bob_amplitude);
  U4D_CHECK(std::isfinite(bob_frequency_hz) && bob_frequency_hz >= 0,
            "RigOptions: bob_frequency_hz must be >= 0, got {}", bob_frequency_hz);
}

Camera MakeLookAtCamera(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                        const Eigen::Vector3d& up, int width, int height,
                        double horizontal_fov_deg) {
  U4D_CHECK(width > 0 && height > 0, "MakeLookAtCamera: image size must be positive, got {}x{}",
            width, height);
  U4D_CHECK(horizontal_fov_deg > 0 && horizontal_fov_deg < 179,
            "MakeLookAtCamera: horizontal fov must be in (0, 179) degrees, got {}",
            horizontal_fov_deg);
  const Eigen::Vector3d to_target = target - center;
  U4D_CHECK(to_target.norm() > 1e-9, "MakeLookAtCamera: camera centre equals the target");
  const Eigen::Vector3d forward = to_target.normalized();
  const Eigen::Vector3d side = forward.cross(up);
  U4D_CHECK(side.norm() > 1e-9, "MakeLookAtCamera: view direction is parallel to up");
  const Eigen::Vector3d right = side.normalized();    // camera x
  const Eigen::Vector3d down = forward.cross(right);  // camera y (z cross x = y)
  Camera cam;
  cam.width = width;
  cam.height = height;
  const double f = 0.5 * width / std::tan(0.5 * horizontal_fov_deg * M_PI / 180.0);
  cam.K << f, 0, 0.5 * (width - 1), 0, f, 0.5 * (height - 1), 0, 0, 1;
  cam.cam_from_world.rotation.row(0) = right.transpose();
  cam.cam_from_world.rotation.row(1) = down.transpose();
  cam.cam_from_world.rotation.row(2) = forward.transpose();
  cam.cam_from_world.translation = -cam.cam_from_world.rotation * center;
  return cam;
}

std::vector<Camera> RigCameras(const RigOptions& o, double time) {
  o.Check();
  U4D_CHECK(std::isfinite(time), "RigCameras: time must be finite");
  std::vector<Camera> cameras;
  cameras.reserve(o.num_views);
  for (int v = 0; v < o.num_views; ++v) {
    const double step = o.arc_deg >= 360.0 ? 360.0 / o.num_views
                                           : (o.num_views > 1 ? o.arc_deg / (o.num_views - 1) : 0);
    const double angle =
        (o.start_angle_deg + step * v + o.angular_speed_deg_per_s * time) * M_PI / 180.0;
    const double phase = 2.399963 * v;  // golden angle: views bob out of phase
    const double bob = o.bob_amplitude * std::sin(2 * M_PI * o.bob_frequency_hz * time + phase);
    const Eigen::Vector3d center(o.look_at.x() + o.radius * std::cos(angle), o.height + bob,
                                 o.look_at.z() + o.radius * std::sin(angle));
    cameras.push_back(MakeLookAtCamera(center, o.look_at, Eigen::Vector3d::UnitY(), o.image_width,
                                       o.image_height, o.horizontal_fov_deg));
  }
  return cameras;
}

std::vector<std::vector<Camera>> RigSequence(const RigOptions& options, int num_frames,
                                             double fps) {
  U4D_CHECK(num_frames >= 0, "RigSequence: num_frames must be >= 0, got {}", num_frames);
  U4D_CHECK(std::isfinite(fps) && fps > 0, "RigSequence: fps must be > 0, got {}", fps);
  std::vector<std::vector<Camera>> out;
  out.reserve(num_frames);
  for (int f = 0; f < num_frames; ++f) out.push_back(RigCameras(options, f / fps));
  return out;
}

}  // namespace u4d::synth
