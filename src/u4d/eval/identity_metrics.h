// Identity figures of an instance prediction over a whole sequence: does a GT
// person keep one predicted id across views and frames, and does that id have
// a mesh? (docs/metrics.md, "Identity").
//
// No new matching: the accumulator is fed the per-view-frame InstanceMatch of
// EvaluateInstances (segmentation_metrics.h). A visible GT instance g is
// *matched* to predicted id p in a view-frame when its match has pred_id p != 0
// and IoU >= match_iou (the threshold of InstanceSegOptions, the same that
// decides `missed`); otherwise it is visible but unmatched. From these:
//  - ids per person: the distinct predicted ids a GT person is matched to over
//    all views and frames (ideal 1); the mean is over people matched at least
//    once, the never-matched ones are counted apart;
//  - in-view switches: per view, over pairs of frames (f, f + 1) in which the
//    person is matched in both, the number of pairs whose ids differ (a change
//    across a frame where the person is unmatched is not a switch);
//  - cross-view disagreements: per frame, the number of views in which the
//    person is matched minus the number of those views that agree on its most
//    common matched id at that frame (ties do not change the count);
//  - purity: per predicted id, the distinct GT people it is matched to (1 is
//    pure, 2 means two people share the id somewhere in the sequence);
//  - frames without a mesh (only when AddMeshes was called): for each frame
//    given to AddMeshes and each GT person visible at that frame (a GT mesh, or
//    a visible GT instance in some view), whether none of the predicted ids the
//    person is matched to at that frame (in any view) has a predicted mesh at
//    that frame. A frame where the person is matched in no view counts as
//    without a mesh, and also apart as `unmatched`.
// Every GT instance id is a "person" here, whatever its class.
#pragma once

#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "u4d/eval/segmentation_metrics.h"

namespace u4d::eval {

// Figures of one GT person.
struct IdentityPerson {
  int gt_id = 0;
  std::string label;            // class of the GT instance ("" if only seen as a mesh)
  std::vector<int> pred_ids;    // distinct predicted ids matched, ascending
  int visible_view_frames = 0;  // view-frames where the GT instance is visible
  int matched_view_frames = 0;  // ... and matched (IoU >= match_iou)
  int switches = 0;             // in-view identity switches, summed over views
  int cross_view_disagreements = 0;
  int visible_frames = 0;    // frames given to AddMeshes where the person is visible
  int no_mesh_frames = 0;    // ... and none of its matched ids has a mesh
  int unmatched_frames = 0;  // ... of those, frames where it is matched in no view
};

struct IdentitySummary {
  double match_iou = 0.5;
  std::vector<IdentityPerson> people;  // ascending GT id
  // Purity: the GT people each predicted id is matched to (ascending).
  std::map<int, std::vector<int>> people_of_pred_id;
  int matched_people = 0;          // people matched at least once
  double mean_ids_per_person = 0;  // over matched people; NaN when none
  int switches = 0, cross_view_disagreements = 0;
  double mean_people_per_pred_id = 0;  // over matched predicted ids; NaN when none
  int shared_pred_ids = 0;             // predicted ids matched to >= 2 people
  bool with_meshes = false;
  int visible_frames = 0, no_mesh_frames = 0, unmatched_frames = 0;  // summed over people
};

struct IdentityAccumulator {
  double match_iou = 0.5;
  // Per GT id: its matched predicted id (0 = visible but unmatched) per
  // (view, frame) in which it is visible.
  std::map<int, std::map<std::pair<int, int>, int>> matched;
  std::map<int, std::string> labels;  // class of each GT id (first seen)
  bool with_meshes = false;
  // Per frame given to AddMeshes: GT ids with a GT mesh, predicted ids with a mesh.
  std::map<int, std::set<int>> gt_meshes, pred_meshes;

  // Throws u4d::Error unless match_iou is in (0, 1].
  explicit IdentityAccumulator(double match_iou = 0.5);

  // The matches of one view-frame (view and frame are indices >= 0). Throws
  // u4d::Error on a negative index, a GT id <= 0, or a (GT id, view, frame)
  // given twice.
  void Add(int view, int frame, const std::vector<InstanceMatch>& matches);
  // The meshes of one frame: the GT ids that have a GT mesh at `frame` and the
  // predicted ids that have a predicted mesh at `frame`. Throws u4d::Error on a
  // negative frame or a frame given twice.
  void AddMeshes(int frame, const std::vector<int>& gt_mesh_ids,
                 const std::vector<int>& pred_mesh_ids);

  IdentitySummary Summarize() const;
  nlohmann::json ToJson() const;  // Summarize() as the "identity" block of eval.json
};

}  // namespace u4d::eval
