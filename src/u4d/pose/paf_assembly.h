// Bottom-up assembly of per-view 2D skeletons from OpenPose BODY25 joint
// candidates and part-affinity scores (paper Section 2.1.1 takes 2D poses per
// view; on Shelf the published inputs are candidates + PAF scores, as written
// by the 4D Association code, io/import_fourda.h).
//
// OpenPose-style greedy assembly (Cao et al., CVPR 2017, Sec. 2.4), on the
// given scores rather than on PAF line integrals:
//  1. For each of the 26 BODY25 limbs, in the order of the file (which
//     starts at the neck and walks outwards), the candidate connections (a, b)
//     with score >= `min_paf_score` whose endpoints both have a detection
//     score >= `min_joint_score` are sorted by score (descending) and taken
//     greedily so that every candidate is used at most once per limb.
//  2. The chosen connections build people: a connection whose a-endpoint is
//     already in a person that lacks the b joint type extends it (and vice
//     versa); two people holding one endpoint each are merged when they share
//     no joint type; otherwise a new person is started. A person's score is
//     the sum of its joint scores and connection scores.
//  3. People with fewer than `min_joints` joints, or a score per joint below
//     `min_mean_score`, are dropped.
// Output: COCO-17 poses (io/poses.h Coco17FromBody25) in pixels, confidence =
// the candidate's detection score; score = mean confidence of the keypoints
// present. Candidate coordinates are normalised to [0, 1] in the file and are
// scaled by the image size (x * width, y * height).
#pragma once

#include <array>
#include <vector>

#include "u4d/io/import_fourda.h"
#include "u4d/io/poses.h"

namespace u4d {

struct PafAssemblyOptions {
  // Candidate joints below this detection score are ignored.
  double min_joint_score = 0.05;
  // Connections below this part-affinity score are ignored.
  double min_paf_score = 0.1;
  // BODY25 joints an assembled person needs.
  int min_joints = 5;
  // Minimum of (sum of joint and connection scores) / joints.
  double min_mean_score = 0.3;

  void Check() const;  // throws u4d::Error naming the bad field
};

// BODY25 limbs as joint pairs in the order of the 4D Association files.
const std::array<std::array<int, 2>, 26>& Body25Limbs();

// Assembles the people of one view and frame. Throws u4d::Error when the
// frame does not have 25 joint types and 26 limbs of matching sizes, or the
// image size is not positive.
std::vector<Pose2d> AssembleBody25(const FourdaDetectionFrame& frame, int width, int height,
                                   const PafAssemblyOptions& options = {});

}  // namespace u4d
