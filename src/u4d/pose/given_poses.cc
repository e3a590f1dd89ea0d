#include "u4d/pose/given_poses.h"

#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d {

std::vector<std::vector<Pose3d>> ReadGivenPoses3d(const fs::path& capture_root, int num_frames,
                                                  bool allow_missing) {
  U4D_CHECK(num_frames >= 0, "ReadGivenPoses3d: num_frames must be >= 0, got {}", num_frames);
  std::vector<std::vector<Pose3d>> frames(num_frames);
  for (int f = 0; f < num_frames; ++f) {
    const fs::path path = capture_root / layout::Poses3d(f);
    if (allow_missing && !fs::exists(path)) continue;
    U4D_CHECK(fs::exists(path), "{}: given 3D poses of frame {} not found", path.string(), f);
    frames[f] = ReadPoses3d(path);
  }
  return frames;
}

}  // namespace u4d
