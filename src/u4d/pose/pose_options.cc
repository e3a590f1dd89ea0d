#include "u4d/pose/pose_options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, MultiViewPoseOptions* o) {
  r.Add("min_keypoint_confidence", &o->min_keypoint_confidence,
        "2D keypoints below this confidence count as missing");
  r.Add("max_epipolar_distance", &o->max_epipolar_distance,
        "association threshold on the mean symmetric epipolar distance (fraction of the image "
        "width)");
  r.Add("min_shared_keypoints", &o->min_shared_keypoints,
        "keypoints confident in both detections needed for a pairwise affinity");
  r.Add("min_views", &o->min_views, "views a person must be associated in to be triangulated");
  r.Add("max_reprojection_error", &o->max_reprojection_error,
        "inlier threshold of the per-joint RANSAC (fraction of the image width)");
  r.Add("mirror_gain", &o->mirror_gain,
        "a view's detection is mirrored when its mirror reprojects with less than this fraction of "
        "its own error (0: never)");
  r.Add("min_triangulation_angle_deg", &o->min_triangulation_angle_deg,
        "a joint needs two inlier views whose rays meet at least at this angle (degrees; opposite "
        "cameras count as parallel)");
  r.Add("min_joints", &o->min_joints, "triangulated COCO joints a person needs to be reported");
}

void DeclareOptions(OptionRegistry& r, PoseTrackerOptions* o) {
  r.Add("max_match_distance", &o->max_match_distance,
        "mean joint distance (m) above which a pose cannot continue a track");
  r.Add("max_missed_frames", &o->max_missed_frames,
        "frames a track (or one of its joints) survives without a measurement");
  r.Add("alpha", &o->alpha, "alpha-beta filter: alpha in (0, 1]");
  r.Add("beta", &o->beta, "alpha-beta filter: beta in [0, 2 - alpha)");
  r.Add("gate_distance", &o->gate_distance,
        "innovation (m) above which a joint measurement is an outlier");
  r.Add("max_gated_frames", &o->max_gated_frames,
        "consecutive gated frames after which the filter is reset to the measurement");
}

void DeclareOptions(OptionRegistry& r, PoseSmoothingOptions* o) {
  r.Add("window_seconds", &o->window_seconds, "length of the fitting window in seconds (0 = off)");
  r.Add("degree", &o->degree, "polynomial degree (>= 1)");
}

}  // namespace u4d
