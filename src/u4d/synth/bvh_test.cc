// BVH parsing and forward kinematics, and retargeting onto the 17-joint
// skeleton, checked on the real CMU subject 131 files (metres, 120 fps, y up).
#include "u4d/synth/bvh.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "u4d/synth/skeleton.h"
#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"

namespace u4d::synth {
namespace {

// The CMU clips shipped in data/mocap.
fs::path CmuClip(const std::string& take) {
  return ShippedDataFile(fs::path("mocap") / ("scaled_131_" + take + ".bvh"));
}

const BvhMotion& Cmu01() {
  static const BvhMotion m = ReadBvh(CmuClip("01"));
  return m;
}

TEST(Bvh, HeaderCountsMatchTheFile) {
  const BvhMotion& m = Cmu01();
  EXPECT_EQ(m.num_frames, 995);
  EXPECT_NEAR(m.frame_time, 0.008333, 1e-9);
  EXPECT_EQ(m.values.rows(), 995);
  // 31 joints: root with 6 channels, 30 with 3 -> 96 channels; 7 End Sites.
  EXPECT_EQ(m.num_channels, 96);
  EXPECT_EQ(m.joints.size(), 38u);
  EXPECT_EQ(m.joints[0].name, "Hips");
  EXPECT_EQ(m.joints[0].channels.size(), 6u);
  const BvhMotion m2 = ReadBvh(CmuClip("02"));
  EXPECT_EQ(m2.num_frames, 1248);
  // First motion value of 131_02 is the root X position in the file.
  EXPECT_NEAR(m2.values(0, 0), 0.271524, 1e-12);
}

TEST(Bvh, ChannelOrderIsReadPerJoint) {
  const BvhMotion& m = Cmu01();
  const int shoulder = FindBvhJoint(m, "LeftShoulder");
  ASSERT_GE(shoulder, 0);
  ASSERT_EQ(m.joints[shoulder].channels.size(), 3u);
  EXPECT_EQ(m.joints[shoulder].channels[1],
            BvhChannel::kXrotation);  // "Zrotation Xrotation Yrotation"
  const int hip = FindBvhJoint(m, "LeftHip");
  EXPECT_EQ(m.joints[hip].channels[1], BvhChannel::kYrotation);
}

TEST(Bvh, BoneLengthsAreConstantOverAllFrames) {
  const BvhMotion& m = Cmu01();
  double worst = 0;
  for (int f = 0; f < m.num_frames; ++f) {
    const std::vector<Rigid3d> w = BvhForwardKinematics(m, f);
    for (size_t j = 1; j < m.joints.size(); ++j) {
      const double len = (w[j].translation - w[m.joints[j].parent].translation).norm();
      worst = std::max(worst, std::abs(len - m.joints[j].offset.norm()));
      ASSERT_TRUE(IsRotation(w[j].rotation, 1e-9));
    }
  }
  EXPECT_LT(worst, 1e-9);
}

TEST(Bvh, FigureHeightAndFeetArePlausible) {
  const BvhMotion& m = Cmu01();
  const int head_end = FindBvhJoint(m, "Head_End");
  const std::vector<int> feet = {FindBvhJoint(m, "LeftToe"),     FindBvhJoint(m, "RightToe"),
                                 FindBvhJoint(m, "LeftAnkle"),   FindBvhJoint(m, "RightAnkle"),
                                 FindBvhJoint(m, "LeftToe_End"), FindBvhJoint(m, "RightToe_End")};
  for (int f : feet) ASSERT_GE(f, 0);
  const std::vector<Rigid3d> rest = BvhRestPose(m);
  double rest_min = 1e9;
  for (const Rigid3d& t : rest) rest_min = std::min(rest_min, t.translation.y());
  // The CMU Head_End joint sits below the crown, so the joint span of the
  // skeleton (1.37 m here) is shorter than the stature; the stature estimated
  // from the hip height (~0.53 of the stature for adults) must be 1.5-2.0 m.
  const double rest_span = rest[head_end].translation.y() - rest_min;
  EXPECT_GT(rest_span, 1.3);
  EXPECT_LT(rest_span, 1.9);
  const double stature_from_hips = (rest[0].translation.y() - rest_min) / 0.53;
  EXPECT_GT(stature_from_hips, 1.5);
  EXPECT_LT(stature_from_hips, 2.0);
  std::printf("CMU 131: joint span %.3f m, stature from hip height %.3f m\n", rest_span,
              stature_from_hips);
  // Over time: a foot joint is (nearly) the lowest point in most frames.
  int feet_lowest = 0;
  double max_stature = 0;
  for (int f = 0; f < m.num_frames; ++f) {
    const std::vector<Rigid3d> w = BvhForwardKinematics(m, f);
    double lowest = 1e9, lowest_foot = 1e9;
    for (const Rigid3d& t : w) lowest = std::min(lowest, t.translation.y());
    for (int j : feet) lowest_foot = std::min(lowest_foot, w[j].translation.y());
    if (lowest_foot - lowest < 0.03) ++feet_lowest;
    max_stature = std::max(max_stature, w[head_end].translation.y() - lowest_foot);
  }
  EXPECT_GT(feet_lowest, 0.95 * m.num_frames);
  EXPECT_GT(max_stature, 1.3);
  EXPECT_LT(max_stature, 1.9);
}

TEST(Bvh, ErrorsNameTheFile) {
  try {
    ReadBvh("/nonexistent/walk.bvh");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/walk.bvh"), std::string::npos);
  }
  const std::string text =
      "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition "
      "Zrotation Yrotation Xrotation\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 2\n"
      "Frame Time: 0.1\n0 0 0 0 0 0\n1 2 3 4 5\n";
  try {
    ParseBvh(text, "short.bvh");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("short.bvh"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  std::string bad = text;
  bad.replace(bad.find("Zrotation"), 9, "Wrotation");
  try {
    ParseBvh(bad, "bad.bvh");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.bvh:5"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("Wrotation"), std::string::npos);
  }
  // A complete small file parses, and FK applies the channels in order.
  std::string good = text;
  good.replace(good.find("1 2 3 4 5"), 9, "1 2 3 0 90 0");
  const BvhMotion m = ParseBvh(good, "good.bvh");
  const std::vector<Rigid3d> w = BvhForwardKinematics(m, 1);
  EXPECT_NEAR((w[0].translation - Eigen::Vector3d(1, 2, 3)).norm(), 0, 1e-12);
  // End Site offset (0,1,0) is unchanged by a rotation about y.
  EXPECT_NEAR((w[1].translation - Eigen::Vector3d(1, 3, 3)).norm(), 0, 1e-12);
  EXPECT_THROW(BvhForwardKinematics(m, 2), Error);
}

// Retargeting: our bone lengths stay constant, and our bones point where the
// BVH's corresponding bones point (the file's ground truth), at every frame.
TEST(Retarget, BonesFollowTheMocapAndKeepTheirLength) {
  const BvhMotion& m = Cmu01();
  const BodyShape shape = MakeBodyShape(1.68, 1.05);
  RetargetOptions opt;
  opt.fps = 30;
  opt.ground_each_frame = false;
  const MocapClip clip = RetargetBvh(m, shape, opt);
  // 995 frames at 1/120 s = 8.28 s -> 249 samples at 30 fps.
  ASSERT_EQ(clip.poses.size(), 249u);
  struct Pair {
    int ours_a, ours_b;
    const char* bvh_a;
    const char* bvh_b;
  };
  const Pair pairs[] = {{kLeftHip, kLeftKnee, "LeftHip", "LeftKnee"},
                        {kLeftKnee, kLeftAnkle, "LeftKnee", "LeftAnkle"},
                        {kRightKnee, kRightAnkle, "RightKnee", "RightAnkle"},
                        {kLeftShoulder, kLeftElbow, "LeftShoulder", "LeftElbow"},
                        {kRightElbow, kRightWrist, "RightElbow", "RightWrist"}};
  double worst_angle = 0, worst_len = 0, worst_pelvis = 0;
  const double scale = (shape.rest[kPelvis].y() - shape.rest[kLeftAnkle].y()) /
                       (BvhRestPose(m)[0].translation.y() -
                        BvhRestPose(m)[FindBvhJoint(m, "LeftAnkle")].translation.y());
  for (size_t i = 0; i < clip.poses.size(); ++i) {
    const BodyPose& pose = clip.poses[i];
    for (const auto& [parent, child] : SkeletonBones()) {
      const double len = (pose.position[child] - pose.position[parent]).norm();
      worst_len =
          std::max(worst_len, std::abs(len - (shape.rest[child] - shape.rest[parent]).norm()));
    }
    // Sample i is at 4.0002 i source frames; compare with the nearest frame.
    const int f = std::min<int>(std::lround(i / 30.0 / m.frame_time), m.num_frames - 1);
    const std::vector<Rigid3d> w = BvhForwardKinematics(m, f);
    for (const Pair& p : pairs) {
      const Eigen::Vector3d ours = (pose.position[p.ours_b] - pose.position[p.ours_a]).normalized();
      const Eigen::Vector3d theirs =
          (w[FindBvhJoint(m, p.bvh_b)].translation - w[FindBvhJoint(m, p.bvh_a)].translation)
              .normalized();
      worst_angle = std::max(worst_angle, std::acos(std::clamp(ours.dot(theirs), -1.0, 1.0)));
    }
    worst_pelvis =
        std::max(worst_pelvis, (pose.position[kPelvis] - scale * w[0].translation).norm());
  }
  EXPECT_LT(worst_len, 1e-9);
  // Nearest-frame comparison: at most 0.002 frames of motion between them.
  EXPECT_LT(worst_angle * 180 / M_PI, 3.0);
  EXPECT_LT(worst_pelvis, 0.01);
  std::printf("retarget: worst bone direction error %.3f deg, pelvis %.4f m\n",
              worst_angle * 180 / M_PI, worst_pelvis);
}

TEST(Retarget, GroundedClipHasFeetOnTheFloorAndSamplesContinuously) {
  const MocapClip clip = RetargetBvh(Cmu01(), MakeBodyShape(1.8), RetargetOptions{});
  for (const BodyPose& pose : clip.poses) {
    ASSERT_NEAR(LowestFootHeight(clip.shape, pose), 0, 1e-9);
  }
  // Interpolated samples lie between their neighbours.
  const BodyPose mid = SampleClip(clip, 2.5 / clip.fps);
  const Eigen::Vector3d expect =
      0.5 * (clip.poses[2].position[kPelvis] + clip.poses[3].position[kPelvis]);
  EXPECT_LT((mid.position[kPelvis] - expect).norm(), 1e-9);
  EXPECT_NEAR(clip.Duration(), 248 / 30.0, 1e-9);
}

}  // namespace
}  // namespace u4d::synth
