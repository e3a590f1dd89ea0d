// The inputs of the algorithms read whole from a capture on disk, for the
// tests and the benches: the pipeline (pipeline/) reads and caches them its
// own way, segment by segment, and the algorithms take them in memory.
#pragma once

#include <vector>

#include "u4d/features/temporal_tracks.h"
#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/poses.h"
#include "u4d/joint/frame_setup.h"
#include "u4d/keyframes/keyframe_similarity.h"

namespace u4d {

// Everything for frames [first_frame, first_frame + num_frames) of every view:
// images through FrameReader, masks from masks/<view>/<frame>.png (+ .json)
// when present (a missing file = no mask for that frame), 3D poses from
// `poses` (indexed by k = frame - first_frame; empty = none). num_frames < 0
// means to the end. Throws on a bad range.
std::vector<TemporalTrack> ComputeTemporalTracks(const Capture& capture,
                                                 const std::vector<std::vector<Pose3d>>& poses,
                                                 const TemporalTrackOptions& options,
                                                 int first_frame = 0, int num_frames = -1,
                                                 TrackStats* stats = nullptr);

// Observations of a capture: masks from gt/instances (ground_truth) or masks/
// (a missing file = nothing detected), poses from gt/joints3d or poses3d/ (a
// missing file = no poses that frame), and the given tracks.
KeyframeObservations ReadKeyframeObservations(const Capture& capture, bool ground_truth,
                                              std::vector<TemporalTrack> tracks);

// Reads frame `frame` of a capture (with t−1 and t+1 when they exist): images,
// the initial masks in masks/ (views without a mask file get none) and the
// given poses of t and t+1 (`poses_by_frame[f]`, may be empty). Sparse
// correspondences are left empty for the caller. Throws u4d::Error naming the
// file on a missing or corrupt frame.
JointFrameData ReadJointFrameData(const Capture& capture, FrameReader* reader, int frame,
                                  const std::vector<std::vector<Pose3d>>& poses_by_frame);

}  // namespace u4d
