#include "u4d/testing/shelf.h"

#include <algorithm>

#include "u4d/io/import_calibration.h"
#include "u4d/io/import_fourda.h"
#include "u4d/util/check.h"

namespace u4d {

void ShelfPipelineOptions::Check() const {
  assembly.Check();
  multiview.Check();
  tracking.Check();
  U4D_CHECK(max_frames >= 0, "ShelfPipelineOptions.max_frames must be >= 0, got {}", max_frames);
}

ShelfPipelineResult RunShelfPipeline(const fs::path& dir, const ShelfPipelineOptions& options) {
  options.Check();
  const std::vector<NamedCamera> named = ReadFourdaCalibration(dir / "calibration.json");
  U4D_CHECK(named.size() >= 2, "{}: need at least 2 cameras, found {}",
            (dir / "calibration.json").string(), named.size());
  std::vector<Camera> cameras;
  std::vector<FourdaDetections> detections;
  for (const NamedCamera& c : named) {
    cameras.push_back(c.camera);
    detections.push_back(ReadFourdaDetections(dir / "detection" / (c.name + ".txt")));
    U4D_CHECK(detections.back().frames.size() == detections.front().frames.size(),
              "{}: {} frames, but view {} has {}", (dir / "detection" / (c.name + ".txt")).string(),
              detections.back().frames.size(), named.front().name,
              detections.front().frames.size());
  }
  int frames = static_cast<int>(detections.front().frames.size());
  if (options.max_frames > 0) frames = std::min(frames, options.max_frames);
  ShelfPipelineResult result;
  PoseTrackerState tracker;
  for (int f = 0; f < frames; ++f) {
    std::vector<std::vector<Pose2d>> poses(cameras.size());
    double people = 0;
    for (size_t v = 0; v < cameras.size(); ++v) {
      poses[v] = AssembleBody25(detections[v].frames[f], cameras[v].width, cameras[v].height,
                                options.assembly);
      people += poses[v].size();
    }
    result.two_d_people.push_back(people / cameras.size());
    result.raw.push_back(TriangulatePoses(poses, cameras, options.multiview));
    result.tracked.push_back(UpdatePoseTracks(tracker, result.raw.back(), options.tracking));
  }
  return result;
}

std::array<Eigen::Vector4d, 14> Shelf14FromH36m17(const Pose3d& pose) {
  using namespace h36m17;
  static constexpr int kLimbJoints[12] = {kRightAnkle,    kRightKnee,    kRightHip,   kLeftHip,
                                          kLeftKnee,      kLeftAnkle,    kRightWrist, kRightElbow,
                                          kRightShoulder, kLeftShoulder, kLeftElbow,  kLeftWrist};
  std::array<Eigen::Vector4d, 14> out;
  for (int i = 0; i < 12; ++i) out[i] = pose.joints[kLimbJoints[i]];
  const Eigen::Vector4d& neck = pose.joints[kNeck];
  const Eigen::Vector4d& head = pose.joints[kHead];
  out[12] = neck;
  if (neck.w() > 0 && head.w() > 0) {
    out[13] << 2 * head.head<3>() - neck.head<3>(), std::min(neck.w(), head.w());
  } else {
    out[13].setZero();
  }
  return out;
}

}  // namespace u4d
