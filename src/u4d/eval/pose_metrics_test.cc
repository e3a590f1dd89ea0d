#include "u4d/eval/pose_metrics.h"

#include <cmath>

#include <gtest/gtest.h>

#include "u4d/util/check.h"
#include "u4d/util/testing.h"

namespace u4d::eval {
namespace {

// A standing H36M-17 skeleton at x offset `x`; every arm segment is 0.3 m.
Person3d Standing(int id, double x) {
  Person3d p;
  p.id = id;
  const std::vector<Eigen::Vector3d> j = {
      {0, 1.0, 0},    {-0.1, 1.0, 0}, {-0.1, 0.55, 0}, {-0.1, 0.1, 0},  // pelvis, right leg
      {0.1, 1.0, 0},  {0.1, 0.55, 0}, {0.1, 0.1, 0},                    // left leg
      {0, 1.25, 0},   {0, 1.5, 0},    {0, 1.6, 0},     {0, 1.75, 0},    // spine .. head
      {0.2, 1.5, 0},  {0.2, 1.2, 0},  {0.2, 0.9, 0},                    // left arm
      {-0.2, 1.5, 0}, {-0.2, 1.2, 0}, {-0.2, 0.9, 0}};                  // right arm
  for (const Eigen::Vector3d& v : j) p.joints.push_back(v + Eigen::Vector3d(x, 0, 0));
  p.confidence.assign(j.size(), 1.0);
  return p;
}

TEST(Pose, MpjpeOfAShiftAndOptimalMatching) {
  const std::vector<Person3d> gt = {Standing(1, 0), Standing(2, 2)};
  std::vector<Person3d> pred = {Standing(8, 2.05), Standing(9, 0.05)};  // swapped order
  const PoseMetrics m = EvaluatePoses(pred, gt, H36m17Limbs(), {}, "test");
  EXPECT_EQ(m.matched, 2);
  EXPECT_EQ(m.joints, 34);
  EXPECT_NEAR(m.Mpjpe(), 0.05, 1e-12);
  // A 0.05 m shift is within half of every limb length (>= 0.15 m): all correct.
  EXPECT_DOUBLE_EQ(m.pcp.Rate(), 1.0);
  // One prediction only: the other GT person is missed, all its limbs wrong.
  pred.pop_back();
  const PoseMetrics one = EvaluatePoses(pred, gt, H36m17Limbs(), {}, "test");
  EXPECT_EQ(one.missed, 1);
  EXPECT_NEAR(one.Mpjpe(), 0.05, 1e-12);
  EXPECT_DOUBLE_EQ(one.pcp.Rate(), 0.5);
  EXPECT_DOUBLE_EQ(one.pcp_per_person.at(2).Rate(), 1.0);
  EXPECT_DOUBLE_EQ(one.pcp_per_person.at(1).Rate(), 0.0);
}

TEST(Pose, PcpJustInsideAndJustOutside) {
  // Moving the left elbow by d moves upper and lower left arm (0.3 m each):
  // mean endpoint error d / 2 against alpha * length = 0.15 m.
  const std::vector<Person3d> gt = {Standing(1, 0)};
  for (const auto& [d, correct] : {std::pair{0.29, true}, std::pair{0.31, false}}) {
    Person3d p = Standing(1, 0);
    p.joints[12] += Eigen::Vector3d(0, 0, d);
    const PoseMetrics m = EvaluatePoses({p}, gt, H36m17Limbs(), {}, "test");
    EXPECT_DOUBLE_EQ(m.pcp_per_limb.at("upper_arm").Rate(), correct ? 1.0 : 0.5) << d;
    EXPECT_DOUBLE_EQ(m.pcp_per_limb.at("lower_arm").Rate(), correct ? 1.0 : 0.5) << d;
    EXPECT_DOUBLE_EQ(m.pcp.Rate(), correct ? 1.0 : 0.8) << d;
    EXPECT_NEAR(m.Mpjpe(), d / 17, 1e-12);
  }
}

TEST(Pose, ShelfTorsoUsesMidpointsAndMissingJoints) {
  // Shelf-14: hips 2, 3 and shoulders 8, 9; torso from mid-hip to mid-shoulder.
  Person3d g;
  g.id = 1;
  g.joints.assign(14, Eigen::Vector3d::Zero());
  g.joints[2] = {-0.1, 1, 0};
  g.joints[3] = {0.1, 1, 0};
  g.joints[8] = {-0.2, 1.5, 0};
  g.joints[9] = {0.2, 1.5, 0};
  g.confidence.assign(14, 0.0);
  for (int j : {2, 3, 8, 9}) g.confidence[j] = 1.0;
  const std::vector<Limb> torso = {Shelf14Limbs()[8]};
  ASSERT_EQ(torso[0].name, "torso");
  Person3d p = g;
  for (Eigen::Vector3d& v : p.joints) v.z() += 0.24;  // 0.24 <= 0.5 * 0.5
  EXPECT_DOUBLE_EQ(EvaluatePoses({p}, {g}, torso, {}, "t").pcp.Rate(), 1.0);
  for (Eigen::Vector3d& v : p.joints) v.z() += 0.02;  // 0.26 > 0.25
  EXPECT_DOUBLE_EQ(EvaluatePoses({p}, {g}, torso, {}, "t").pcp.Rate(), 0.0);
  // Limbs with a missing GT endpoint are not evaluated.
  EXPECT_EQ(EvaluatePoses({p}, {g}, Shelf14Limbs(), {}, "t").pcp.total, 1);
  // A limb naming a joint out of range is a broken contract.
  EXPECT_THROW(EvaluatePoses({p}, {g}, H36m17Limbs(), {}, "t"), Error);
}

TEST(Pose, ReadWriteJson) {
  const fs::path path = test_util::FreshTestDir("pose_test", "json") / "000000.json";
  WritePoses3dJson(path, {Standing(4, 1)}, "h36m17");
  std::string skeleton;
  const auto back = ReadPoses3dJson(path, &skeleton);
  EXPECT_EQ(skeleton, "h36m17");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].id, 4);
  EXPECT_NEAR((back[0].joints[10] - Eigen::Vector3d(1, 1.75, 0)).norm(), 0, 1e-12);
  EXPECT_THROW(ReadPoses3dJson(path.parent_path() / "missing.json"), Error);
  fs::remove_all(path.parent_path());
}

}  // namespace
}  // namespace u4d::eval
