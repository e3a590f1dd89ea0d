#include "u4d/pipeline/run_options.h"

#include "u4d/joint/parameters.h"
#include "u4d/util/check.h"

namespace u4d {

std::string ToString(MaskSource s) {
  switch (s) {
    case MaskSource::kAuto:
      return "auto";
    case MaskSource::kGiven:
      return "given";
    case MaskSource::kUnsupervised:
      return "unsupervised";
  }
  return "?";
}

std::string ToString(PoseSource s) {
  switch (s) {
    case PoseSource::kAuto:
      return "auto";
    case PoseSource::kGiven3d:
      return "given3d";
    case PoseSource::kFrom2d:
      return "from2d";
    case PoseSource::kNone:
      return "none";
  }
  return "?";
}

MaskSource MaskSourceFromString(const std::string& s) {
  for (MaskSource m : {MaskSource::kAuto, MaskSource::kGiven, MaskSource::kUnsupervised})
    if (ToString(m) == s) return m;
  ThrowError(fmt::format("unknown mask source '{}' (expected auto, given or unsupervised)", s));
}

PoseSource PoseSourceFromString(const std::string& s) {
  for (PoseSource p :
       {PoseSource::kAuto, PoseSource::kGiven3d, PoseSource::kFrom2d, PoseSource::kNone})
    if (ToString(p) == s) return p;
  ThrowError(fmt::format("unknown pose source '{}' (expected auto, given3d, from2d or none)", s));
}

void RunOptions::Check() const {
  U4D_CHECK(first_frame >= 0, "RunOptions.first_frame must be >= 0, got {}", first_frame);
  U4D_CHECK(num_frames == -1 || num_frames >= 1,
            "RunOptions.num_frames must be -1 (all) or >= 1, got {}", num_frames);
  U4D_CHECK(picture_width >= 0, "RunOptions.picture_width must be >= 0, got {}", picture_width);
  U4D_CHECK(track_chunk_frames >= 2, "RunOptions.track_chunk_frames must be >= 2, got {}",
            track_chunk_frames);
  U4D_CHECK(keyframe_mask_width >= 16, "RunOptions.keyframe_mask_width must be >= 16, got {}",
            keyframe_mask_width);
  U4D_CHECK(threads >= 0, "RunOptions.threads must be >= 0, got {}", threads);
  AblationTerms(ablation);  // throws on an unknown name
  background.Check();
  init.Check();
  frame_setup.Check();
  joint.Check();
  pose.Check();
  pose_tracking.Check();
  pose_smoothing.Check();
  sparse.Check();
  regions.Check();
  tracks.Check();
  keyframes.Check();
  fusion.Check();
  scene_flow.Check();
  gltf.Check();
}

nlohmann::json RunOptions::ToJson() const {
  using nlohmann::json;
  return json{
      {"first_frame", first_frame},
      {"num_frames", num_frames},
      {"masks", ToString(masks)},
      {"poses", ToString(poses)},
      {"ablation", ablation},
      {"picture_width", picture_width},
      {"track_chunk_frames", track_chunk_frames},
      {"keyframe_mask_width", keyframe_mask_width},
      {"paper_weights", paper_weights},
      {"frame_setup",
       {{"working_width", frame_setup.working_width},
        {"depth_margin_m", frame_setup.depth_margin_m},
        {"min_joints_inside", frame_setup.min_joints_inside}}},
      {"joint",
       {{"weights", u4d::ToJson(joint.weights)},
        {"rounds", joint.rounds},
        {"sweeps_per_block", joint.sweeps_per_block},
        {"motion_rounds", joint.motion_rounds},
        {"depth_coarse_step", joint.depth_coarse_step},
        {"depth_refine_band", joint.depth_refine_band},
        {"depth_truncation", joint.depth_truncation},
        {"motion_truncation_px", joint.motion_truncation_px},
        {"roi_margin_px", joint.roi_margin_px},
        {"depth_object_ranges", joint.depth_object_ranges},
        {"motion_candidates_per_pixel", joint.motion_candidates_per_pixel},
        {"motion_reg_quadratic", joint.motion_reg_quadratic},
        {"motion_reg_edge_aware", joint.motion_reg_edge_aware},
        {"motion_reg_boundary", static_cast<int>(joint.motion_reg_boundary)},
        {"flow_fusion",
         {{"enabled", joint.fusion.enabled},
          {"proposals",
           {joint.fusion.refined, joint.fusion.deepflow, joint.fusion.dis_fine, joint.fusion.dis,
            joint.fusion.smoothed}},
          {"rounds", joint.fusion.rounds}}}}},
      {"pose_smoothing",
       {{"window_seconds", pose_smoothing.window_seconds}, {"degree", pose_smoothing.degree}}},
      {"tracks",
       {{"window", tracks.window},
        {"ratio", tracks.ratio},
        {"max_features", tracks.max_features},
        {"symmetry_test", tracks.symmetry_test},
        {"add_joint_tracks", tracks.add_joint_tracks}}},
      {"keyframes",
       {{"threshold", keyframes.threshold},
        {"use",
         {keyframes.use_correspondence, keyframes.use_semantic, keyframes.use_distance,
          keyframes.use_pose, keyframes.use_shape}},
        {"pose_scale_m", keyframes.pose_scale_m},
        {"distance_scale", keyframes.distance_scale}}},
      {"fusion",
       {{"pixel_step", fusion.pixel_step},
        {"poisson_depth", fusion.poisson_depth},
        {"consistency_filter", fusion.consistency_filter},
        {"consistency_tolerance", fusion.consistency_tolerance},
        {"density_quantile", fusion.density_quantile}}},
      {"scene_flow",
       {{"visibility_tolerance", scene_flow.visibility_tolerance},
        {"consistency_tolerance", scene_flow.consistency_tolerance}}},
      {"gltf_fps", gltf.fps},
  };
}

}  // namespace u4d
