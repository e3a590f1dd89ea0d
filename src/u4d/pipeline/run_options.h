// Options of `u4d run` (pipeline.h): which inputs to use, the frame range,
// the working resolution and every stage's algorithm options. Every field is
// declared once (DeclareOptions, util/options.h): all of them are written to
// the scene's params.json, `u4d run --config` and `--set` override any of them,
// docs/options.md lists them, and a resumed run must use the same values of
// every option that changes results (ResumeKey).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "u4d/features/object_regions.h"
#include "u4d/features/sparse_points.h"
#include "u4d/features/temporal_tracks.h"
#include "u4d/fusion/depth_fusion.h"
#include "u4d/fusion/flow_consensus.h"
#include "u4d/fusion/gltf.h"
#include "u4d/fusion/scene_flow.h"
#include "u4d/init/init.h"
#include "u4d/joint/frame_setup.h"
#include "u4d/joint/joint_view.h"
#include "u4d/keyframes/keyframe_similarity.h"
#include "u4d/pipeline/initial_objects.h"
#include "u4d/pipeline/unlabelled_objects.h"
#include "u4d/pose/multiview_pose.h"
#include "u4d/pose/pose_smoothing.h"
#include "u4d/pose/pose_tracking.h"
#include "u4d/util/options.h"

namespace u4d {

// Where the initial instance masks come from.
enum class MaskSource {
  kAuto,          // the capture's masks/ when present, else unsupervised
  kGiven,         // masks/<view>/<frame>.png (a missing file = nothing detected)
  kUnsupervised,  // init/ (background model + people detector + cross-view check)
};
// Where the 3D poses come from.
enum class PoseSource {
  kAuto,     // poses3d/, else poses2d/ triangulated, else none
  kGiven3d,  // poses3d/<frame>.json (given skeletons, paper Sec. 2.1.1)
  kFrom2d,   // poses2d/<view>/<frame>.json triangulated and tracked (pose/)
  kNone,     // no poses: objects from the cross-view association, no pose term
};
std::string ToString(MaskSource s);
std::string ToString(PoseSource s);
MaskSource MaskSourceFromString(const std::string& s);  // throws u4d::Error on an unknown name
PoseSource PoseSourceFromString(const std::string& s);

struct RunOptions {
  int first_frame = 0;
  int num_frames = -1;  // -1: to the end of the capture
  MaskSource masks = MaskSource::kAuto;
  PoseSource poses = PoseSource::kAuto;
  // (the option `ablation` is a preset of joint.terms, not a field: DeclareOptions)
  int picture_width = 480;        // viewer pictures (0 = the camera's width)
  int track_chunk_frames = 40;    // temporal tracks are linked within chunks of this many
                                  // frames (bounded memory on long captures)
  int keyframe_mask_width = 240;  // masks are downscaled to this width for KS_ij
  // Frames further apart in the source than this (capture.json's
  // source_frames at its fps) are a cut: nothing temporal crosses it
  // (ContinuesFrom). A second: a walking person moves ~1.4 m in it, beyond
  // what the flow's search and the tracks follow.
  double max_frame_gap_s = 1.0;
  bool evaluate = true;      // write eval.json when the capture has gt/
  bool resume = true;        // skip the segments an earlier run finished
  int threads = 0;           // views solved in parallel (0 = TBB's default)
  bool progress = true;      // progress bars on stderr
  bool allow_empty = false;  // succeed even when no frame has an object (else u4d::Error)

  BackgroundOptions background;   // unsupervised masks: the background model
  InitOptions init;               // unsupervised masks: foreground, people, cross-view check
  ChromaKeyOptions chroma_key;    // unsupervised masks: green/blue-screen views keyed
  FrameSetupOptions frame_setup;  // working width, depth margins
  JointViewOptions joint;         // the energy; weights default to PaperWeights at run time
  bool paper_weights = true;      // set joint.weights from the paper's table for the capture
  MultiViewPoseOptions pose;
  PoseTrackerOptions pose_tracking;
  PoseSmoothingOptions pose_smoothing;  // poses from 2D only: offline smoothing after tracking
  SparseFrameOptions sparse;
  ObjectRegionOptions regions;
  ObjectLinkOptions link;              // without poses: object ids through time
  UnlabelledObjectOptions unlabelled;  // given masks: objects the detector missed everywhere
  TemporalTrackOptions tracks;
  KeyframeOptions keyframes;
  FusionOptions fusion;
  TrackOptions scene_flow;
  FlowConsensusOptions flow_consensus;  // the views' flows on objects, combined
  GltfOptions gltf;

  void Check() const;  // throws u4d::Error naming the bad field
  // Every option (DeclareOptions below), for params.json.
  nlohmann::json ToJson() const;
  // `params` (ToJson(), possibly with more top-level fields) without the run
  // control options (evaluate, resume, threads, progress, allow_empty): what a
  // resumed run must share with the run that wrote the scene. params.json of
  // the earlier format (FromLegacyAblation) is read as the terms that ran.
  static nlohmann::json ResumeKey(nlohmann::json params);
};
// Every field of RunOptions and of the structs nested in it, declared once
// for params.json, --config and docs/options.md (util/options.h), and the
// preset `ablation`: the paper's ablation (AblationTerms) as joint.terms.
void DeclareOptions(OptionRegistry& r, ObjectLinkOptions* o);
void DeclareOptions(OptionRegistry& r, UnlabelledObjectOptions* o);
void DeclareOptions(OptionRegistry& r, RunOptions* o);

// Options JSON of the earlier format (params.json written before `ablation`
// became a preset: a string beside joint.terms, a term on when on in both)
// -> the terms that ran: when `j` has "ablation" and all of joint.terms, the
// terms off in that ablation are switched off and "ablation" is removed.
// Other JSON is returned as is (a new "ablation" is a preset, applied first).
nlohmann::json FromLegacyAblation(nlohmann::json j);

}  // namespace u4d
