// Consistency figures of a 4D scene that need no ground truth, so that a run
// on a real capture can be measured (paper Sec. 4: the silhouette overlap
// error S_e and the projection error, here taken against the scene's own
// segmentation as the paper's S_e is):
//
//  - S_e (own flow): the scene's instance masks at the first frame of every
//    temporal segment are forward-warped with the scene's flow, frame by
//    frame through the segment (PropagateMask), and compared with the
//    scene's masks of the same instance at each later frame: 1 - IoU per
//    (view, frame, instance), averaged. Lower is better; 0 when the flow
//    carries every mask exactly onto the next segmentation. With
//    `baseline_flows`, the same masks are propagated with OpenCV's flows
//    (DeepFlow, DIS, Farneback) computed on the capture's images instead:
//    the paper's comparison.
//  - cross-view consistency: every `pixel_step`-th person pixel with a
//    known depth is lifted to 3D and projected into every other view where
//    it lands in the image. There the depths d' of the 2x2 pixels around the
//    projection are compared with the point's depth z': any
//    |d' - z'| <= depth_tolerance z' is an agreement (the same surface is
//    seen; the 2x2 neighbourhood keeps points at a silhouette edge from
//    being judged on the wrong side of it), every known d' > (1 + tol) z' a
//    conflict (the other view sees through the point: a free-space
//    violation), otherwise an occlusion (something in front; no verdict),
//    no depth at all "unseen". Reported: the depth agreement rate
//    agree / (agree + conflict), and among agreeing points the share whose
//    instance id is the same at an agreeing pixel (label agreement).
//  - projection error: the fused meshes (meshes/<id>/<frame>.ply) rendered
//    together (z-buffered) into every view against the scene's mask of the
//    same id,
//    |render xor mask| / |mask| per (view, frame, object), averaged.
// Frames are the scene's (scene.json); cameras are the capture's
// (CameraAt(frame)). Throws u4d::Error naming the file on a missing or
// corrupt map, or a map whose size differs from its camera.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "u4d/baselines/flow_baselines.h"
#include "u4d/eval/silhouette.h"
#include "u4d/io/capture.h"
#include "u4d/util/file.h"

namespace u4d::eval {

struct ConsistencyOptions {
  double depth_tolerance = 0.02;  // relative depth difference that counts as agreement
  int pixel_step = 2;             // sample every n-th pixel in x and y for the cross-view check
  // OpenCV flows to propagate the masks with as well (they need the images).
  std::vector<baselines::FlowBaseline> baseline_flows;
  PropagateOptions propagate;
  void Check() const;
};

struct CrossViewCounts {
  int64_t points = 0;             // (pixel, other view) pairs that land in the other image
  int64_t agree = 0;              // same surface
  int64_t conflict = 0;           // the other view sees through the point
  int64_t occluded = 0;           // the other view sees something in front
  int64_t unseen = 0;             // no depth there
  int64_t label_agree = 0;        // among `agree`, the same instance id
  double DepthAgreement() const;  // agree / (agree + conflict); NaN when none
  double LabelAgreement() const;  // label_agree / agree; NaN when none
};

struct ConsistencyReport {
  RatioMean se_own_flow;                         // S_e with the scene's flow
  std::map<std::string, RatioMean> se_baseline;  // S_e with OpenCV flows, by name
  CrossViewCounts cross_view;
  std::map<std::string, CrossViewCounts> cross_view_by_view;  // by the view lifted from
  RatioMean projection_error;                                 // meshes vs the scene's masks
  nlohmann::json ToJson() const;
  std::string FormatTable() const;
};

ConsistencyReport EvaluateSceneConsistency(const Capture& capture, const fs::path& scene_dir,
                                           const ConsistencyOptions& options = {});

}  // namespace u4d::eval
