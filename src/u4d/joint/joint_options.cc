#include "u4d/joint/joint_options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, FrameSetupOptions* o) {
  r.Add("working_width", &o->working_width, "the optimisation runs at this width (never upscaled)");
  r.Add("depth_margin_m", &o->depth_margin_m, "depth range: joints' z range widened by this");
  r.Add("min_joints_inside", &o->min_joints_inside,
        "joints needed inside an instance to assign it to a person");
  r.Add("split_merged", &o->split_merged,
        "split a detector instance that merges touching people among them by their capsules (else "
        "it goes whole to one person)");
  r.Add("min_joint_confidence", &o->min_joint_confidence,
        "joints below this confidence are missing");
  r.Nested("hull", &o->hull);
  r.Add("guided_upsampling", &o->guided_upsampling,
        "camera-size labels follow the image's colour edges near the solve's boundaries (joint "
        "bilateral upsampling; false: nearest neighbour)");
  r.Add("keep_initial_detail", &o->keep_initial_detail,
        "camera-size labels keep the initial masks' detail where the solve kept its input (false: "
        "the working-resolution labels upscaled by nearest neighbour)");
  r.Add("flow_at_camera_size", &o->flow_at_camera_size,
        "the objects' camera-size flow takes, per pixel, the solve's flow or the camera-size dense "
        "match, whichever keeps the brightness over a window (false: the solve's flow upscaled)");
  r.Add("flow_window_px", &o->flow_window_px, "that window's side, camera pixels (odd)");
  r.Add("flow_object_matches", &o->flow_object_matches,
        "that step also tries each object's own match, the rest of the image greyed out at t "
        "and t+1 (false: the whole image's match only)");
  r.Add("flow_carried_candidate", &o->flow_carried_candidate,
        "that step also tries the frame before's written flow carried forward along itself "
        "(constant velocity), where that frame continues into this one (false: the two "
        "images' candidates only)");
  r.Add("flow_median_px", &o->flow_median_px,
        "then each object's camera-size flow is median-filtered over a square of this side, "
        "working pixels, over the object's own pixels there (0 = off)");
  r.Add("flow_fill_radius_px", &o->flow_fill_radius_px,
        "then an object pixel whose backward match does not lead back (forward-backward check) "
        "takes the affine motion of its object's consistent pixels within this radius, working "
        "pixels (0 = off; needs flow_object_matches)");
  r.Add("flow_variational_iterations", &o->flow_variational_iterations,
        "last, the variational refinement of each object's camera-size flow on its own pair of "
        "images, fixed-point iterations (0 = off; needs flow_object_matches)");
  r.Add("colour_from_other_views", &o->colour_from_other_views,
        "with several objects in the view, each object's colour model (E_a) also learns from "
        "its pixels in the other views at t (false: only an object the view's labels lack)");
  // `pose` (the capsule model) is not declared: it is JointViewOptions::pose,
  // which callers copy in (the pipeline does), so the capsules are one setting.
}

void DeclareOptions(OptionRegistry& r, HullSupportOptions* o) {
  r.Add("enabled", &o->enabled,
        "grow each object's region by its leave-one-out visual hull from the other views, and "
        "let E_sem not prefer the background there (parts the view's mask missed)");
  r.Add("min_views", &o->min_views, "other views that must put a hull point on the object");
  r.Add("max_background_views", &o->max_background_views,
        "other views that may put a hull point on the background (a part the detector dropped in "
        "several views)");
  r.Add("mask_tolerance_px", &o->mask_tolerance_px,
        "the other views' object labels are dilated by this (working pixels)");
  r.Add("depth_samples", &o->depth_samples, "depths tested per ray over the object's range");
  r.Add("confirm", &o->confirm,
        "E_a does not overrule the view's label where the other views' hull confirms it (a colour "
        "the background shares, e.g. a white shoe on white tiles); for masks the capture trusts");
  r.Add("confirm_inset_px", &o->confirm_inset_px,
        "a confirming view must hold the point this far inside its object labels (pixels): not "
        "the detectors' boundary errors");
  r.Add("colour_samples", &o->colour_samples,
        "E_a samples the supported pixels as their object (they are never background samples; "
        "more merges where touching people merge in the other views)");
  r.Add("max_side", &o->max_side, "rays are cast at this longest side (the map is upsampled)");
}

void DeclareOptions(OptionRegistry& r, PosePriorOptions* o) {
  r.Add("limb_radius_m", &o->limb_radius_m, "capsule radius of arm and leg bones");
  r.Add("torso_radius_m", &o->torso_radius_m, "capsule radius of spine, hip and shoulder bones");
  r.Add("head_radius_m", &o->head_radius_m, "capsule radius of the neck-head bone");
  r.Add("taper_torso_ends", &o->taper_torso_ends,
        "bones leaving the torso taper from torso_radius_m to limb_radius_m at the hip / shoulder "
        "/ neck joint (false: torso radius along the whole bone)");
  r.Add("head_joint_on_crown", &o->head_joint_on_crown,
        "the head joint is the crown (the synthetic ground truth), not the head centre built from "
        "2D keypoints: the neck-head capsule ends one head radius before it (false: its cap "
        "reaches one head radius beyond the joint)");
  r.Add("occluder_limb_radius_m", &o->occluder_limb_radius_m,
        "another person's capsules with limbs this thick hide a capsule behind them (<= "
        "limb_radius_m: plain z-buffer)");
  r.Add("shape_own_label_only", &o->shape_own_label_only,
        "e_3d at a pixel covered by person k's capsule counts only when the pixel is labelled k");
  r.Add("core_fraction", &o->core_fraction,
        "w(p) = exp(−(r / core_fraction)² / 2), r in capsule radii: the pose is trusted most near "
        "the bone axis");
  r.Add("samples_per_bone", &o->samples_per_bone, "discs drawn along each bone");
  r.Add("min_confidence", &o->min_confidence, "joints below this confidence are missing");
  r.Add("sigma_motion_px", &o->sigma_motion_px,
        "σ_m of the motion sub-terms (pixels, working resolution)");
  r.Add("sigma_shape_m", &o->sigma_shape_m, "σ_s of the 3D shape sub-term (metres)");
}

void DeclareOptions(OptionRegistry& r, FlowFusionOptions* o) {
  r.Add("enabled", &o->enabled,
        "run the stage (only when E_f is on: the proposals are photometric)");
  r.Add("refined", &o->refined, "proposal: the discrete solution refined by parabola fits of E_f");
  r.Add("deepflow", &o->deepflow, "proposal: OpenCV DeepFlow of the reference view t -> t+1");
  r.Add("dis_fine", &o->dis_fine,
        "proposal: OpenCV DIS (medium preset) down to the finest pyramid scale, 10 variational "
        "refinement iterations");
  r.Add("dis", &o->dis, "proposal: OpenCV DIS (medium preset)");
  r.Add("smoothed", &o->smoothed, "proposal: the current field, Gaussian-smoothed (σ = 1 px, 5x5)");
  r.Add("rounds", &o->rounds, "passes over the proposals (>= 1)");
}

void DeclareOptions(OptionRegistry& r, JointViewOptions* o) {
  r.Nested("weights", &o->weights);
  r.Nested("terms", &o->terms);
  r.Nested("labels", &o->labels);
  r.Nested("depth", &o->depth);
  r.Nested("motion_labels", &o->motion_labels);
  r.Nested("flow", &o->flow);
  r.Nested("pose", &o->pose);
  r.Add("rounds", &o->rounds, "alternations of the l, d, m blocks");
  r.Add("motion_rounds", &o->motion_rounds,
        "the motion block runs in the first this many rounds only (>= 1)");
  r.Add("sweeps_per_block", &o->sweeps_per_block, "expansion sweeps per block and round");
  r.Add("depth_truncation", &o->depth_truncation, "τ_d, depth label steps");
  r.Add("depth_coarse_step", &o->depth_coarse_step,
        "> 1: the depth block first expands over every this-th depth, then lets pixels move by at "
        "most this many labels; 0 or 1: one pass over all depths");
  r.Add("depth_refine_band", &o->depth_refine_band,
        "from the second round on, a pixel with a depth may move by at most this many depth labels "
        "(or to U); 0 = no limit");
  r.Add("depth_object_ranges", &o->depth_object_ranges,
        "a pixel may take only the depth ranges of the objects whose region holds it, or U (false: "
        "the union range everywhere)");
  r.Add("motion_candidates_per_pixel", &o->motion_candidates_per_pixel,
        "> 0: in the motion block a pixel may take only its this many lowest-unary motions or keep "
        "its own; 0 = every motion");
  r.Add("motion_truncation_px", &o->motion_truncation_px, "τ_m, pixels (working resolution)");
  r.Add(
      "motion_reg_quadratic", &o->motion_reg_quadratic,
      "E_r's distance: truncated squared difference (the paper; true) or truncated linear (false)");
  r.Add("motion_reg_edge_aware", &o->motion_reg_edge_aware,
        "E_r's pair weight also multiplied by the colour contrast weight of E_c: motion smoothing "
        "fades across colour edges");
  r.AddEnum("motion_reg_boundary", &o->motion_reg_boundary,
            {{"free", MotionRegBoundary::kFree},
             {"discontinuity", MotionRegBoundary::kDiscontinuity},
             {"ignore", MotionRegBoundary::kIgnoreLabels}},
            "E_r across label boundaries: free (a cut removes E_r, the paper read literally), "
            "discontinuity (a cut pays the truncated maximum) or ignore (every pair pays)");
  r.Add("semantic_temporal", &o->semantic_temporal,
        "E_sem from the initial masks of t-1, t, t+1 carried to t by DIS flow (the paper's ψ_T; "
        "false: the mask of t only)");
  r.Nested("fusion", &o->fusion);
  r.Nested("background_flow", &o->background_flow);
  r.Add("roi_margin_px", &o->roi_margin_px, "dilation of the objects' regions (working pixels)");
  r.Add("appearance_refits", &o->appearance_refits,
        "re-learn frame t's colour GMMs from a labelling of the label unaries + E_c this many "
        "times before the energy is fixed (0 = the initial masks' GMMs, as the paper)");
  r.Add("label_moves_carry_depth", &o->label_moves_carry_depth,
        "after the first round a pixel taking label l takes the depth of the nearest pixel "
        "labelled l");
  r.AddEnum(
      "algorithm", &o->algorithm,
      {{"bk", mrf::MaxFlowAlgorithm::kBoykovKolmogorov},
       {"boost_bk", mrf::MaxFlowAlgorithm::kBoostBoykovKolmogorov}},
      "max-flow of the expansion moves: bk (own Boykov-Kolmogorov) or boost_bk (Boost.Graph)");
}

void DeclareOptions(OptionRegistry& r, BackgroundFlowOptions* o) {
  r.Add("enabled", &o->enabled,
        "the flow outside the objects' regions is the camera's rigid flow (false: 0 there)");
  r.Add("min_depth_m", &o->min_depth_m, "nearest depth a background point may take (> 0)");
}

void DeclareOptions(OptionRegistry& r, JointWeights* o) {
  r.Add("depth", &o->depth, "λ_d (E_d)");
  r.Add("appearance", &o->appearance, "λ_a (E_a)");
  r.Add("semantic", &o->semantic, "λ_sem (E_sem)");
  r.Add("flow", &o->flow, "λ_f (E_f)");
  r.Add("smooth", &o->smooth, "λ_s (E_s)");
  r.Add("smooth_spatial", &o->smooth_spatial, "λ_s^s (E_s, spatial part)");
  r.Add("smooth_temporal", &o->smooth_temporal, "λ_s^t (E_s, temporal part)");
  r.Add("contrast", &o->contrast, "λ_c (E_c)");
  r.Add("contrast_colour", &o->contrast_colour, "λ_ca (E_c, colour contrast)");
  r.Add("contrast_label", &o->contrast_label, "λ_cl (E_c, semantic contrast)");
  r.Add("motion_reg", &o->motion_reg, "λ_r (E_r)");
  r.Add("motion_reg_label", &o->motion_reg_label, "λ_r^L (E_r, semantic regularisation)");
  r.Add("motion_reg_app", &o->motion_reg_app,
        "λ_r^A (E_r, appearance regularisation; the table's λ_r^C)");
  r.Add("pose", &o->pose, "λ_p (E_p)");
  r.Add("pose_2d", &o->pose_2d, "λ_2d (E_p, 2D part)");
  r.Add("pose_3d", &o->pose_3d, "λ_3d (E_p, 3D part)");
}

void DeclareOptions(OptionRegistry& r, JointTerms* o) {
  r.Add("depth", &o->depth, "E_d on");
  r.Add("appearance", &o->appearance, "E_a on");
  r.Add("semantic", &o->semantic, "E_sem on");
  r.Add("flow", &o->flow, "E_f on");
  r.Add("smooth", &o->smooth, "E_s on");
  r.Add("contrast", &o->contrast, "E_c on");
  r.Add("motion_reg", &o->motion_reg, "E_r on");
  r.Add("pose", &o->pose, "E_p on");
}

void DeclareOptions(OptionRegistry& r, LabelCostOptions* o) {
  r.Add("gmm_components", &o->gmm_components, "components of the colour GMMs (paper: 10)");
  r.Add("max_samples_per_label", &o->max_samples_per_label,
        "colour samples used to fit a GMM (random subset)");
  r.Add("background_band_px", &o->background_band_px,
        "background samples: within this distance of the ROI's objects");
  r.Add("colour_bands", &o->colour_bands,
        "E_a's colour models per horizontal band of the objects' rows: the band's models decide "
        "object or background, the whole ones which object (a shoe is a small share of a person's "
        "colours; 1 = one model per label: a part the view's mask lacks is a large share of its "
        "band's background, and the other views no longer bring it back)");
  r.Add("max_samples_per_band", &o->max_samples_per_band,
        "colour samples used to fit a band's GMM (random subset)");
  r.Add("min_band_samples", &o->min_band_samples,
        "a band's model of a label needs this many of the view's own samples in it (else the "
        "label's whole model)");
  r.Add("appearance_inset_px", &o->appearance_inset_px,
        "colour samples only from pixels at least this far inside their label's initial mask; 0 = "
        "every pixel (for masks the capture trusts)");
  r.Add("mask_softness_px", &o->mask_softness_px,
        "logistic scale of P_sem across a mask boundary (pixels)");
  r.Add("min_probability", &o->min_probability,
        "floor of P_sem and of the likelihood ratio (sets the normalisation)");
  r.Add("detector_scores", &o->detector_scores,
        "E_sem weighs each initial mask by its detector score (false: every mask is certain)");
  r.Add("seed", &o->seed, "sampling and EM initialisation");
}

void DeclareOptions(OptionRegistry& r, DepthCostOptions* o) {
  r.Add("num_depths", &o->num_depths,
        "depth labels sampled uniformly in INVERSE depth over [near, far]");
  r.Add("patch_radius", &o->patch_radius, "NCC window (2r+1)^2");
  r.Add("num_best_views", &o->num_best_views,
        "k of O_k: the k most photo-consistent auxiliary views are averaged");
  r.Add("max_aux_views", &o->max_aux_views,
        "auxiliary views considered: the ones whose optical axes are closest in angle to the "
        "reference's (excluding views > 90 deg apart)");
  r.Add("unknown_cost", &o->unknown_cost,
        "M_U, the cost of the unknown label (same scale as m, in [0, 1])");
  r.Add("min_patch_std", &o->min_patch_std,
        "reference patches with a std below this (0..255 scale, per channel: summed variance < nc "
        "* std^2) are textureless: m = 0.5");
  r.Add("use_color", &o->use_color, "ZNCC over the three BGR channels (else over grey values)");
  r.Add("smooth_sigma", &o->smooth_sigma,
        "Gaussian pre-smoothing of the images (pixels, 0 = none)");
}

void DeclareOptions(OptionRegistry& r, MotionLabelOptions* o) {
  r.Add("window", &o->window,
        "half-size (pixels, working resolution) of the window of motions around each sparse "
        "displacement (the paper's window)");
  r.Add("cluster_radius", &o->cluster_radius,
        "sparse displacements closer than this (pixels) share one centre");
  r.Add("max_centres", &o->max_centres,
        "most-supported displacement clusters kept as window centres (+ the zero motion always)");
  r.Add("support_radius", &o->support_radius,
        "e_F^S: a pixel is \"near\" a sparse correspondence when within this distance (pixels)");
}

void DeclareOptions(OptionRegistry& r, FlowCostOptions* o) {
  r.Add("temporal", &o->temporal, "e_F^T: brightness constancy, same view, t -> t+1");
  r.Add("cross_view", &o->cross_view,
        "e_F^V: consistency with the other views at t+1 (needs depth_t)");
  r.Add("sparse", &o->sparse,
        "e_F^S: labels farther than motion_labels.window from every nearby sparse displacement are "
        "forbidden");
  r.Add("dense_support", &o->dense_support,
        "e_F^S also allows the motions within motion_labels.window of each pixel's dense match");
  r.Add("max_view_angle_deg", &o->max_view_angle_deg,
        "e_F^V uses only views whose optical axis is within this angle of the reference's "
        "(degrees, in (0, 180])");
  r.Add("patch_radius", &o->patch_radius,
        "colour differences averaged over a (2r+1)^2 patch (>= 0)");
  r.Add("truncation", &o->truncation, "per-term costs truncated at this (> 0)");
}

}  // namespace u4d
