// Multi-view triangulation of feature tracks into sparse 3D points, and their
// assignment to object instances (paper Sec. 2.1, sparse reconstruction; the
// sparse points seed the SCSR-style initial reconstruction, object_regions.h).
//
// Per track: linear triangulation (TriangulateDlt), then Levenberg-Marquardt
// on the three coordinates minimising the squared reprojection error with
// the full (distorting) camera model. Outliers: while the worst observation
// reprojects farther than `max_reprojection_px`, it is dropped and the point
// re-estimated; the point is discarded when fewer than `min_views`
// observations remain, when it lies behind an observing camera (cheirality),
// or when the largest angle between its viewing rays is below
// `min_triangulation_angle_deg` (depth poorly constrained).
//
// Instances. The per-view initial masks number their instances
// independently (a detector does not know identities), so the ids are first
// associated across views (AssociateInstances): two per-view instances are
// linked by every sparse point observed inside both; pairs are merged
// greedily by decreasing link count (at least `min_links`) into objects,
// never putting two instances of one view into one object, nor two instances
// of different classes when the detector's classes are given (a box seen in
// one view and a ball seen in another are two objects). A point's object
// is then the majority vote over its observations (background, 0, counts as
// a vote; a tie goes to the smallest object id other than background;
// per-view ids not associated with any object abstain).
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/features/keypoints.h"
#include "u4d/features/multiview_matching.h"
#include "u4d/geometry/camera.h"

namespace u4d {

struct SparseOptions {
  double max_reprojection_px = 2.0;          // observations reprojecting farther are dropped
  double min_triangulation_angle_deg = 1.5;  // largest ray angle a point must reach
  int min_views = 2;                         // observations a point keeps at least (>= 2)
  int refine_iterations = 10;                // Levenberg-Marquardt iterations per estimate
  int min_links = 3;                         // AssociateInstances: points linking two instances

  void Check() const;  // throws u4d::Error naming the field on a bad value
};

struct SparsePoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world, metres
  int instance = 0;  // object id (AssociateInstances), 0 = background / unknown
  std::vector<std::pair<int, int>> observations;  // (view, keypoint), sorted by view
  std::vector<Eigen::Vector2d> pixels;            // the observed pixels, parallel
  double reprojection_rmse = 0;                   // pixels, over the kept observations
};

// Triangulates and refines every track (in parallel); returns the surviving
// points. `cameras` and `keypoints` are parallel, one per view; a track
// referring to a view or keypoint out of range throws u4d::Error.
std::vector<SparsePoint> TriangulateTracks(const std::vector<Camera>& cameras,
                                           const std::vector<ViewKeypoints>& keypoints,
                                           const std::vector<Track>& tracks,
                                           const SparseOptions& options = {});

// Per-view instance id -> object id (>= 1) of the objects found across views.
struct InstanceAssociation {
  int num_objects = 0;
  std::vector<std::map<int, int>> object_of;  // [view][mask id] -> object id
  int ObjectOf(int view, int mask_id) const;  // 0 when unassociated or background
};

// The detector's class of each instance: [view][mask id] -> class name. An
// instance without an entry has the class "" (alike only to another "").
using InstanceClasses = std::vector<std::map<int, std::string>>;
std::string ClassOf(const InstanceClasses& classes, int view, int mask_id);

// `masks[v]` is the initial instance id image of view v (any integer type,
// 0 = background); an empty Mat means no detections in that view. Objects
// are numbered 1..K by decreasing number of points. `classes` (null: all
// alike) keeps instances of different classes apart. Throws u4d::Error when
// the number of masks differs from the number of views seen in `points`, a
// mask's size differs from its camera's, or `classes` has another length.
InstanceAssociation AssociateInstances(const std::vector<Camera>& cameras,
                                       const std::vector<cv::Mat>& masks,
                                       const std::vector<SparsePoint>& points,
                                       const SparseOptions& options = {},
                                       const InstanceClasses* classes = nullptr);

// Sets each point's `instance` by majority vote (see the header comment).
// A background observation on a pixel of `unknown` (null, or one Mat per
// view, empty = none: detections of another class, which may hide or hold
// the object) abstains instead.
void AssignInstances(const std::vector<cv::Mat>& masks, const InstanceAssociation& association,
                     std::vector<SparsePoint>& points,
                     const std::vector<cv::Mat>* unknown = nullptr);

// The mask id at a (distorted) pixel, nearest pixel; 0 outside the image or
// for an empty mask.
int MaskIdAt(const cv::Mat& mask, const Eigen::Vector2d& pixel);

// ---- one frame, all stages ----

struct SparseFrameOptions {
  KeypointOptions keypoints;           // detection
  MatchingOptions matching;            // pair matching and track linking
  SparseOptions sparse;                // triangulation, outliers, instances
  int detection_mask_dilation_px = 4;  // features only near initial masks; < 0 = whole image

  void Check() const;
};

struct SparseFrame {
  std::vector<ViewKeypoints> keypoints;  // per view
  std::vector<Track> tracks;             // before triangulation
  std::vector<SparsePoint> points;
  InstanceAssociation association;
  double seconds_detect = 0, seconds_match = 0, seconds_triangulate = 0, seconds_assign = 0;
};

// Runs detection, matching, triangulation and instance assignment on one
// frame. `images`, `masks` and `cameras` are parallel (masks may be empty
// Mats, then detection covers the whole image of that view).
SparseFrame ReconstructSparseFrame(const std::vector<Camera>& cameras,
                                   const std::vector<cv::Mat>& images,
                                   const std::vector<cv::Mat>& masks,
                                   const SparseFrameOptions& options = {});

}  // namespace u4d
