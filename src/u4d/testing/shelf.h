// The Shelf pipeline on the 4D Association files (import_fourda.h): per view
// BODY25 candidates + PAF scores -> per-view COCO-17 skeletons
// (paf_assembly.h) -> multi-view H36M-17 poses (multiview_pose.h) -> tracked
// and smoothed poses (pose_tracking.h); and the conversion of a predicted
// H36M-17 pose to the 14 evaluated Shelf joints.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "u4d/io/poses.h"
#include "u4d/pose/multiview_pose.h"
#include "u4d/pose/paf_assembly.h"
#include "u4d/pose/pose_tracking.h"
#include "u4d/util/file.h"

namespace u4d {

struct ShelfPipelineOptions {
  PafAssemblyOptions assembly;     // per-view 2D skeletons
  MultiViewPoseOptions multiview;  // association and triangulation
  PoseTrackerOptions tracking;     // identities and smoothing
  int max_frames = 0;              // process at most this many frames (0 = all)

  void Check() const;  // checks the nested options
};

struct ShelfPipelineResult {
  std::vector<std::vector<Pose3d>> raw;      // per frame, triangulated (ids -1)
  std::vector<std::vector<Pose3d>> tracked;  // per frame, tracked and smoothed
  std::vector<double> two_d_people;          // per frame: mean 2D people per view
};

// Runs the pipeline on `dir` (calibration.json + detection/<cam>.txt for
// every camera of the calibration). Throws u4d::Error naming the file on a
// missing or malformed file, or when the views' frame counts differ.
ShelfPipelineResult RunShelfPipeline(const fs::path& dir, const ShelfPipelineOptions& options = {});

// Shelf's 14 evaluated joints (r ankle, r knee, r hip, l hip, l knee,
// l ankle, r wrist, r elbow, r shoulder, l shoulder, l elbow, l wrist, bottom
// head, top head) from H36M-17: limbs copied; bottom head = H36M neck; top
// head = head + (head - neck), i.e. the inverse of H36m17FromShelf15's
// "head = mid(neck, head top)" (io/poses.h). Confidence 0 = missing.
std::array<Eigen::Vector4d, 14> Shelf14FromH36m17(const Pose3d& pose);

}  // namespace u4d
