// Evaluation of a prediction against a capture's ground truth: the library
// side of `u4d eval`.
//
// Ground truth lives under <capture>/gt (io/layout.h). A prediction directory
// is laid out like gt/ itself: instances/, depth/, flow/, joints3d/, meshes/
// (so `--pred <capture>/gt` evaluates the GT against itself). Any subset may
// be present; a modality is evaluated when both its GT and its prediction
// directory exist. Rules for missing files:
//  - GT instances / depth: every view and frame of the capture must have a
//    file (else u4d::Error naming it); GT flow likewise for frames 0..N-2 (the
//    last frame is optional), with gt/flow_valid/ required per file when that
//    directory exists; GT joints and meshes may be sparse in time.
//  - a missing prediction file counts as an empty prediction (no instance,
//    no depth, no flow, no person, no mesh) and is counted in
//    `missing_predictions`.
// With `initial_masks`, the capture's initial masks (masks/<view>/<frame>)
// are evaluated as instance predictions instead; a missing one is a dropped
// detection and counts as empty.
// docs/metrics.md defines every number reported.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "u4d/eval/dense_metrics.h"
#include "u4d/eval/identity_metrics.h"
#include "u4d/eval/mesh_metrics.h"
#include "u4d/eval/pose_metrics.h"
#include "u4d/eval/segmentation_metrics.h"
#include "u4d/eval/silhouette.h"
#include "u4d/io/capture.h"
#include "u4d/util/file.h"

namespace u4d::eval {

struct EvalOptions {
  InstanceSegOptions instances;
  PoseOptions pose;
  ChamferOptions chamfer;
  PropagateOptions propagate;
  // S_e: key-frames are frames 0, k, 2k, ...; masks are propagated from each
  // key-frame through the following k - 1 frames.
  int keyframe_interval = 10;
  // Class whose GT pixels form the "people" mask for depth and flow.
  std::string people_class = "person";
  void Check() const;
};

struct EvalInput {
  fs::path capture;  // capture root (holds capture.json and gt/)
  fs::path pred;     // prediction directory; ignored with initial_masks
  bool initial_masks = false;
};

struct MeshEval {
  int gt_meshes = 0, pred_meshes = 0, matched = 0;
  RatioMean chamfer, pred_to_gt, gt_to_pred, accuracy, completeness, f_score;
};

struct EvalReport {
  std::string source;  // what was evaluated (directory or "initial masks")
  std::optional<InstanceSegAccumulator> instances;
  // From the same matches as `instances` (and, when the prediction has
  // meshes/, its mesh files): ids per person, switches, purity, frames
  // without a mesh.
  std::optional<IdentityAccumulator> identity;
  std::optional<DepthMetrics> depth, depth_people;
  // flow_background: every pixel that is not of people_class (the static
  // scene; on a moving rig its flow is the camera's motion).
  std::optional<FlowMetrics> flow, flow_people, flow_background;
  std::optional<RatioMean> silhouette_overlap_error;  // S_e
  std::optional<PoseMetrics> poses;
  std::optional<MeshEval> meshes;
  std::optional<RatioMean> projection_error;
  std::map<std::string, int> missing_predictions;  // per modality

  nlohmann::json ToJson() const;
  std::string FormatTable() const;  // human-readable summary
};

EvalReport EvaluateCapture(const EvalInput& input, const EvalOptions& options = {});

// The forward flow (CV_32FC2, pixels) of view index `view` from `frame` to
// frame + 1; an empty Mat when there is none (every pixel is then dropped).
using FlowSource = std::function<cv::Mat(int view, int frame)>;

// The silhouette overlap error S_e of any flow (docs/metrics.md): the GT
// instance masks of every key-frame 0, k, 2k, ... (k = keyframe_interval)
// forward-warped frame by frame with `flow`, against the GT instance of the
// same id at each later frame of the key-frame's segment (1 - IoU per
// instance, averaged per view-frame, then over view-frames). EvaluateCapture
// calls it with the prediction's flow; `u4d eval --se-baselines` with OpenCV
// flows on the capture's images, so that the two are measured alike. Throws
// u4d::Error naming the file when a GT mask is missing or a flow's size
// differs from it.
RatioMean GtSilhouetteOverlap(const Capture& capture, const FlowSource& flow,
                              const EvalOptions& options = {});

}  // namespace u4d::eval
