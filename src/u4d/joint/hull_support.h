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
//   - at most `max_background_views` of them put X on the background (an
//     occluder's pixels, another object's label, do not count against o: o
//     may be behind it), and
//   - those that put X on o (o's labels dilated by `mask_tolerance_px`)
//     outnumber those on the background by at least `min_views`.
// The paper restores missing limbs by dilating towards the 3D joints; this is
// the same role when no pose is given, and an addition to the capsules when
// one is (frame_setup.h). Only pixels that v's labels put on the background,
// or on one of the object's `claims`, are tested (and the map is 0 on the
// others): near the object's own pixels, over the claimed labels' pixels,
// and over the whole image when v's labels lack the object (a person the
// detector missed in v). A pixel supported by several objects takes the
// nearest one. The claims are the other objects of the view: a detector
// merges a box with the person holding it, or two people one behind the
// other, in some views, and there the one's pixels carry the other's label.
// The visual hull cannot tell which of two overlapping objects is in front
// (the space in front of the one behind projects into the one in front in
// every view), so the claim covers the whole of o's hull in the other's
// pixels, and the solve's data terms decide. The map widens the solve's
// region and relaxes E_sem there (the detector's background, or the claimed
// object, at p is contradicted by the other views: E_sem does not prefer it
// over o; the supported pixels are no colour sample of the claimed object,
// nor of the background at t, t−1 and t+1, and with colour_samples E_a's
// colour models sample them as o: frame_setup.cc), so E_a, E_c, E_d and a
// person's E_p decide the label.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"

namespace u4d {

struct HullSupportOptions {
  bool enabled = true;
  int min_views = 3;  // other views that must put a point on the object
  // Other views that may put a supported point on the background, at a
  // pixel the view itself puts there: a detector drops a limb in several
  // views of a frame, and one view that dropped it too would otherwise carve
  // it out of the others' hull. Each such view is outvoted (above): one
  // more view must hold the point. Over another object's pixels (claims)
  // and for HullConfirmation every view must agree: the hull a dissent
  // allows is larger, and a person's larger hull would claim the other
  // person's shoes where they look alike. 0 by default: the larger hull
  // also adds false positives next to the body (docs/joint.md).
  int max_background_views = 0;
  int mask_tolerance_px = 2;  // the other views' object labels dilated by this (pixels)
  int depth_samples = 64;     // depths tested per ray, even in depth over the object's range
  // E_a also samples the supported pixels as their object (they are never
  // background samples: frame_setup.cc). Off by default: where touching
  // people merge in the other views the samples carry the other person's
  // and the gap's colours (more merges).
  bool colour_samples = false;
  int max_side = 240;  // rays are cast at this longest side (the map is then upsampled)
  // E_a does not overrule a label the other views confirm (HullConfirmation).
  // Off by default: it keeps masks the views agree on (true masks: white
  // shoes on white tiles), but it also keeps a boundary error every
  // detector mask shares, and on detector-like masks it costs a little
  // accuracy at the working resolution (docs/joint.md). For masks the capture
  // trusts (keyed, hand-made).
  bool confirm = false;
  // A confirming view must hold the point this far inside its object labels
  // (pixels): a detector's boundary errs by a few pixels in every view, and a
  // leave-one-out hull from dilated masks would confirm the view's own error.
  int confirm_inset_px = 2;
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

// The other half of the same evidence: the pixels of view `ref` that its own
// labels give to an object o and whose ray meets o's leave-one-out hull (the
// same test as above) — the other views agree with the view's label there.
// CV_16U, o at those pixels, 0 elsewhere (claims play no part). The solve
// trusts the agreement over the view's colour models (label_costs.h
// TrustConfirmedLabels): a white shoe on white floor tiles is the background's
// colour, but every other view puts the shoe on the person. Same inputs and
// errors as HullSupport. The rays of every object are cast over the pixels
// the view gives to any object (within their search boxes), and o is
// confirmed where its hull is the nearest a ray meets: a person behind the
// one seen meets the ray too. The other views must hold the point
// `confirm_inset_px` inside their labels. `seen`, when given, receives the
// nearest object at every such pixel, confirmed or not (0 = none met): where
// the view gave one person's pixels to another (a merged instance split
// wrongly), the object the other views put there. `alone`, when given,
// receives (CV_8U) the confirmed pixels whose ray meets no other object's
// hull: where people overlap in the view the hulls, bloated between views,
// may put the wrong one in front.
cv::Mat HullConfirmation(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& labels,
                         int ref, const std::vector<HullObject>& objects,
                         const HullSupportOptions& options = {}, cv::Mat* seen = nullptr,
                         cv::Mat* alone = nullptr);

}  // namespace u4d
