// Surface points of the visual hull of instance masks: the silhouette points
// that join the feature points when objects are associated across views
// without poses (pipeline/initial_objects.h), for wide-baseline rigs where
// feature matches are few.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "u4d/features/sparse_points.h"
#include "u4d/geometry/camera.h"

namespace u4d {

struct SilhouettePointOptions {
  int max_side = 160;         // masks are tested at this longest side (pixels)
  int pixels_per_view = 400;  // rays cast per view (a regular sample of its foreground)
  int depth_samples = 192;    // depths per ray, even in inverse depth
  double min_depth_m = 0.3;   // nearest depth tested
  int min_views_seeing = 2;   // other views that must see a point (inside their image)
  // Share of the other views seeing a point that must hold it in their
  // foreground: a detector misses a person in some views, and one such view
  // must not carve that person out of every view's hull.
  double min_foreground_share = 0.75;
  void Check() const;
};

// Points on the visual hull of the union of the masks: for sampled
// foreground pixels of every view, the first depth along the ray whose point
// projects into the foreground of at least min_foreground_share of the other
// views that see it (at least min_views_seeing of them; a view whose mask
// holds no foreground at all, where the detector found nobody, does not
// vote, like an absent mask); observations are the views it projects
// into the foreground of, with their pixels (full resolution). The farthest depth is 1.5 x the
// largest distance between two cameras (at least 5 m). `unknown` (null, or
// one Mat per view, empty = none) marks pixels where a view cannot tell:
// the detections of another class (people, when the masks hold the objects
// they carry) may hide an object or hold it merged, so a point projecting
// there abstains in that view (neither seeing nor holding) instead of being
// carved away. Throws u4d::Error on mismatched counts or sizes.
std::vector<SparsePoint> SilhouettePoints(const std::vector<Camera>& cameras,
                                          const std::vector<cv::Mat>& masks,
                                          const SilhouettePointOptions& options = {},
                                          const std::vector<cv::Mat>* unknown = nullptr);

}  // namespace u4d
