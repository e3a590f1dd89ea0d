// Key-frames against ground-truth 3D poses (paper Sec. 2.1.3: a key-frame
// should stand for frames whose poses recur). Used by keyframes_gt_test and
// bench/keyframes_bench.cc; not part of the pipeline.
//
// GT pose distance of frames (a, b): for each person present in both
// (matched by person_id), the mean over the 17 H36M joints of
// |(x_a - pelvis_a) - (x_b - pelvis_b)| in metres (root-relative MPJPE, world
// axes: a person facing the other way has a different pose), averaged over
// those people. Joints with confidence 0 are skipped; a person with fewer than
// 8 common joints, and a frame pair with no common person, is not evaluated.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "u4d/io/poses.h"
#include "u4d/keyframes/keyframe_similarity.h"

namespace u4d {

// The distance above; NaN when no person can be compared.
double GtPoseDistance(const std::vector<Pose3d>& a, const std::vector<Pose3d>& b);

// The N x N matrix of GtPoseDistance over frames (NaN where undefined).
Eigen::MatrixXd GtPoseDistanceMatrix(const std::vector<std::vector<Pose3d>>& gt_poses);

struct KeyframeGtEvaluation {
  int num_keyframes = 0;
  int members = 0;      // frames t with frame_keyframe[t] != t (and a defined distance)
  double mean_all = 0;  // mean GT pose distance over all frame pairs a < b
  double median_all = 0;
  double mean_member = 0;  // mean over members of the distance to their own key-frame
  double median_member = 0;
  double max_member = 0;
  // Baseline with the same number of key-frames and no image evidence: the
  // frames cut into equal temporal segments, each frame assigned to its
  // segment's middle frame. Mean over its members as above.
  double mean_member_uniform = 0;
  // Recurrences: members further than `recurrence_gap` frames from their
  // key-frame (beyond the reach of the temporal tracks, so sent back by
  // pose/shape similarity), and their mean GT distance to it.
  int recurring_members = 0;
  double mean_recurring = 0;
  double MemberRatio() const { return mean_all > 0 ? mean_member / mean_all : 0; }
};

// Compares `selection` (frame_keyframe) with the GT pose distances `gt`
// (GtPoseDistanceMatrix). Throws when the sizes differ.
KeyframeGtEvaluation EvaluateKeyframesWithGtPoses(const KeyframeSelection& selection,
                                                  const Eigen::MatrixXd& gt,
                                                  int recurrence_gap = 10);

}  // namespace u4d
