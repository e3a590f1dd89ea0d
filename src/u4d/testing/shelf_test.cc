// Shelf (real data, /work/shared/data/shelf_pose): the pose pipeline's PCP
// against the published ground truth, with the literature's protocol: per GT
// actor (ids 0-2 = actors 1-3; id 3, the fourth person labelled in a few
// frames, is not part of the standard table) matched to its nearest predicted
// person, average-PCP with alpha 0.5 on Shelf's 14 joints and limbs
// (eval/pose_metrics.h Shelf14Limbs), and the mean of the three actors.
// Also a hand-made PAF assembly case with a known answer.
#include <map>

#include <gtest/gtest.h>

#include "u4d/eval/pose_metrics.h"
#include "u4d/io/import_fourda.h"
#include "u4d/testing/shelf.h"
#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

const fs::path kShelf = DataDir() / "shelf_pose";

std::vector<eval::Person3d> ToShelf14(const std::vector<Pose3d>& poses) {
  std::vector<eval::Person3d> out;
  for (const Pose3d& p : poses) {
    eval::Person3d q;
    q.id = p.person_id;
    for (const Eigen::Vector4d& x : Shelf14FromH36m17(p)) {
      q.joints.push_back(x.head<3>());
      q.confidence.push_back(x.w());
    }
    out.push_back(q);
  }
  return out;
}

// Per GT actor id: the pooled metrics over the frames where it is labelled.
std::map<int, eval::PoseMetrics> PerActor(const std::vector<std::vector<Pose3d>>& pred,
                                          const FourdaGroundTruth& gt) {
  const auto limbs = eval::Shelf14Limbs();
  std::map<int, eval::PoseMetrics> out;
  for (size_t f = 0; f < std::min(pred.size(), gt.frames.size()); ++f) {
    const auto p = ToShelf14(pred[f]);
    for (const FourdaPerson3d& g : gt.frames[f]) {
      eval::Person3d q;
      q.id = g.id;
      for (int j = 0; j < 14; ++j) {
        q.joints.push_back(g.joints.col(j).head<3>());
        q.confidence.push_back(g.joints(3, j));
      }
      out[g.id].Add(eval::EvaluatePoses(p, {q}, limbs, {}, "shelf frame " + std::to_string(f)));
    }
  }
  return out;
}

double MeanPcpOfActors123(const std::map<int, eval::PoseMetrics>& m) {
  double sum = 0;
  for (int id = 0; id < 3; ++id) sum += m.at(id).pcp.Rate();
  return sum / 3;
}

TEST(Shelf, PcpOfTheFullPipeline) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kShelf);
  const FourdaGroundTruth gt = ReadFourdaGroundTruth(kShelf / "gt.txt");
  const ShelfPipelineResult result = RunShelfPipeline(kShelf);
  ASSERT_EQ(result.raw.size(), gt.frames.size());
  const auto raw = PerActor(result.raw, gt);
  const auto tracked = PerActor(result.tracked, gt);
  ASSERT_TRUE(raw.count(0) && raw.count(1) && raw.count(2));
  const double raw_pcp = MeanPcpOfActors123(raw), tracked_pcp = MeanPcpOfActors123(tracked);
  std::printf("Shelf average PCP (actors 1-3): raw %.2f %%, tracked %.2f %%\n", 100 * raw_pcp,
              100 * tracked_pcp);
  for (const auto& [name, c] : tracked.at(0).pcp_per_limb) {
    std::printf("  %-10s", name.c_str());
    for (int id = 0; id < 3; ++id)
      std::printf(" %6.1f", 100 * tracked.at(id).pcp_per_limb.at(name).Rate());
    std::printf("\n");
  }
  // Measured 95.3 % raw and 96.0 % tracked (published multi-view methods:
  // ~96-97 %). Floors a little below the measured figures: a regression in
  // assembly, association or triangulation costs several points.
  EXPECT_GE(tracked_pcp, 0.95);
  EXPECT_GE(raw_pcp, 0.945);
  // Actor 1 is visible in most frames and nearly perfect (measured 99.4 %).
  EXPECT_GE(tracked.at(0).pcp.Rate(), 0.98);
}

// Two people, each a neck (1), right shoulder (2) and mid hip (8), with PAF
// scores that favour the correct pairs; candidates deliberately listed in a
// different order per joint type.
TEST(Shelf, PafAssemblyPicksTheHighestScoringConnections) {
  FourdaDetectionFrame frame;
  frame.joints.assign(25, Eigen::Matrix3Xd(3, 0));
  auto set = [&](int type, std::vector<Eigen::Vector3d> c) {
    frame.joints[type].resize(3, c.size());
    for (size_t i = 0; i < c.size(); ++i) frame.joints[type].col(i) = c[i];
  };
  set(1, {{0.2, 0.2, 0.9}, {0.7, 0.2, 0.9}});      // necks of A, B
  set(2, {{0.65, 0.25, 0.8}, {0.15, 0.25, 0.8}});  // shoulders of B, A
  set(8, {{0.2, 0.6, 0.9}, {0.7, 0.6, 0.9}});      // hips of A, B
  set(5, {{0.25, 0.25, 0.8}, {0.75, 0.25, 0.8}});  // left shoulders of A, B
  const auto& limbs = Body25Limbs();
  frame.pafs.resize(26);
  for (int l = 0; l < 26; ++l)
    frame.pafs[l] =
        Eigen::MatrixXd::Zero(frame.joints[limbs[l][0]].cols(), frame.joints[limbs[l][1]].cols());
  frame.pafs[0] << 0.9, 0.2, 0.3, 0.8;   // neck-midhip: A-A, B-B
  frame.pafs[7] << 0.3, 0.9, 0.85, 0.2;  // neck-rshoulder: A-shoulder1, B-shoulder0
  frame.pafs[11] << 0.9, 0.1, 0.1, 0.9;  // neck-lshoulder: A-A, B-B
  PafAssemblyOptions o;
  o.min_joints = 3;
  const std::vector<Pose2d> people = AssembleBody25(frame, 1000, 500, o);
  ASSERT_EQ(people.size(), 2u);
  for (const Pose2d& p : people) {
    const Eigen::Vector3d& s = p.keypoints[coco17::kRightShoulder];
    const Eigen::Vector3d& l = p.keypoints[coco17::kLeftShoulder];
    ASSERT_GT(s.z(), 0);
    ASSERT_GT(l.z(), 0);
    // Both shoulders of one assembled person belong to the same true person
    // (A: x 150 and 250, B: 650 and 750; coordinates scaled by the size).
    EXPECT_DOUBLE_EQ(l.x() - s.x(), 100);
    EXPECT_DOUBLE_EQ(s.y(), 125);
  }
  EXPECT_NE(people[0].keypoints[coco17::kRightShoulder].x(),
            people[1].keypoints[coco17::kRightShoulder].x());
  frame.pafs[0].resize(1, 1);
  EXPECT_THROW(AssembleBody25(frame, 1000, 500, o), Error);
  EXPECT_THROW(AssembleBody25(frame, 0, 500, o), Error);
}

}  // namespace
}  // namespace u4d
