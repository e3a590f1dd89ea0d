// Identities and temporal smoothing of per-frame 3D poses (paper Section
// 2.1.1: the skeletons keep their identity through the sequence).
//
// Matching. At every frame the tracks' predicted poses (last state plus
// velocity) are matched one-to-one to the frame's poses, greedily by
// increasing mean distance over the joints valid in both (at least 3 such
// joints); a pair farther than `max_match_distance` stays unmatched. With
// two or three people per frame greedy equals the optimal assignment except
// in contrived cases; the metrics (eval/) keep the Hungarian method.
// Unmatched poses start new tracks with fresh ids (0, 1, 2, ... in order of
// creation); a track unmatched for more than `max_missed_frames` frames ends.
//
// Smoothing. Per joint an alpha-beta (constant-velocity) filter, which unlike
// a plain exponential average has no lag on steady motion:
//   pred = x + v;  r = z - pred;  x = pred + alpha r;  v = v + beta r.
// Gating: a measured joint with |r| > `gate_distance` is treated as an
// outlier and ignored for this frame (x = pred) — unless the joint has been
// gated `max_gated_frames` times in a row, when the filter is reset to the
// measurement (the person really moved). A joint missing in the frame is
// predicted for up to `max_missed_frames` frames; beyond that it is reported
// missing. alpha = 1, beta = 0 turns smoothing off.
// The output confidence of a joint is the measurement's (or the last one's,
// when predicted, halved per missing frame).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "u4d/io/poses.h"

namespace u4d {

struct PoseTrackerOptions {
  // Mean joint distance (metres) above which a pose cannot continue a track.
  double max_match_distance = 0.5;
  // Frames a track (or one of its joints) survives without a measurement.
  int max_missed_frames = 5;
  // Alpha-beta filter gains, alpha in (0, 1], beta in [0, 2 - alpha) (the
  // filter's stability region). 0.7 / 0.3: no lag on constant velocity, and
  // on a static joint the output keeps ~70 % of the measurement noise
  // variance (stronger smoothing would lag behind accelerating limbs).
  double alpha = 0.7;
  double beta = 0.3;
  // Innovation (metres) above which a joint measurement is an outlier; a
  // limb swap or a wrong triangulation moves a joint by tens of centimetres,
  // while a wrist moves < 0.2 m between frames at 25 fps.
  double gate_distance = 0.3;
  // Consecutive gated frames after which the filter is reset to the measurement.
  int max_gated_frames = 2;

  void Check() const;  // throws u4d::Error naming the bad field
};

struct PoseTrack {
  int id = 0;
  int missed = 0;  // frames since the last match
  std::array<Eigen::Vector3d, 17> x, v;
  std::array<double, 17> conf{};
  std::array<int, 17> joint_missed{};  // frames since the joint was last measured
  std::array<int, 17> gated{};         // consecutive gated frames
  std::array<bool, 17> init{};         // joint has a state
};

struct PoseTrackerState {
  std::vector<PoseTrack> tracks;
  int next_id = 0;
};

// Consumes one frame's poses (ids ignored) and returns the tracked, smoothed
// poses of the tracks matched in this frame, with their track ids, in the
// order of `poses`. Throws u4d::Error on invalid options.
std::vector<Pose3d> UpdatePoseTracks(PoseTrackerState& state, const std::vector<Pose3d>& poses,
                                     const PoseTrackerOptions& options = {});

// Runs UpdatePoseTracks over a sequence (frames[t] = poses of frame t).
std::vector<std::vector<Pose3d>> TrackPoses(const std::vector<std::vector<Pose3d>>& frames,
                                            const PoseTrackerOptions& options = {});

}  // namespace u4d
