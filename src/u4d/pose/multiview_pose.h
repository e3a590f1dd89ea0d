// Multi-view 3D human pose from per-view 2D keypoints (paper Section 2.1.1:
// the 3D skeletons that seed the 4D reconstruction). Input: per view the
// COCO-17 detections of one frame (pixels as seen in the image, i.e.
// distorted; confidence 0 = missing) and the view's camera. Output: one 3D
// pose per person seen in at least `min_views` views, in the internal
// Human3.6M-17 skeleton (io/poses.h), ids -1 (identities through time are
// pose_tracking.h's job).
//
// Method:
//  1. Pairwise affinity. For two detections in two views, the mean symmetric
//     epipolar distance (pixels, on undistorted pixels, EpipolarDistance in
//     both directions) over the keypoints confident in both. Detectors swap
//     left and right, so the distance is also computed with the second
//     detection mirrored (Coco17Mirror pairs exchanged) and the smaller is kept.
//     Pairs sharing fewer than `min_shared_keypoints` keypoints get no affinity.
//  2. Association. Candidate pairs with a distance below
//     `max_epipolar_distance` are merged greedily, closest first, into
//     clusters (union-find) under two constraints: a cluster holds at most one
//     detection per view, and the mean distance over all cross pairs of the
//     two clusters that have an affinity (average linkage) stays below the
//     threshold. Clusters with fewer than `min_views` views are dropped.
//  3. Left/right swaps, greedily with leave-one-out: for every view of the
//     cluster the other views are triangulated (step 4) and the view's
//     detection and its mirror are reprojection-tested against that skeleton;
//     the view whose alternative has the smallest error ratio, when below
//     `mirror_gain`, is flipped, and the step repeats (at most once per view)
//     until no view gains. Clusters of 2 views cannot be judged this way.
//  4. Robust triangulation per COCO joint: the views where the joint is
//     confident. With 3+ views, every pair of views is triangulated
//     (TriangulateDlt) as a hypothesis and the one with the most views
//     reprojecting within `max_reprojection_error` (ties: smaller summed
//     error) wins (exhaustive RANSAC; a person is seen by few views); the
//     inliers are re-triangulated with the DLT weighted by confidence. A
//     joint with fewer than 2 inliers, or whose inlier rays meet at less than
//     `min_triangulation_angle_deg`, is missing. Its confidence is the mean
//     2D confidence of its inliers.
//  5. COCO-17 -> H36M-17 by H36m17FromCoco17 (io/poses.h): pelvis, thorax,
//     spine, neck and the head centre are built from hips, shoulders, ears /
//     eyes / nose. A person with fewer than `min_joints` triangulated COCO
//     joints is dropped.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "u4d/geometry/camera.h"
#include "u4d/io/poses.h"

namespace u4d {

struct MultiViewPoseOptions {
  // 2D keypoints below this confidence count as missing.
  double min_keypoint_confidence = 0.1;
  // Association threshold on the mean symmetric epipolar distance, as a
  // fraction of the image width (0.03 -> 31 px at 1032 px, 9.6 px at 320 px);
  // resolution independent so one default fits small and large images.
  double max_epipolar_distance = 0.03;
  // Keypoints confident in both detections needed for a pairwise affinity.
  int min_shared_keypoints = 4;
  // Views a person must be associated in to be triangulated.
  int min_views = 2;
  // Inlier threshold of the per-joint RANSAC, fraction of the image width
  // (0.02 -> 21 px at 1032 px, 6.4 px at 320 px).
  double max_reprojection_error = 0.02;
  // A view's detection is mirrored when its mirror reprojects with less than
  // this fraction of its own error; 1 disables the test's margin, 0 disables
  // mirroring.
  double mirror_gain = 0.7;
  // A joint needs two inlier views whose rays meet at least at this angle
  // (folded: opposite cameras count as parallel); 2 px of noise moves a
  // 10-degree intersection by ~6x more along the rays than across them.
  double min_triangulation_angle_deg = 10;
  // Triangulated COCO joints a person needs to be reported.
  int min_joints = 6;

  void Check() const;  // throws u4d::Error naming the bad field
};

// One person found in a frame.
struct MultiViewPerson {
  std::vector<int> detections;           // per view: index into that view's detections, -1 = none
  std::vector<bool> mirrored;            // per view: the detection was used left/right mirrored
  std::array<Eigen::Vector4d, 17> coco;  // triangulated COCO-17 (x, y, z, conf), conf 0 = missing
  Pose3d pose;                           // H36M-17 (person_id -1)
  double reprojection_error = 0;         // mean inlier reprojection error over joints, pixels
};

// The COCO-17 keypoints with left and right exchanged.
Keypoints2d MirrorCoco17(const Keypoints2d& keypoints);

// Steps 1-2: clusters of detections, each a vector over views (index or -1).
// `poses` and `cameras` have one entry per view; throws u4d::Error when their
// sizes differ or a camera fails Camera::Check.
std::vector<std::vector<int>> AssociatePoses(const std::vector<std::vector<Pose2d>>& poses,
                                             const std::vector<Camera>& cameras,
                                             const MultiViewPoseOptions& options = {});

// Steps 1-5.
std::vector<MultiViewPerson> EstimateMultiViewPoses(const std::vector<std::vector<Pose2d>>& poses,
                                                    const std::vector<Camera>& cameras,
                                                    const MultiViewPoseOptions& options = {});

// Convenience: the H36M-17 poses of EstimateMultiViewPoses.
std::vector<Pose3d> TriangulatePoses(const std::vector<std::vector<Pose2d>>& poses,
                                     const std::vector<Camera>& cameras,
                                     const MultiViewPoseOptions& options = {});

}  // namespace u4d
