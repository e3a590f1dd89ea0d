#include "u4d/eval/identity_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

nlohmann::json Num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// Number of entries minus the count of the most common value.
int Disagreements(const std::vector<int>& ids) {
  std::map<int, int> count;
  int most = 0;
  for (int id : ids) most = std::max(most, ++count[id]);
  return static_cast<int>(ids.size()) - most;
}

}  // namespace

IdentityAccumulator::IdentityAccumulator(double iou) : match_iou(iou) {
  U4D_CHECK(match_iou > 0 && match_iou <= 1, "IdentityAccumulator: match_iou must be in (0, 1]");
}

void IdentityAccumulator::Add(int view, int frame, const std::vector<InstanceMatch>& matches) {
  U4D_CHECK(view >= 0 && frame >= 0, "IdentityAccumulator: view {} / frame {} must be >= 0", view,
            frame);
  for (const InstanceMatch& m : matches) {
    U4D_CHECK(m.gt_id > 0, "IdentityAccumulator: GT id {} in view {} frame {} must be > 0", m.gt_id,
              view, frame);
    const int pred = m.pred_id != 0 && m.iou >= match_iou ? m.pred_id : 0;
    const bool inserted = matched[m.gt_id].emplace(std::make_pair(view, frame), pred).second;
    U4D_CHECK(inserted, "IdentityAccumulator: GT id {} in view {} frame {} given twice", m.gt_id,
              view, frame);
    labels.emplace(m.gt_id, m.label);
  }
}

void IdentityAccumulator::AddMeshes(int frame, const std::vector<int>& gt_mesh_ids,
                                    const std::vector<int>& pred_mesh_ids) {
  U4D_CHECK(frame >= 0, "IdentityAccumulator: frame {} must be >= 0", frame);
  U4D_CHECK(!pred_meshes.count(frame), "IdentityAccumulator: meshes of frame {} given twice",
            frame);
  with_meshes = true;
  gt_meshes[frame].insert(gt_mesh_ids.begin(), gt_mesh_ids.end());
  pred_meshes[frame].insert(pred_mesh_ids.begin(), pred_mesh_ids.end());
}

IdentitySummary IdentityAccumulator::Summarize() const {
  IdentitySummary s;
  s.match_iou = match_iou;
  s.with_meshes = with_meshes;
  std::set<int> gt_ids;
  for (const auto& [gt, views] : matched) gt_ids.insert(gt);
  for (const auto& [frame, ids] : gt_meshes) gt_ids.insert(ids.begin(), ids.end());

  std::map<int, std::set<int>> people_of_pred;
  double sum_ids = 0;
  for (int gt : gt_ids) {
    IdentityPerson p;
    p.gt_id = gt;
    if (auto it = labels.find(gt); it != labels.end()) p.label = it->second;
    static const std::map<std::pair<int, int>, int> kNone;
    const auto found = matched.find(gt);
    const auto& views = found != matched.end() ? found->second : kNone;
    std::set<int> ids;
    std::map<int, std::vector<int>> ids_at_frame;  // matched ids over views, per frame
    std::set<int> visible_at;                      // frames with a visible GT instance
    const std::pair<int, int>* prev_key = nullptr;
    int prev_pred = 0;
    for (const auto& [key, pred] : views) {  // ordered by view, then frame
      ++p.visible_view_frames;
      visible_at.insert(key.second);
      if (pred != 0) {
        ++p.matched_view_frames;
        ids.insert(pred);
        people_of_pred[pred].insert(gt);
        ids_at_frame[key.second].push_back(pred);
        if (prev_key && prev_key->first == key.first && prev_key->second + 1 == key.second &&
            prev_pred != 0 && prev_pred != pred)
          ++p.switches;
      }
      prev_key = &key;
      prev_pred = pred;
    }
    for (const auto& [frame, at] : ids_at_frame) p.cross_view_disagreements += Disagreements(at);
    p.pred_ids.assign(ids.begin(), ids.end());
    if (with_meshes)
      for (const auto& [frame, pred_ids] : pred_meshes) {
        const auto g = gt_meshes.find(frame);
        const bool visible =
            visible_at.count(frame) || (g != gt_meshes.end() && g->second.count(gt));
        if (!visible) continue;
        ++p.visible_frames;
        const auto at = ids_at_frame.find(frame);
        if (at == ids_at_frame.end()) {
          ++p.no_mesh_frames;
          ++p.unmatched_frames;
          continue;
        }
        const bool has_mesh = std::any_of(at->second.begin(), at->second.end(),
                                          [&](int id) { return pred_ids.count(id) > 0; });
        if (!has_mesh) ++p.no_mesh_frames;
      }
    if (!p.pred_ids.empty()) {
      ++s.matched_people;
      sum_ids += static_cast<double>(p.pred_ids.size());
    }
    s.switches += p.switches;
    s.cross_view_disagreements += p.cross_view_disagreements;
    s.visible_frames += p.visible_frames;
    s.no_mesh_frames += p.no_mesh_frames;
    s.unmatched_frames += p.unmatched_frames;
    s.people.push_back(std::move(p));
  }
  s.mean_ids_per_person = s.matched_people > 0 ? sum_ids / s.matched_people : kNaN;
  double sum_people = 0;
  for (const auto& [pred, people] : people_of_pred) {
    s.people_of_pred_id[pred].assign(people.begin(), people.end());
    sum_people += static_cast<double>(people.size());
    if (people.size() >= 2) ++s.shared_pred_ids;
  }
  s.mean_people_per_pred_id =
      people_of_pred.empty() ? kNaN : sum_people / static_cast<double>(people_of_pred.size());
  return s;
}

nlohmann::json IdentityAccumulator::ToJson() const {
  const IdentitySummary s = Summarize();
  nlohmann::json people = nlohmann::json::object();
  for (const IdentityPerson& p : s.people) {
    nlohmann::json j = {{"label", p.label},
                        {"ids", p.pred_ids.size()},
                        {"pred_ids", p.pred_ids},
                        {"visible_view_frames", p.visible_view_frames},
                        {"matched_view_frames", p.matched_view_frames},
                        {"switches_in_view", p.switches},
                        {"cross_view_disagreements", p.cross_view_disagreements}};
    if (s.with_meshes) {
      j["visible_frames"] = p.visible_frames;
      j["no_mesh_frames"] = p.no_mesh_frames;
      j["unmatched_frames"] = p.unmatched_frames;
    }
    people[std::to_string(p.gt_id)] = j;
  }
  nlohmann::json preds = nlohmann::json::object();
  for (const auto& [pred, gts] : s.people_of_pred_id)
    preds[std::to_string(pred)] = {{"people", gts.size()}, {"gt_ids", gts}};
  nlohmann::json j = {{"match_iou", s.match_iou},
                      {"people", s.people.size()},
                      {"matched_people", s.matched_people},
                      {"mean_ids_per_person", Num(s.mean_ids_per_person)},
                      {"switches_in_view", s.switches},
                      {"cross_view_disagreements", s.cross_view_disagreements},
                      {"pred_ids", s.people_of_pred_id.size()},
                      {"mean_people_per_pred_id", Num(s.mean_people_per_pred_id)},
                      {"shared_pred_ids", s.shared_pred_ids},
                      {"per_person", people},
                      {"per_pred_id", preds}};
  if (s.with_meshes) {
    j["visible_frames"] = s.visible_frames;
    j["no_mesh_frames"] = s.no_mesh_frames;
    j["unmatched_frames"] = s.unmatched_frames;
  }
  return j;
}

}  // namespace u4d::eval
