// E_p's sub-terms alone against their formulas (pose_prior.h), on a hand-built
// PosePriorMap of 3x3 pixels and a pinhole camera, and their gate by the
// label in JointEnergy (joint_energy.h).
#include "u4d/joint/pose_prior.h"

#include <cmath>

#include <gtest/gtest.h>

#include "u4d/joint/joint_energy.h"

namespace u4d {
namespace {

// Pixel 4 (the centre) covered by person 2 with w(p) = 0.8, c(p) = 0.5,
// δ(p) = (1, 2) and bone 0; the other pixels covered by no one.
PosePriorMap Map() {
  PosePriorMap map;
  map.width = map.height = 3;
  map.bone = cv::Mat(3, 3, CV_32S, cv::Scalar(-1));
  map.object = cv::Mat::zeros(3, 3, CV_16U);
  map.weight = cv::Mat::zeros(3, 3, CV_32F);
  map.colour_weight = cv::Mat::zeros(3, 3, CV_32F);
  map.motion_2d = cv::Mat::zeros(3, 3, CV_32FC2);
  map.has_motion = cv::Mat::zeros(3, 3, CV_8U);
  map.bone.at<int>(1, 1) = 0;
  map.object.at<uint16_t>(1, 1) = 2;
  map.weight.at<float>(1, 1) = 0.8f;
  map.colour_weight.at<float>(1, 1) = 0.5f;
  map.motion_2d.at<cv::Vec2f>(1, 1) = cv::Vec2f(1, 2);
  map.has_motion.at<uint8_t>(1, 1) = 1;
  PriorBone bone;  // along +y at z = 5, radius 0.1 at a and at b, no motion
  bone.object_id = 2;
  bone.a = bone.a1 = Eigen::Vector3d(0, 0, 5);
  bone.b = bone.b1 = Eigen::Vector3d(0, 1, 5);
  bone.rotation = Eigen::Matrix3d::Identity();
  bone.radius = bone.radius_a = bone.radius_b = 0.1;
  map.bones = {bone};
  return map;
}

// f = 100, principal point (1, 1), at the world origin looking down +z.
Camera Pinhole() {
  Camera camera;
  camera.width = camera.height = 3;
  camera.K << 100, 0, 1, 0, 100, 1, 0, 0, 1;
  return camera;
}

// e_2d^S + e_2d^L = w(p) [l ≠ k] + w(p) c(p) [l ≠ k].
TEST(PosePriorTest, LabelCostIsE2dSPlusE2dL) {
  const PosePriorMap map = Map();
  EXPECT_NEAR(PoseLabelCost(map, 4, 1), 0.8 * (1 + 0.5), 1e-6);
  EXPECT_NEAR(PoseLabelCost(map, 4, 0), 0.8 * (1 + 0.5), 1e-6);
  EXPECT_EQ(PoseLabelCost(map, 4, 2), 0.0);  // the covering person's own label
  EXPECT_EQ(PoseLabelCost(map, 0, 1), 0.0);  // no person here
}

// e_2d^M = w(p) (1 − exp(−||m − δ(p)||² / 2σ_m²)).
TEST(PosePriorTest, Motion2dCostIsE2dM) {
  const PosePriorMap map = Map();
  PosePriorOptions options;
  options.sigma_motion_px = 3;
  // m − δ = (3, 4): ||·||² = 25.
  EXPECT_NEAR(PoseMotion2dCost(map, 4, Eigen::Vector2f(4, 6), options),
              0.8 * (1 - std::exp(-25.0 / 18.0)), 1e-6);
  EXPECT_NEAR(PoseMotion2dCost(map, 4, Eigen::Vector2f(1, 2), options), 0.0, 1e-12);
  EXPECT_EQ(PoseMotion2dCost(map, 0, Eigen::Vector2f(4, 6), options), 0.0);  // δ unknown
}

// e_3d^S = w(p) (1 − exp(−max(0, dist(Φ(p), bone) − R)² / 2σ_s²)).
TEST(PosePriorTest, Pose3dCostShapePart) {
  PosePriorMap map = Map();
  const Camera camera = Pinhole();
  PosePriorOptions options;
  options.sigma_shape_m = 0.05;
  const Eigen::Vector2d pixel(1, 1);
  // 0.3 m from the axis, R = 0.1: 0.2 outside; 0.2² / (2 · 0.05²) = 8.
  EXPECT_NEAR(Pose3dCost(map, 4, Eigen::Vector3d(0.3, 0.5, 5), pixel, camera, options),
              0.8 * (1 - std::exp(-8.0)), 1e-6);
  // Inside the capsule: 0.
  EXPECT_NEAR(Pose3dCost(map, 4, Eigen::Vector3d(0.05, 0.5, 5), pixel, camera, options), 0.0,
              1e-12);
  // Beyond the end b: distance to b, 0.25 − 0.1 = 0.15 outside; 0.15² / 0.005 = 4.5.
  EXPECT_NEAR(Pose3dCost(map, 4, Eigen::Vector3d(0, 1.25, 5), pixel, camera, options),
              0.8 * (1 - std::exp(-4.5)), 1e-6);
  // A tapered capsule: R = 0.1 at a, 0.2 at b, 0.15 half way; 0.3 − 0.15 = 0.15 outside.
  map.bones[0].radius_b = map.bones[0].radius = 0.2;
  EXPECT_NEAR(Pose3dCost(map, 4, Eigen::Vector3d(0.3, 0.5, 5), pixel, camera, options),
              0.8 * (1 - std::exp(-4.5)), 1e-6);
  // No bone at the pixel: 0.
  EXPECT_EQ(Pose3dCost(map, 0, Eigen::Vector3d(3, 3, 5), pixel, camera, options), 0.0);
}

// e_3d^M = w(p) (1 − exp(−||p + m − Π_{t+1}(a' + R_i (Φ(p) − a))||² / 2σ_m²)).
TEST(PosePriorTest, Pose3dCostMotionPart) {
  PosePriorMap map = Map();
  map.bones[0].has_motion = true;
  map.bones[0].a1 = Eigen::Vector3d(0.1, 0, 5);  // the bone moves 0.1 m along x, no rotation
  map.bones[0].b1 = Eigen::Vector3d(0.1, 1, 5);
  const Camera camera = Pinhole();
  PosePriorOptions options;
  options.sigma_shape_m = 0.05;
  options.sigma_motion_px = 3;
  // Φ(p) = (0.3, 0.5, 5) moves to (0.4, 0.5, 5), seen at (100 · 0.4 / 5 + 1, 100 · 0.5 / 5 + 1)
  // = (9, 11); p + m = (12, 15) is (3, 4) away: 25 / 18. Plus e_3d^S = 1 − exp(−8) as above.
  EXPECT_NEAR(
      Pose3dCost(map, 4, Eigen::Vector3d(0.3, 0.5, 5), Eigen::Vector2d(12, 15), camera, options),
      0.8 * ((1 - std::exp(-8.0)) + (1 - std::exp(-25.0 / 18.0))), 1e-6);
  // Following the predicted motion exactly leaves e_3d^S only.
  EXPECT_NEAR(
      Pose3dCost(map, 4, Eigen::Vector3d(0.3, 0.5, 5), Eigen::Vector2d(9, 11), camera, options),
      0.8 * (1 - std::exp(-8.0)), 1e-6);
}

// The gate of e_3d by the label (PosePriorOptions::shape_own_label_only): at
// a pixel of person 2's capsule, a 3D point 0.3 m off the bone's axis pays
// e_3d when the pixel is labelled 2 and nothing under another label (the
// pixel shows something else, e.g. a person in front); ungated, every label
// pays it and the depth is pulled onto the capsule whatever the label.
TEST(PosePriorTest, Pose3dGatedByTheLabel) {
  const Camera camera = Pinhole();
  JointEnergy energy;
  energy.width = energy.height = 3;
  energy.num_pixels = 9;
  energy.num_labels = 3;
  energy.label_unary.assign(27, 0.f);
  energy.camera_t = energy.camera_t1 = &camera;
  energy.pose = Map();
  energy.use_pose = true;
  energy.pose_3d_share = 1;
  energy.pose_options.sigma_shape_m = 0.05;
  energy.rays.assign(9, Eigen::Vector3d(0.06, 0.1, 1));  // through (0.3, 0.5, 5) at z = 5
  energy.depth.depths = {5.f};
  energy.unknown = 1;
  const double e3d = 0.8 * (1 - std::exp(-8.0));  // as in Pose3dCostShapePart
  const Eigen::Vector2f still(0, 0);
  ASSERT_TRUE(energy.pose_options.shape_own_label_only);  // the default
  EXPECT_NEAR(energy.Pose3d(4, 2, 0, still), e3d, 1e-5);
  EXPECT_EQ(energy.Pose3d(4, 1, 0, still), 0.0);
  EXPECT_EQ(energy.Pose3d(4, 0, 0, still), 0.0);
  EXPECT_EQ(energy.Pose3d(4, 2, energy.unknown, still), 0.0);  // U: no point
  EXPECT_NEAR(energy.LabelUnaryWithPose3d(4, 2, 0, still), e3d, 1e-5);
  EXPECT_EQ(energy.LabelUnaryWithPose3d(4, 1, 0, still), 0.0);
  energy.pose_options.shape_own_label_only = false;
  EXPECT_NEAR(energy.Pose3d(4, 1, 0, still), e3d, 1e-5);
  EXPECT_EQ(energy.LabelUnaryWithPose3d(4, 1, 0, still), 0.0);  // then a depth term only
}

}  // namespace
}  // namespace u4d
