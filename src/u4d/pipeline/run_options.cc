#include "u4d/pipeline/run_options.h"

#include "u4d/features/features_options.h"
#include "u4d/fusion/fusion_options.h"
#include "u4d/init/init_options.h"
#include "u4d/joint/joint_options.h"
#include "u4d/joint/parameters.h"
#include "u4d/keyframes/keyframes_options.h"
#include "u4d/pose/pose_options.h"
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
  U4D_CHECK(max_frame_gap_s > 0, "RunOptions.max_frame_gap_s must be > 0, got {}", max_frame_gap_s);
  U4D_CHECK(threads >= 0, "RunOptions.threads must be >= 0, got {}", threads);
  U4D_CHECK(!paper_weights || u4d::ToJson(joint.weights) == u4d::ToJson(JointWeights()),
            "RunOptions: joint.weights are set but paper_weights is true, so the paper's table "
            "would replace them; set paper_weights to false to use them");
  background.Check();
  init.Check();
  chroma_key.Check();
  frame_setup.Check();
  joint.Check();
  pose.Check();
  pose_tracking.Check();
  pose_smoothing.Check();
  sparse.Check();
  regions.Check();
  link.Check();
  unlabelled.Check();
  tracks.Check();
  keyframes.Check();
  fusion.Check();
  scene_flow.Check();
  flow_consensus.Check();
  gltf.Check();
}

nlohmann::json RunOptions::ToJson() const {
  RunOptions copy = *this;
  return OptionsToJson(OptionsOf(&copy));
}

nlohmann::json FromLegacyAblation(nlohmann::json j) {
  if (!j.is_object() || !j.contains("ablation") || !j["ablation"].is_string()) return j;
  const nlohmann::json::json_pointer terms_path("/joint/terms");
  if (!j.contains(terms_path) || !j[terms_path].is_object()) return j;
  nlohmann::json& terms = j[terms_path];
  const nlohmann::json off = u4d::ToJson(AblationTerms(j["ablation"].get<std::string>()));
  for (const auto& term : off.items())
    if (!terms.contains(term.key())) return j;  // not a complete params.json: a preset
  for (const auto& [name, on] : off.items())
    if (!on.get<bool>()) terms[name] = false;
  j.erase("ablation");
  return j;
}

nlohmann::json RunOptions::ResumeKey(nlohmann::json params) {
  params = FromLegacyAblation(std::move(params));
  RunOptions defaults;
  EraseRunControlOptions(OptionsOf(&defaults), &params);
  return params;
}

void DeclareOptions(OptionRegistry& r, ObjectLinkOptions* o) {
  r.Add("max_centroid_jump_m", &o->max_centroid_jump_m,
        "farther centroids (per frame unseen) are different objects");
  r.Add("max_missing_frames", &o->max_missing_frames,
        "an unseen object is forgotten after this many frames");
  r.Add("max_appearance_distance", &o->max_appearance_distance,
        "across a cut in time, an object whose colours differ from a tracked one's by at most "
        "this (Delta E) is that object; 0 = a cut forgets every object");
  r.Add("min_appearance_margin", &o->min_appearance_margin,
        "... unless another tracked object or another object is within this (Delta E) of that "
        "distance: an ambiguous link gives a new id; 0 = nearest pairs first");
}

void DeclareOptions(OptionRegistry& r, UnlabelledObjectOptions* o) {
  r.Add("enabled", &o->enabled,
        "with given masks on static cameras, foreground no given instance explains and the other "
        "views confirm becomes an object (unlabelled_objects.h)");
  r.Add("margin_px", &o->margin_px,
        "foreground within this distance of a given instance is its boundary error; 0 = 1 px per "
        "60 px of image height");
  r.Add("min_view_fraction", &o->min_view_fraction,
        "of the other views seeing a point of it, the share whose unexplained foreground holds it");
  r.Add("min_area_fraction", &o->min_area_fraction,
        "components smaller than this share of the image are dropped");
  r.Add("class_name", &o->class_name, "the class of the objects found");
}

void DeclareOptions(OptionRegistry& r, RunOptions* o) {
  r.Add("first_frame", &o->first_frame, "first frame of the capture to run");
  r.Add("num_frames", &o->num_frames, "frames to run (-1: to the end of the capture)");
  r.AddEnum("masks", &o->masks,
            {{"auto", MaskSource::kAuto},
             {"given", MaskSource::kGiven},
             {"unsupervised", MaskSource::kUnsupervised}},
            "initial masks: auto (the capture's masks/ when present, else unsupervised), given, "
            "unsupervised");
  r.AddEnum(
      "poses", &o->poses,
      {{"auto", PoseSource::kAuto},
       {"given3d", PoseSource::kGiven3d},
       {"from2d", PoseSource::kFrom2d},
       {"none", PoseSource::kNone}},
      "3D poses: auto (poses3d/, else poses2d/ triangulated, else none), given3d, from2d, none");
  r.AddPreset(
      "ablation", AblationNames(),
      [o](const std::string& name) { o->joint.terms = AblationTerms(name); },
      [o]() -> nlohmann::json {
        for (const std::string& name : AblationNames())
          if (AblationTerms(name) == o->joint.terms) return name;
        return nullptr;  // terms of no ablation
      },
      "sets the joint.terms to the paper's ablation: full (all on), P_M (flow, motion_reg off), "
      "P_P (pose off), P_PM (pose, flow, motion_reg off), P_S (semantic off), P_PS (pose, "
      "semantic off) (AblationTerms); applied before the explicit options, so a joint.terms.* "
      "set in the same file or on the command line wins");
  r.Add("picture_width", &o->picture_width, "viewer pictures (0 = the camera's width)");
  r.Add("track_chunk_frames", &o->track_chunk_frames,
        "temporal tracks are linked within chunks of this many frames (bounded memory on long "
        "captures)");
  r.Add("keyframe_mask_width", &o->keyframe_mask_width,
        "masks are downscaled to this width for KS_ij");
  r.Add("max_frame_gap_s", &o->max_frame_gap_s,
        "frames further apart in the source than this many seconds (capture.json's "
        "source_frames) are a cut: no flow, tracks, key-frame segment or object link crosses it");
  r.Add("evaluate", &o->evaluate, "write eval.json when the capture has gt/",
        OptionRole::kRunControl);
  r.Add("resume", &o->resume, "skip the segments an earlier run finished", OptionRole::kRunControl);
  r.Add("threads", &o->threads, "views solved in parallel (0 = TBB's default)",
        OptionRole::kRunControl);
  r.Add("progress", &o->progress, "progress bars on stderr", OptionRole::kRunControl);
  r.Add("allow_empty", &o->allow_empty,
        "succeed even when no frame has an object (else u4d::Error)", OptionRole::kRunControl);
  r.Nested("background", &o->background);
  r.Nested("init", &o->init);
  r.Nested("chroma_key", &o->chroma_key);
  r.Nested("frame_setup", &o->frame_setup);
  r.Nested("joint", &o->joint);
  r.Add("paper_weights", &o->paper_weights,
        "joint.weights := the paper's table row for the capture (scene type, number of views); "
        "false: joint.weights as given (setting them while this is true is an error)");
  r.Nested("pose", &o->pose);
  r.Nested("pose_tracking", &o->pose_tracking);
  r.Nested("pose_smoothing", &o->pose_smoothing);
  r.Nested("sparse", &o->sparse);
  r.Nested("regions", &o->regions);
  r.Nested("link", &o->link);
  r.Nested("unlabelled", &o->unlabelled);
  r.Nested("tracks", &o->tracks);
  r.Nested("keyframes", &o->keyframes);
  r.Nested("fusion", &o->fusion);
  r.Nested("scene_flow", &o->scene_flow);
  r.Nested("flow_consensus", &o->flow_consensus);
  r.Nested("gltf", &o->gltf);
}

}  // namespace u4d
