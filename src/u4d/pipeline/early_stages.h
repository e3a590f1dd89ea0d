// The stages of `u4d run` before the joint solve (pipeline.h): the 3D
// poses, the initial objects, the temporal tracks and the key-frames. Each
// Compute* writes its outputs into the scene (io/layout.h) and returns them;
// each Read* reads what an earlier run wrote. Nothing temporal crosses a cut
// in time (RunContext::Shots).
#pragma once

#include <vector>

#include "u4d/features/temporal_tracks.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/poses.h"
#include "u4d/keyframes/keyframe_similarity.h"
#include "u4d/pipeline/run_context.h"

namespace u4d {

// Per frame run, the people's 3D poses: given (ids shifted to start at 1),
// triangulated from 2D keypoints and tracked and smoothed within each shot
// (ids unique over the run, from 1), or none. Writes poses3d/.
std::vector<std::vector<Pose3d>> ComputePoses(RunContext& c);
std::vector<std::vector<Pose3d>> ReadScenePoses(const RunContext& c);

// The capture's given masks of `frame`, per view (an empty mask where a view
// has none). Throws naming the file on a bad mask or a size that is not the
// camera's.
std::vector<InstanceMask> ReadGivenMasks(const RunContext& c, int frame);

// Per frame, the initial objects (initial/): from the given masks or the
// unsupervised chain, named by the poses, the ground-plane step or the
// object linker (whose links a cut ends). Returns the frames done and lists
// the frames with no object in c.log.empty_frames.
int ComputeInitialObjects(RunContext& c, const std::vector<std::vector<Pose3d>>& poses);

// A run with no object in any frame fails (unless allowed) with what would
// help; one with some empty frames warns. Called after the initial stage is
// recorded, so that a rerun with allow_empty resumes from it.
void CheckNotEmpty(const RunContext& c);

// Per view, feature tracks (and joint tracks with poses) linked within
// chunks of track_chunk_frames inside each shot. Writes tracks/.
std::vector<TemporalTrack> ComputeTracks(RunContext& c,
                                         const std::vector<std::vector<Pose3d>>& poses);
std::vector<TemporalTrack> ReadSceneTracks(const RunContext& c);

// The key-frames (paper Eq. 3, keyframes/), chosen within each shot, so
// that no segment spans a cut. Writes keyframes.json.
KeyframeSelection ComputeKeyframes(RunContext& c, const std::vector<std::vector<Pose3d>>& poses,
                                   const std::vector<TemporalTrack>& tracks);

}  // namespace u4d
