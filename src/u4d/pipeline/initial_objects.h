// The objects a run reconstructs, per frame, before the joint optimisation:
// the initial instance masks turned into object-id masks (the same id for the
// same person in every view and frame) and, without poses, each view's depth
// range per object.
//
// With 3D poses (tracked people, person_id >= 1): a detector instance takes
// the person whose projected joints fall inside it most often
// (joint/frame_setup.h AssignInstancesToPeople); the joint optimisation then
// draws each person's region and depth range from the joints.
//
// Without poses: the paper's sparse reconstruction of the frame
// (features/sparse_points.h ReconstructSparseFrame) associates the per-view
// instances across views into objects, and features/object_regions.h gives
// each object's depth range per view (sparse points, else the visual hull).
// Identities through time: an object takes the id of the previous frame's
// object whose sparse-point centroid is nearest, when within
// `max_centroid_jump_m` (greedy, nearest pairs first); otherwise a new id.
//
// Files (io/layout.h): initial/masks/<view>/<frame>.png (16-bit ids, an
// absent file = no mask in that view) and initial/objects/<frame>.json
// {"frame", "objects": [{"id", "centroid": [x,y,z] | null}],
//  "depth_ranges": {"<view>": {"<id>": [near, far]}}}.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/features/object_regions.h"
#include "u4d/features/sparse_points.h"
#include "u4d/io/poses.h"
#include "u4d/joint/frame_setup.h"
#include "u4d/util/file.h"

namespace u4d {

struct FrameObjects {
  std::vector<cv::Mat> ids;  // per view: CV_16U object ids at camera size; empty = no mask
  // Per view: object id -> (near, far) metres; filled without poses only.
  std::vector<std::map<int, std::pair<double, double>>> depth_ranges;
  std::map<int, Eigen::Vector3d> centroids;  // object id -> world centroid (without poses)
  int num_sparse_points = 0;                 // points of the frame's sparse reconstruction
};

// Identity state carried from frame to frame (no poses).
struct ObjectLinker {
  double max_centroid_jump_m = 0.5;  // farther centroids are different objects
  std::map<int, Eigen::Vector3d> previous;
  int next_id = 1;
};

// With poses: `masks[v]` detector ids (empty = none) -> object ids.
FrameObjects ObjectsFromPoses(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& masks,
                              const std::vector<Pose3d>& poses, const FrameSetupOptions& options);

// Without poses: see above. Throws u4d::Error on mismatched sizes.
FrameObjects ObjectsFromSparse(const std::vector<Camera>& cameras,
                               const std::vector<cv::Mat>& images,
                               const std::vector<cv::Mat>& masks,
                               const SparseFrameOptions& sparse_options,
                               const ObjectRegionOptions& region_options, ObjectLinker* linker);

// Writes / reads the files above for `frame` under the scene root `out`.
// Reading a frame never written throws u4d::Error naming the file.
void WriteFrameObjects(const fs::path& out, const std::vector<std::string>& view_names, int frame,
                       const FrameObjects& objects);
FrameObjects ReadFrameObjects(const fs::path& out, const std::vector<std::string>& view_names,
                              int frame);

}  // namespace u4d
