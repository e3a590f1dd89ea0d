#include "u4d/init/init_options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, BackgroundOptions* o) {
  r.Add("max_frames", &o->max_frames,
        "frames sampled evenly over the sequence for the median (>= 1)");
  r.Add("envelope", &o->envelope,
        "keep the temporal envelope of the sampled frames' foreground (step 5)");
  r.Add("envelope_min_frames", &o->envelope_min_frames,
        "envelope: pixels foreground in at least this many sampled frames (>= 1; 1 = the union)");
}

void DeclareOptions(OptionRegistry& r, ForegroundOptions* o) {
  r.Add("threshold_sigmas", &o->threshold_sigmas, "foreground: distance > this * noise level");
  r.Add("min_noise_sigma", &o->min_noise_sigma, "floor of the noise level (Lab units)");
  r.Add("suppress_shadows", &o->suppress_shadows,
        "classify darker, same-chroma pixels as background");
  r.Add("shadow_min_ratio", &o->shadow_min_ratio, "shadow: L / L_background >= this");
  r.Add("shadow_max_ratio", &o->shadow_max_ratio, "shadow: L / L_background <= this");
  r.Add("shadow_chroma_sigmas", &o->shadow_chroma_sigmas,
        "shadow: chroma change <= this * noise level");
  r.Add("morph_radius_px", &o->morph_radius_px,
        "opening/closing radius; 0 = 1 px per 360 px of height");
  r.Add("min_blob_fraction", &o->min_blob_fraction,
        "components (and holes) smaller than this * area go");
}

void DeclareOptions(OptionRegistry& r, CrossViewOptions* o) {
  r.Add("enabled", &o->enabled,
        "cross-view consistency check (step 3) when >= 2 calibrated views are given");
  r.Add("consistency_max_side", &o->consistency_max_side,
        "longest image side at which rays are tested (px)");
  r.Add("step_px", &o->step_px, "ray march step: projected motion in other views (px)");
  r.Add("min_depth_m", &o->min_depth_m, "nearest depth tested (m)");
  r.Add("max_depth_m", &o->max_depth_m, "farthest; 0 = 1.5 x the largest camera baseline");
  r.Add("min_view_fraction", &o->min_view_fraction,
        "of the other views seeing the point, in foreground");
  r.Add("min_views_seeing", &o->min_views_seeing,
        "a depth counts only when this many others see it (capped at views - 1)");
  r.Add("consistency_dilation_px", &o->consistency_dilation_px,
        "dilation of the other views' masks (reduced px)");
  r.Add("min_consistent_fraction", &o->min_consistent_fraction,
        "a component is kept above this consistent share");
  r.Add("carve_pixels", &o->carve_pixels, "also drop inconsistent pixels in kept components");
}

void DeclareOptions(OptionRegistry& r, PeopleOptions* o) {
  r.Add("use_hog", &o->use_hog, "split/confirm components with HOG people boxes");
  r.Add("hog_threshold", &o->hog_threshold, "HOG SVM hit threshold (higher: fewer boxes)");
  r.Add("min_person_height_px", &o->min_person_height_px,
        "upscale so that people this tall fit 128 px windows");
  r.Add("hog_max_side", &o->hog_max_side, "longest side at which HOG runs (downscale above)");
  r.Add("require_detection", &o->require_detection, "drop components with no HOG box");
  r.Add("group_radius_px", &o->group_radius_px,
        "fragments closer than this are one instance; 0 = h/100");
  r.Add("box_min_coverage", &o->box_min_coverage,
        "HOG boxes with less foreground than this share get GrabCut");
  using BoxFill = PeopleOptions::BoxFill;
  r.AddEnum("box_fill", &o->box_fill,
            {{"never", BoxFill::kNever},
             {"empty-views", BoxFill::kEmptyViews},
             {"always", BoxFill::kAlways}},
            "GrabCut in HOG boxes with little foreground: never, in views where the background "
            "leaves less than one instance of foreground, or always");
  r.Add("grabcut_box_iterations", &o->grabcut_box_iterations,
        "GrabCut iterations in those boxes (>= 1)");
  r.Add("boxes_from_views", &o->boxes_from_views,
        "where boxes get GrabCut, boxes of people that two calibrated views' boxes place on the "
        "floor replace the single-view boxes");
  r.Add("views_hog_threshold", &o->views_hog_threshold,
        "HOG threshold of the boxes other views confirm");
  r.Add("foot_max_gap_m", &o->foot_max_gap_m, "two views' foot rays of one person pass this close");
  r.Add("floor_tolerance_m", &o->floor_tolerance_m,
        "their meeting points are this close to the floor");
  r.Add("person_radius_m", &o->person_radius_m, "a person's cylinder (m): feet of one person");
  r.Add("person_height_m", &o->person_height_m, "a person's cylinder height (m)");
  r.Add("split_by_profile", &o->split_by_profile,
        "split wide components at column-profile valleys");
  r.Add("profile_valley_ratio", &o->profile_valley_ratio,
        "valley < this * the smaller neighbouring peak");
  r.Add("min_instance_fraction", &o->min_instance_fraction,
        "instances smaller than this * area are dropped");
  r.Add("grabcut_iterations", &o->grabcut_iterations,
        "cv::grabCut iterations per instance; 0 = off");
  r.Add("grabcut_max_side", &o->grabcut_max_side,
        "instance box is downscaled to this side for GrabCut");
}

void DeclareOptions(OptionRegistry& r, StillOptions* o) {
  r.Add("still_grabcut_iterations", &o->still_grabcut_iterations,
        "GrabCut iterations in the envelope's hull; 0 = off");
  r.Add("envelope_dilation", &o->envelope_dilation,
        "envelope dilation before its hull (x image height)");
  r.Add("envelope_ring", &o->envelope_ring, "probable-background ring around the hull (x height)");
  r.Add("still_max_side", &o->still_max_side,
        "GrabCut runs with the image's longest side at most this");
  r.Add("still_require_model", &o->still_require_model,
        "add only where the background model shows the subject");
  r.Add("carve_still_fill", &o->carve_still_fill,
        "keep filled pixels only where cross-view consistent");
  r.Add("remove_ghosts", &o->remove_ghosts, "drop ghost components (RemoveGhosts) before step 5");
  r.Add("ghost_edge_ratio", &o->ghost_edge_ratio,
        "ghost: outline gradient in the image < this x in the model (0.5: the model's edge is "
        "clearly stronger)");
}

void DeclareOptions(OptionRegistry& r, GroundOptions* o) {
  r.Add("enabled", &o->enabled, "run step 6 (else step 4 splits each view)");
  r.Add("occupancy_min_views", &o->occupancy_min_views,
        "cameras needed; also views that must see a voxel");
  r.Add("occupancy_max_side", &o->occupancy_max_side,
        "longest image side at which voxels are tested (px)");
  r.Add("occupancy_cells", &o->occupancy_cells, "cells per side of the cubic grid");
  r.Add("occupancy_extent", &o->occupancy_extent,
        "grid half-size: this x median camera distance to the rig centre");
  r.Add("min_column_height_m", &o->min_column_height_m,
        "lower columns are floor, shadow, clutter (m)");
  r.Add("min_person_height_m", &o->min_person_height_m,
        "a person's highest column reaches this (m)");
  r.Add("previous_radius_m", &o->previous_radius_m,
        "a previous person's position holds a candidate within this (m; SeparatePeopleOnGround)");
  r.Add("min_lone_height_m", &o->min_lone_height_m,
        "a lower region touching none that tall is a person when it reaches this (m)");
  r.Add("person_smoothing_m", &o->person_smoothing_m, "Gaussian sigma on the height map (m)");
  r.Add("person_saddle_ratio", &o->person_saddle_ratio,
        "regions merge above this x the lower peak");
  r.Add("min_exclusive_share", &o->min_exclusive_share,
        "phantoms: no view has this share of its rays alone");
  r.Add(
      "min_split_share", &o->min_split_share,
      "an instance merges a second person nearest on this x as many of its rays as its own person");
  r.Add("instance_split_view_share", &o->instance_split_view_share,
        "given masks: a map candidate that k instances hold in this share of the views holding "
        "it is k touching people; 0 = off");
  r.Add("min_split_exclusive_share", &o->min_split_exclusive_share,
        "an instance split is kept when each part is alone on this share of its rays in some "
        "view");
  r.Add("occupancy_fill_fraction", &o->occupancy_fill_fraction,
        "pixels missing an id take the nearest within this x image height, else are dropped");
}

void DeclareOptions(OptionRegistry& r, InitOptions* o) {
  r.Nested("foreground", &o->foreground);
  r.Nested("cross_view", &o->cross_view);
  r.Nested("people", &o->people);
  r.Nested("still", &o->still);
  r.Nested("ground", &o->ground);
}

void DeclareOptions(OptionRegistry& r, ChromaKeyOptions* o) {
  using Mode = ChromaKeyOptions::Mode;
  r.AddEnum("mode", &o->mode, {{"off", Mode::kOff}, {"auto", Mode::kAuto}, {"on", Mode::kOn}},
            "key green/blue-screen views: off, auto (views whose border is mostly one saturated "
            "hue), on (every view)");
  r.Add("colour", &o->colour,
        "backdrop colour: auto (found at the border), green, blue or #RRGGBB");
  r.Add("max_frames", &o->max_frames, "frames sampled (evenly) to find the backdrop colour");
  r.Add("border_fraction", &o->border_fraction,
        "border band width where the backdrop colour is looked for (x the shorter side)");
  r.Add("min_saturation", &o->min_saturation,
        "saturated: |rgb chroma| >= this (grey 0, pure primary 1)");
  r.Add("hue_tolerance_deg", &o->hue_tolerance_deg, "backdrop hue +- this (degrees)");
  r.Add("min_key_fraction", &o->min_key_fraction,
        "backdrop: chroma along the key's >= this x the key's (spill stays foreground)");
  r.Add("min_brightness", &o->min_brightness,
        "backdrop: r + g + b >= this x the key's (darker pixels are foreground)");
  r.Add("min_border_share", &o->min_border_share,
        "auto: key a view when this share of its border is backdrop");
}

}  // namespace u4d
