#include "u4d/eval/identity_metrics.h"

#include <cmath>
#include <map>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

constexpr int kFrames = 4;

// A 10 x 1 GT id map. Layout A: person 1 in columns 0-5, person 2 in 7-9;
// layout B: person 1 in 0-2, person 2 in 4-9.
InstanceMask GtMap(bool layout_b = false) {
  InstanceMask m{cv::Mat::zeros(1, 10, CV_16UC1), {{1, "person", 1.0}, {2, "person", 1.0}}};
  for (int x = 0; x < 10; ++x) {
    const bool one = layout_b ? x <= 2 : x <= 5;
    const bool two = layout_b ? x >= 4 : x >= 7;
    m.ids.at<uint16_t>(0, x) = one ? 1 : two ? 2 : 0;
  }
  return m;
}

// The prediction that gives GT person g the id relabel[g] (absent or 0: not predicted).
InstanceMask Relabel(const InstanceMask& gt, const std::map<int, int>& relabel) {
  InstanceMask m{cv::Mat::zeros(gt.ids.size(), CV_16UC1), {}};
  std::set<int> ids;
  for (int x = 0; x < gt.ids.cols; ++x) {
    const auto it = relabel.find(gt.ids.at<uint16_t>(0, x));
    if (it == relabel.end() || it->second == 0) continue;
    m.ids.at<uint16_t>(0, x) = static_cast<uint16_t>(it->second);
    ids.insert(it->second);
  }
  for (int id : ids) m.instances.push_back({id, "person", 1.0});
  return m;
}

// Runs EvaluateInstances on every view-frame of `pred` ([view][frame] ->
// relabelling of GT layout A, or of layout B for the views in `layout_b`) and
// feeds the matches to `acc`, as evaluate.cc does.
void Feed(const std::vector<std::vector<std::map<int, int>>>& pred, IdentityAccumulator* acc,
          const std::set<int>& layout_b = {}) {
  for (int v = 0; v < static_cast<int>(pred.size()); ++v)
    for (int f = 0; f < static_cast<int>(pred[v].size()); ++f) {
      const InstanceMask gt = GtMap(layout_b.count(v) > 0);
      const InstanceSegResult r =
          EvaluateInstances(Relabel(gt, pred[v][f]), gt, InstanceSegOptions{}, "test");
      acc->Add(v, f, r.matches);
    }
}

std::vector<std::vector<std::map<int, int>>> Same(int views, const std::map<int, int>& relabel) {
  return std::vector<std::vector<std::map<int, int>>>(
      views, std::vector<std::map<int, int>>(kFrames, relabel));
}

TEST(IdentityMetrics, PerfectPredictionHasOneIdPerPersonAndNoSwitch) {
  IdentityAccumulator acc;
  Feed(Same(2, {{1, 5}, {2, 9}}), &acc);
  const IdentitySummary s = acc.Summarize();
  ASSERT_EQ(s.people.size(), 2u);
  EXPECT_EQ(s.people[0].pred_ids, std::vector<int>{5});
  EXPECT_EQ(s.people[1].pred_ids, std::vector<int>{9});
  EXPECT_EQ(s.people[0].visible_view_frames, 2 * kFrames);
  EXPECT_EQ(s.people[0].matched_view_frames, 2 * kFrames);
  EXPECT_EQ(s.matched_people, 2);
  EXPECT_DOUBLE_EQ(s.mean_ids_per_person, 1.0);
  EXPECT_EQ(s.switches, 0);
  EXPECT_EQ(s.cross_view_disagreements, 0);
  EXPECT_DOUBLE_EQ(s.mean_people_per_pred_id, 1.0);
  EXPECT_EQ(s.shared_pred_ids, 0);
  EXPECT_FALSE(s.with_meshes);
  const nlohmann::json j = acc.ToJson();
  EXPECT_EQ(j["mean_ids_per_person"].get<double>(), 1.0);
  EXPECT_EQ(j["per_person"]["2"]["ids"].get<int>(), 1);
  EXPECT_EQ(j["per_pred_id"]["9"]["gt_ids"], nlohmann::json::array({2}));
  EXPECT_FALSE(j.contains("no_mesh_frames"));
}

TEST(IdentityMetrics, RenumberingPerViewAndFrameIsCountedExactly) {
  // Person 1 is 10 (v + 1) + f, person 2 is 100 + 10 (v + 1) + f: a new id in
  // every view-frame, like a per-image detector.
  std::vector<std::vector<std::map<int, int>>> pred(2, std::vector<std::map<int, int>>(kFrames));
  for (int v = 0; v < 2; ++v)
    for (int f = 0; f < kFrames; ++f)
      pred[v][f] = {{1, 10 * (v + 1) + f}, {2, 100 + 10 * (v + 1) + f}};
  IdentityAccumulator acc;
  Feed(pred, &acc);
  const IdentitySummary s = acc.Summarize();
  ASSERT_EQ(s.people.size(), 2u);
  for (const IdentityPerson& p : s.people) {
    EXPECT_EQ(p.pred_ids.size(), 2u * kFrames);      // 8 distinct ids
    EXPECT_EQ(p.switches, 2 * (kFrames - 1));        // 3 changes in each of 2 views
    EXPECT_EQ(p.cross_view_disagreements, kFrames);  // the 2 views differ at every frame
  }
  EXPECT_DOUBLE_EQ(s.mean_ids_per_person, 8.0);
  EXPECT_EQ(s.switches, 12);
  EXPECT_EQ(s.cross_view_disagreements, 8);
  EXPECT_EQ(s.people_of_pred_id.size(), 16u);
  EXPECT_DOUBLE_EQ(s.mean_people_per_pred_id, 1.0);
}

TEST(IdentityMetrics, SwapInOneViewGivesTwoSwitchesAndOneDisagreementPerFrame) {
  // Three views; in view 2 the ids of the two people are swapped from frame 2 on.
  auto pred = Same(3, {{1, 5}, {2, 9}});
  for (int f = 2; f < kFrames; ++f) pred[2][f] = {{1, 9}, {2, 5}};
  IdentityAccumulator acc;
  Feed(pred, &acc);
  const IdentitySummary s = acc.Summarize();
  ASSERT_EQ(s.people.size(), 2u);
  EXPECT_EQ(s.switches, 2);  // frame 1 -> 2 in view 2, once per person
  EXPECT_EQ(s.people[0].switches, 1);
  EXPECT_EQ(s.people[1].switches, 1);
  // Frames 2 and 3: two views say 5, one says 9 (for person 1), and vice versa.
  EXPECT_EQ(s.people[0].cross_view_disagreements, 2);
  EXPECT_EQ(s.people[1].cross_view_disagreements, 2);
  EXPECT_EQ(s.cross_view_disagreements, 4);
  EXPECT_EQ(s.people[0].pred_ids, (std::vector<int>{5, 9}));
  EXPECT_DOUBLE_EQ(s.mean_ids_per_person, 2.0);
  // Both ids cover both people somewhere.
  EXPECT_EQ(s.shared_pred_ids, 2);
  EXPECT_DOUBLE_EQ(s.mean_people_per_pred_id, 2.0);
  EXPECT_EQ(s.people_of_pred_id.at(5), (std::vector<int>{1, 2}));
}

TEST(IdentityMetrics, MergedIdCoversTwoPeople) {
  // One predicted id 7 over both people in every view-frame. It matches the
  // larger person: person 1 in view 0 (layout A, IoU 6/9), person 2 in view 1
  // (layout B, IoU 6/9); the smaller one is unmatched.
  IdentityAccumulator acc;
  Feed(Same(2, {{1, 7}, {2, 7}}), &acc, {1});
  const IdentitySummary s = acc.Summarize();
  ASSERT_EQ(s.people.size(), 2u);
  EXPECT_EQ(s.people[0].pred_ids, std::vector<int>{7});
  EXPECT_EQ(s.people[0].matched_view_frames, kFrames);  // view 0 only
  EXPECT_EQ(s.people[0].visible_view_frames, 2 * kFrames);
  EXPECT_DOUBLE_EQ(s.mean_ids_per_person, 1.0);  // blind to the merge...
  EXPECT_EQ(s.switches + s.cross_view_disagreements, 0);
  EXPECT_EQ(s.people_of_pred_id.at(7), (std::vector<int>{1, 2}));  // ...purity is not
  EXPECT_EQ(s.shared_pred_ids, 1);
  EXPECT_DOUBLE_EQ(s.mean_people_per_pred_id, 2.0);
}

TEST(IdentityMetrics, FramesWithoutAMesh) {
  // Masks: person 1 -> 5, person 2 -> 9, except frame 3 where person 1 is not
  // predicted in any view.
  auto pred = Same(2, {{1, 5}, {2, 9}});
  for (int v = 0; v < 2; ++v) pred[v][3] = {{2, 9}};
  IdentityAccumulator acc;
  Feed(pred, &acc);
  // GT meshes: people 1 and 2 always, person 3 (in no image) at frame 0.
  // Predicted meshes: frame 1 has 11 instead of 9, frame 2 lacks 9.
  acc.AddMeshes(0, {1, 2, 3}, {5, 9});
  acc.AddMeshes(1, {1, 2}, {5, 11});
  acc.AddMeshes(2, {1, 2}, {5});
  acc.AddMeshes(3, {1, 2}, {5, 9});
  const IdentitySummary s = acc.Summarize();
  ASSERT_TRUE(s.with_meshes);
  ASSERT_EQ(s.people.size(), 3u);
  const IdentityPerson &p1 = s.people[0], &p2 = s.people[1], &p3 = s.people[2];
  EXPECT_EQ(p1.visible_frames, 4);
  EXPECT_EQ(p1.no_mesh_frames, 1);  // frame 3: unmatched (mesh 5 exists, but is not its)
  EXPECT_EQ(p1.unmatched_frames, 1);
  EXPECT_EQ(p2.visible_frames, 4);
  EXPECT_EQ(p2.no_mesh_frames, 2);  // frames 1 and 2: no mesh 9
  EXPECT_EQ(p2.unmatched_frames, 0);
  EXPECT_EQ(p3.gt_id, 3);
  EXPECT_EQ(p3.label, "");
  EXPECT_EQ(p3.visible_frames, 1);
  EXPECT_EQ(p3.no_mesh_frames, 1);
  EXPECT_EQ(p3.unmatched_frames, 1);
  EXPECT_TRUE(p3.pred_ids.empty());
  EXPECT_EQ(s.visible_frames, 9);
  EXPECT_EQ(s.no_mesh_frames, 4);
  EXPECT_EQ(s.unmatched_frames, 2);
  EXPECT_EQ(s.matched_people, 2);  // person 3 is not in the mean
  EXPECT_DOUBLE_EQ(s.mean_ids_per_person, 1.0);
  const nlohmann::json j = acc.ToJson();
  EXPECT_EQ(j["no_mesh_frames"].get<int>(), 4);
  EXPECT_EQ(j["per_person"]["2"]["no_mesh_frames"].get<int>(), 2);
  EXPECT_EQ(j["people"].get<int>(), 3);
}

TEST(IdentityMetrics, ThresholdGapsAndBadInput) {
  IdentityAccumulator acc(0.5);
  auto match = [](int gt, int pred, double iou) {
    InstanceMatch m;
    m.gt_id = gt;
    m.pred_id = pred;
    m.label = "person";
    m.iou = iou;
    return m;
  };
  acc.Add(0, 0, {match(1, 4, 0.9)});
  acc.Add(0, 1, {match(1, 6, 0.4)});  // below match_iou: visible, unmatched
  acc.Add(0, 2, {match(1, 6, 0.5)});  // a change across a gap is no switch
  acc.Add(0, 3, {match(1, 6, 1.0)});
  IdentitySummary s = acc.Summarize();
  ASSERT_EQ(s.people.size(), 1u);
  EXPECT_EQ(s.people[0].pred_ids, (std::vector<int>{4, 6}));
  EXPECT_EQ(s.people[0].visible_view_frames, 4);
  EXPECT_EQ(s.people[0].matched_view_frames, 3);
  EXPECT_EQ(s.switches, 0);
  acc.Add(0, 4, {match(1, 4, 0.7)});  // 6 -> 4 on consecutive matched frames
  EXPECT_EQ(acc.Summarize().switches, 1);

  EXPECT_THROW(acc.Add(0, 4, {match(1, 4, 0.7)}), Error);  // given twice
  EXPECT_THROW(acc.Add(-1, 0, {}), Error);
  EXPECT_THROW(acc.Add(1, 0, {match(0, 4, 0.7)}), Error);
  EXPECT_THROW(IdentityAccumulator(0.0), Error);
  acc.AddMeshes(0, {}, {});
  EXPECT_THROW(acc.AddMeshes(0, {}, {}), Error);

  // Nobody matched: the means are NaN (null in eval.json).
  IdentityAccumulator none;
  none.Add(0, 0, {match(1, 0, 0.0)});
  s = none.Summarize();
  EXPECT_EQ(s.matched_people, 0);
  EXPECT_TRUE(std::isnan(s.mean_ids_per_person));
  EXPECT_TRUE(std::isnan(s.mean_people_per_pred_id));
  EXPECT_TRUE(none.ToJson()["mean_ids_per_person"].is_null());
}

}  // namespace
}  // namespace u4d::eval
