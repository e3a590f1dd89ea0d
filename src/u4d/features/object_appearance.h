// The colours an object wears, seen by all views at one frame: what tells
// people apart when their positions say nothing (after a cut in time, where
// ObjectLinker re-identifies them, pipeline/initial_objects.h).
//
// A person's clothes differ above and below the waist more than across a
// shirt, and the waist is near the middle of a standing person's image, so
// the object's pixels in each view are split at the middle row of their
// extent into an upper and a lower band, and each band is summarised by its
// mean CIE L*a*b* colour (perceptually uniform: a distance in it is a colour
// difference, Delta E 1976). The bands are averaged over the views, each
// weighted by its pixel count, so a view that sees much of the person counts
// most. The mean, not a histogram: the masks of a detector or of the
// unsupervised step leak onto the background and drop parts, which a mean
// over thousands of pixels absorbs.
#pragma once

#include <map>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace u4d {

struct ObjectAppearance {
  Eigen::Vector3d upper = Eigen::Vector3d::Zero();  // mean L*a*b* above the middle row
  Eigen::Vector3d lower = Eigen::Vector3d::Zero();  // and below it
  double pixels = 0;                                // pixels it is the mean of, all views
};

// Per object id (>= 1) of `ids` (per view CV_16UC1, empty = no mask), its
// appearance in `images` (per view CV_8UC3 BGR, the size of its ids).
// Objects without a pixel are absent. Throws u4d::Error naming the view on
// mismatched counts, sizes or types.
std::map<int, ObjectAppearance> ObjectAppearances(const std::vector<cv::Mat>& images,
                                                  const std::vector<cv::Mat>& ids);

// The colour difference of two appearances: the mean of the two bands'
// Delta E (CIE 1976) distances.
double AppearanceDistance(const ObjectAppearance& a, const ObjectAppearance& b);

// The pixel-weighted mean of two appearances (a track's running appearance).
ObjectAppearance MeanAppearance(const ObjectAppearance& a, const ObjectAppearance& b);

}  // namespace u4d
