// Multi-view support of the objects' regions (issue 22, "missing parts come
// back"): a part of a person that one view's initial mask misses (a dropped
// arm, a cut-off head) is still held by the other views' masks. Its pixels in
// the view are those whose ray meets the object's visual hull built from the
// *other* views (leave-one-out), so the view's own error cannot veto them.
//
// A point X on the ray of pixel p of view v, at a depth in the object's range
// [depth_near, depth_far] in v, supports object o when, over the other views u
// that hold o (some pixel of o in u's labels) and see X (in front of u, inside
// its image):
//   - no u puts X on the background (an occluder's pixels, another object's
//     label, do not count against o: o may be behind it), and
//   - at least `min_views` of them put X on o (o's labels dilated by
//     `mask_tolerance_px`).
// The paper restores missing limbs by dilating towards the 3D joints; this is
// the same role when no pose is given, and an addition to the capsules when
// one is (frame_setup.h). Only pixels that v's labels put on the background,
// or on one of the object's `claims`, are tested (and the map is 0 on the
// others); a pixel supported by several objects takes the nearest one. The
// claims are the people, for an object without a pose: a detector merges a
// box with the person holding it in some views, and there the box's pixels
// carry the person's label. The map widens the solve's region and relaxes
// E_sem there (the detector's background, or the claimed person, at p is
// contradicted by the other views: E_sem does not prefer it over o; the
// claimed pixels are no colour sample of the person, and with colour_samples
// E_a's colour models sample the supported pixels as o, not as the
// background: frame_setup.cc), so E_a, E_c, E_d and the person's E_p decide
// the label.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"

namespace u4d {

struct HullSupportOptions {
  bool enabled = true;
  int min_views = 3;          // other views that must put a point on the object
  int mask_tolerance_px = 2;  // the other views' object labels dilated by this (pixels)
  int depth_samples = 64;     // depths tested per ray, even in depth over the object's range
  // E_a also samples the supported pixels as their object and not as the
  // background. Off by default: it restores a part cut in every frame of the
  // neighbourhood, but where touching people merge in the other views the
  // samples carry the other person's and the gap's colours (more merges).
  bool colour_samples = false;
  int max_side = 240;  // rays are cast at this longest side (the map is then upsampled)
  void Check() const;  // throws u4d::Error naming the bad field
};

// One object's depth range in the reference view.
struct HullObject {
  int id = 0;                            // >= 1, the label in every view's `labels`
  double depth_near = 0, depth_far = 0;  // metres, 0 < near < far
  std::vector<int> claims;               // labels of the view it may take (above)
};

// The support map of view `ref` (CV_16U, the labels' size: an object id, 0 =
// none) from the other views' labels (CV_16U object ids, each the size of its
// camera; an empty Mat = a view without labels, which does not vote).
// Throws u4d::Error when the sizes disagree with the cameras, an object's
// range is bad, or an option is out of range.
cv::Mat HullSupport(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& labels, int ref,
                    const std::vector<HullObject>& objects, const HullSupportOptions& options = {});

}  // namespace u4d
