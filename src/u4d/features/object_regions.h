// The initial per-object reconstruction regions (the SCSR-style
// initialisation of paper Sec. 2.1): for every object found by
// AssociateInstances (sparse_points.h) and every view, the image region in
// which the object's depth will be reconstructed and the depth range
// [depth_near, depth_far] (z in that camera, metres) to search.
//
// Region: the union of the view's initial-mask instances associated with the
// object. Human-pose constraint: when 3D joints of the person are given (H36M
// order, io/poses.h), every bone with an end joint that projects outside the
// region is drawn into it as a thick segment (radius `limb_radius_m` at the
// joints' depth), so a limb the detector dropped (e.g. a forearm) is added
// back; pixels of another object's region are never taken. A view where the
// object was not detected gets the drawn skeleton alone (or nothing).
//
// Depth range, first that applies:
//   kSparsePoints: >= min_points of the object's sparse points observed in the
//     view: the [percentile_near, percentile_far] percentiles of their depths,
//     widened by depth_margin_m on each side;
//   kJoints: the joints' depths widened by joint_depth_margin_m;
//   kVisualHull: depths along the rays of (a sample of) the region's pixels
//     whose 3D point projects inside the object's region in every other view
//     that detected it (outside the image constrains nothing), widened by
//     depth_margin_m;
//   kNone: [hull_near_m, hull_far_m].
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/features/silhouette_points.h"
#include "u4d/features/sparse_points.h"
#include "u4d/io/poses.h"

namespace u4d {

struct ObjectRegionOptions {
  double percentile_near = 0.02;      // depth percentile giving depth_near (in [0, 1])
  double percentile_far = 0.98;       // depth percentile giving depth_far (>= percentile_near)
  double depth_margin_m = 0.25;       // margin on both sides (body thickness, sparse coverage)
  int min_points = 10;                // fewer points in a view -> fallback depth range
  double joint_depth_margin_m = 0.3;  // margin around the joints' depth range
  double limb_radius_m = 0.07;        // half-width of a bone drawn by the pose constraint
  double min_joint_confidence = 0.1;  // joints below this confidence are ignored
  double hull_near_m = 0.2;           // visual hull search: nearest depth
  double hull_far_m = 30.0;           // visual hull search: farthest depth
  int hull_depth_steps = 256;         // depth samples per ray (geometric spacing)
  int hull_max_pixels = 400;          // rays sampled per region
  // The visual hull's surface points that join the feature points without
  // poses (pipeline/initial_objects.h ObjectsFromSparse).
  SilhouettePointOptions silhouette;

  void Check() const;  // throws u4d::Error naming the field on a bad value
};

enum class DepthSource { kSparsePoints, kJoints, kVisualHull, kNone };
std::string ToString(DepthSource source);

struct ObjectRegion {
  int instance = 0;       // object id (AssociateInstances), >= 1
  int view = 0;           // view index
  bool detected = false;  // the initial masks of this view contain the object
  cv::Mat mask;           // CV_8U, 255 inside the region, camera size
  double depth_near = 0;  // metres, z in the camera
  double depth_far = 0;   // metres
  DepthSource depth_source = DepthSource::kNone;
  int num_points = 0;         // sparse points of the object observed in this view
  int pose_added_pixels = 0;  // pixels added by the human-pose constraint
};

// For each pose, the object it belongs to (0 if none): the object whose
// regions contain most of the pose's projected joints over all views.
std::vector<int> AssociatePoses(const std::vector<Camera>& cameras,
                                const std::vector<cv::Mat>& masks,
                                const InstanceAssociation& association,
                                const std::vector<Pose3d>& poses,
                                const ObjectRegionOptions& options = {});

// Regions of all objects: result[object - 1][view]. `masks` as for
// AssociateInstances; `poses` may be empty. Throws u4d::Error on mismatched
// sizes.
std::vector<std::vector<ObjectRegion>> InitialObjectRegions(
    const std::vector<Camera>& cameras, const std::vector<cv::Mat>& masks,
    const InstanceAssociation& association, const std::vector<SparsePoint>& points,
    const std::vector<Pose3d>& poses, const ObjectRegionOptions& options = {});

}  // namespace u4d
