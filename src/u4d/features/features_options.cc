#include "u4d/features/features_options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, SparseFrameOptions* o) {
  r.Nested("keypoints", &o->keypoints);
  r.Nested("matching", &o->matching);
  r.Nested("sparse", &o->sparse);
  r.Add("detection_mask_dilation_px", &o->detection_mask_dilation_px,
        "features only near initial masks; < 0 = whole image");
}

void DeclareOptions(OptionRegistry& r, SparseOptions* o) {
  r.Add("max_reprojection_px", &o->max_reprojection_px,
        "observations reprojecting farther are dropped");
  r.Add("min_triangulation_angle_deg", &o->min_triangulation_angle_deg,
        "largest ray angle a point must reach");
  r.Add("min_views", &o->min_views, "observations a point keeps at least (>= 2)");
  r.Add("refine_iterations", &o->refine_iterations, "Levenberg-Marquardt iterations per estimate");
  r.Add("min_links", &o->min_links, "AssociateInstances: points linking two instances");
}

void DeclareOptions(OptionRegistry& r, KeypointOptions* o) {
  r.Add("max_features", &o->max_features, "keep at most this many (strongest) per view; 0 = all");
  r.Add("contrast_threshold", &o->contrast_threshold,
        "SIFT contrast threshold (OpenCV default 0.04)");
  r.Add("edge_threshold", &o->edge_threshold, "SIFT edge threshold (OpenCV default)");
  r.Add("root_sift", &o->root_sift, "RootSIFT: L1-normalise, then square-root descriptors");
}

void DeclareOptions(OptionRegistry& r, MatchingOptions* o) {
  r.Add("ratio", &o->ratio, "Lowe's ratio on descriptor distances (< 1)");
  r.Add("mutual", &o->mutual, "keep only mutual nearest neighbours");
  r.Add("max_epipolar_px", &o->max_epipolar_px, "epipolar gate in undistorted pixels");
  r.Add("max_descriptor_distance", &o->max_descriptor_distance,
        "absolute L2 gate (RootSIFT vectors have norm 1)");
  r.Add("min_track_views", &o->min_track_views, "tracks seen in fewer views are dropped (>= 2)");
  r.Add("neighbour_views", &o->neighbour_views,
        "a view is matched only with this many nearest views by optical-axis angle; 0 = all pairs");
  r.Add("max_pair_angle_deg", &o->max_pair_angle_deg,
        "only pairs whose optical axes differ by at most this (degrees, in (0, 180])");
}

void DeclareOptions(OptionRegistry& r, ObjectRegionOptions* o) {
  r.Add("percentile_near", &o->percentile_near, "depth percentile giving depth_near (in [0, 1])");
  r.Add("percentile_far", &o->percentile_far,
        "depth percentile giving depth_far (>= percentile_near)");
  r.Add("depth_margin_m", &o->depth_margin_m,
        "margin on both sides (body thickness, sparse coverage)");
  r.Add("min_points", &o->min_points, "fewer points in a view -> fallback depth range");
  r.Add("joint_depth_margin_m", &o->joint_depth_margin_m, "margin around the joints' depth range");
  r.Add("limb_radius_m", &o->limb_radius_m, "half-width of a bone drawn by the pose constraint");
  r.Add("min_joint_confidence", &o->min_joint_confidence,
        "joints below this confidence are ignored");
  r.Add("hull_near_m", &o->hull_near_m, "visual hull search: nearest depth");
  r.Add("hull_far_m", &o->hull_far_m, "visual hull search: farthest depth");
  r.Add("hull_depth_steps", &o->hull_depth_steps, "depth samples per ray (geometric spacing)");
  r.Add("hull_max_pixels", &o->hull_max_pixels, "rays sampled per region");
  r.Nested("silhouette", &o->silhouette);
}

void DeclareOptions(OptionRegistry& r, SilhouettePointOptions* o) {
  r.Add("max_side", &o->max_side, "masks are tested at this longest side (pixels)");
  r.Add("pixels_per_view", &o->pixels_per_view,
        "rays cast per view (a regular sample of its foreground)");
  r.Add("depth_samples", &o->depth_samples, "depths per ray, even in inverse depth");
  r.Add("min_depth_m", &o->min_depth_m, "nearest depth tested");
  r.Add("min_views_seeing", &o->min_views_seeing,
        "other views that must see a point (inside their image)");
  r.Add("min_foreground_share", &o->min_foreground_share,
        "share of the other views seeing a point that must hold it in their foreground");
}

void DeclareOptions(OptionRegistry& r, TemporalTrackOptions* o) {
  r.Add("window", &o->window, "frames i is matched to: j in (i, i + window]");
  r.Add("ratio", &o->ratio, "Lowe's ratio: best < ratio * second best distance");
  r.Add("symmetry_test", &o->symmetry_test, "keep only matches found both forwards and backwards");
  r.Add("max_features", &o->max_features, "SIFT features per frame (strongest kept); 0 = all");
  r.Add("contrast_threshold", &o->contrast_threshold,
        "cv::SIFT contrastThreshold (lower: more features)");
  r.Add("restrict_to_masks", &o->restrict_to_masks,
        "detect only inside the dilated instance masks");
  r.Add("mask_dilation_px", &o->mask_dilation_px,
        "dilation of the masks (pixels) before restricting");
  r.Add("add_joint_tracks", &o->add_joint_tracks, "add projected 3D joints as tracks");
  r.Add("min_joint_confidence", &o->min_joint_confidence,
        "joints below this confidence are skipped");
}

}  // namespace u4d
