#include "u4d/testing/capture_inputs.h"

#include <string>
#include <utility>

#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

namespace u4d {
namespace {

cv::Mat ReadMaskIdsIfPresent(const Capture& capture, int view, int frame) {
  const std::string& name = capture.views[view].name;
  const fs::path png = capture.root / layout::Mask(name, frame);
  if (!fs::exists(png)) return {};
  return ReadInstanceMask(png, capture.root / layout::MaskInfo(name, frame)).ids;
}

}  // namespace

std::vector<TemporalTrack> ComputeTemporalTracks(const Capture& capture,
                                                 const std::vector<std::vector<Pose3d>>& poses,
                                                 const TemporalTrackOptions& options,
                                                 int first_frame, int num_frames,
                                                 TrackStats* stats) {
  options.Check();
  if (num_frames < 0) num_frames = capture.num_frames - first_frame;
  U4D_CHECK(first_frame >= 0 && num_frames >= 1 && first_frame + num_frames <= capture.num_frames,
            "ComputeTemporalTracks: frames [{}, {}) outside the capture's [0, {})", first_frame,
            first_frame + num_frames, capture.num_frames);
  U4D_CHECK(poses.empty() || static_cast<int>(poses.size()) == num_frames,
            "ComputeTemporalTracks: {} pose frames given for {} frames", poses.size(), num_frames);
  FrameReader reader(capture);
  std::vector<TemporalTrack> all;
  for (int v = 0; v < capture.NumViews(); ++v) {
    std::vector<FrameFeatures> frames;
    std::vector<cv::Mat> masks;
    Timer timer;
    for (int k = 0; k < num_frames; ++k) {
      masks.push_back(ReadMaskIdsIfPresent(capture, v, first_frame + k));
      frames.push_back(DetectFrameFeatures(reader.Read(v, first_frame + k), masks.back(), options));
    }
    if (stats) stats->seconds_detect += timer.Seconds();
    for (TemporalTrack& t : LinkFeatureTracks(v, first_frame, frames, options, stats)) {
      all.push_back(std::move(t));
    }
    if (options.add_joint_tracks && !poses.empty()) {
      for (TemporalTrack& t : JointTracks(capture, v, first_frame, poses, masks, options)) {
        all.push_back(std::move(t));
      }
    }
  }
  return all;
}

KeyframeObservations ReadKeyframeObservations(const Capture& capture, bool ground_truth,
                                              std::vector<TemporalTrack> tracks) {
  KeyframeObservations obs;
  obs.num_frames = capture.num_frames;
  obs.masks.resize(capture.NumViews());
  for (int v = 0; v < capture.NumViews(); ++v) {
    const std::string& name = capture.views[v].name;
    for (int f = 0; f < capture.num_frames; ++f) {
      const fs::path png =
          capture.root / (ground_truth ? layout::GtInstances(name, f) : layout::Mask(name, f));
      const fs::path info = capture.root / (ground_truth ? layout::GtInstancesInfo(name, f)
                                                         : layout::MaskInfo(name, f));
      obs.masks[v].push_back(fs::exists(png) ? ReadInstanceMask(png, info) : InstanceMask{});
    }
  }
  bool any = false;
  std::vector<std::vector<Pose3d>> poses(capture.num_frames);
  for (int f = 0; f < capture.num_frames; ++f) {
    const fs::path p = capture.root / (ground_truth ? layout::GtJoints3d(f) : layout::Poses3d(f));
    if (fs::exists(p)) poses[f] = ReadPoses3d(p), any = true;
  }
  if (any) obs.poses = std::move(poses);
  obs.tracks = std::move(tracks);
  obs.Check();
  return obs;
}

JointFrameData ReadJointFrameData(const Capture& capture, FrameReader* reader, int frame,
                                  const std::vector<std::vector<Pose3d>>& poses_by_frame) {
  U4D_CHECK(frame >= 0 && frame < capture.num_frames, "ReadJointFrameData: frame {} out of [0, {})",
            frame, capture.num_frames);
  const int nv = capture.NumViews();
  auto read_masks = [&](int f) {
    std::vector<cv::Mat> masks(nv);
    for (int v = 0; v < nv; ++v) {
      const fs::path png = capture.root / layout::Mask(capture.views[v].name, f);
      if (fs::exists(png))
        masks[v] =
            ReadInstanceMask(png, capture.root / layout::MaskInfo(capture.views[v].name, f)).ids;
    }
    return masks;
  };
  auto read_images = [&](int f) {
    std::vector<cv::Mat> images(nv);
    for (int v = 0; v < nv; ++v) images[v] = reader->Read(v, f);
    return images;
  };
  JointFrameData data;
  for (int v = 0; v < nv; ++v) data.cameras_t.push_back(capture.views[v].CameraAt(frame));
  data.images_t = read_images(frame);
  data.masks_t = read_masks(frame);
  if (frame > 0) {
    data.images_prev = read_images(frame - 1);
    data.masks_prev = read_masks(frame - 1);
  }
  if (frame + 1 < capture.num_frames) {
    for (int v = 0; v < nv; ++v) data.cameras_t1.push_back(capture.views[v].CameraAt(frame + 1));
    data.images_t1 = read_images(frame + 1);
    data.masks_t1 = read_masks(frame + 1);
  }
  if (frame < static_cast<int>(poses_by_frame.size())) data.poses_t = poses_by_frame[frame];
  if (frame + 1 < static_cast<int>(poses_by_frame.size()))
    data.poses_t1 = poses_by_frame[frame + 1];
  data.sparse.resize(nv);
  return data;
}

}  // namespace u4d
