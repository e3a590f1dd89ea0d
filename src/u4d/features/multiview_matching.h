// Matching of SIFT features between the calibrated views of one frame and
// linking of the pairwise matches into multi-view tracks (paper Sec. 2.1,
// sparse reconstruction).
//
// Pair matching is guided by the calibration: for a feature in view a, only
// features of view b within `max_epipolar_px` of its epipolar line are
// candidates (pixels undistorted first, geometry/epipolar.h). Among those
// candidates the nearest descriptor must pass Lowe's ratio test against the
// second nearest candidate, and (optionally) the match must be mutual: the
// nearest epipolar-consistent candidate of the view-b feature in view a is
// the same feature.
//
// Tracks: the matches of all pairs are joined with union-find over the
// features; a connected component with two features from the same view is
// inconsistent and rejected as a whole; components seen in fewer than
// `min_track_views` views are dropped.
#pragma once

#include <utility>
#include <vector>

#include "u4d/features/keypoints.h"
#include "u4d/geometry/camera.h"

namespace u4d {

struct MatchingOptions {
  double ratio = 0.8;                    // Lowe's ratio on descriptor distances (< 1)
  bool mutual = true;                    // keep only mutual nearest neighbours
  double max_epipolar_px = 2.0;          // epipolar gate in undistorted pixels
  double max_descriptor_distance = 0.7;  // absolute L2 gate (RootSIFT vectors have norm 1)
  int min_track_views = 2;               // tracks seen in fewer views are dropped (>= 2)
  // MatchAllViews matches a view only with its `neighbour_views` nearest views
  // by optical-axis angle (a pair is matched when either view lists the
  // other); wider pairs still join tracks through the views in between.
  // SIFT is unreliable beyond ~50 degrees of viewpoint change: on the 8-view
  // synthetic ring (45 degrees apart) matching all 28 pairs gave 110 points
  // with 70 % within 2 cm of GT, the 2 neighbours 79 points with 86 %.
  // 0 = all pairs.
  int neighbour_views = 2;
  // ... and only pairs whose optical axes differ by at most this (degrees,
  // in (0, 180]).
  double max_pair_angle_deg = 180.0;

  void Check() const;  // throws u4d::Error naming the field on a bad value
};

struct PairMatches {
  int view_a = 0;
  int view_b = 0;
  std::vector<std::pair<int, int>> matches;  // (keypoint in a, keypoint in b)
};

// (view, keypoint index) of one feature.
using TrackElement = std::pair<int, int>;
// Features of one scene point, at most one per view, sorted by view.
using Track = std::vector<TrackElement>;

// Guided matching of one view pair. Throws u4d::Error when the descriptors
// are not CV_32F with 128 columns.
PairMatches MatchViewPair(const Camera& camera_a, const Camera& camera_b,
                          const ViewKeypoints& keypoints_a, const ViewKeypoints& keypoints_b,
                          const MatchingOptions& options = {});

// Links pairwise matches into tracks. `num_keypoints[v]` is the number of
// features of view v; a match referring to a view or keypoint out of range
// throws u4d::Error.
std::vector<Track> LinkTracks(const std::vector<PairMatches>& pairs,
                              const std::vector<int>& num_keypoints,
                              const MatchingOptions& options = {});

// Angle in degrees between the optical axes of two cameras.
double OpticalAxisAngleDeg(const Camera& a, const Camera& b);

// The view pairs (a < b) MatchAllViews matches (see `neighbour_views`).
std::vector<std::pair<int, int>> SelectViewPairs(const std::vector<Camera>& cameras,
                                                 const MatchingOptions& options = {});

// The pairs of SelectViewPairs matched (in parallel over pairs), then linked.
// `cameras` and `keypoints` are parallel, one per view.
std::vector<Track> MatchAllViews(const std::vector<Camera>& cameras,
                                 const std::vector<ViewKeypoints>& keypoints,
                                 const MatchingOptions& options = {});

}  // namespace u4d
