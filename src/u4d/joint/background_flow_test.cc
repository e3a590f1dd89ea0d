#include "u4d/joint/background_flow.h"

#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "u4d/util/check.h"

namespace u4d {
namespace {

Camera MakeCamera(const Eigen::Matrix3d& world_to_cam, const Eigen::Vector3d& center) {
  Camera c;
  c.width = 160;
  c.height = 120;
  c.K << 150, 0, 79.5, 0, 150, 59.5, 0, 0, 1;
  c.cam_from_world.rotation = world_to_cam;
  c.cam_from_world.translation = -world_to_cam * center;
  return c;
}

// The true rigid flow of a static wall (the world plane z = 4) seen from
// cam_t and cam_t1: each pixel's ray hits the wall, the point is projected
// into cam_t1.
cv::Mat WallFlow(const Camera& cam_t, const Camera& cam_t1) {
  cv::Mat flow(cam_t.height, cam_t.width, CV_32FC2);
  const Eigen::Vector3d c = cam_t.Center();
  for (int y = 0; y < flow.rows; ++y)
    for (int x = 0; x < flow.cols; ++x) {
      const Eigen::Vector3d d = cam_t.Unproject({x, y}, 1.0) - c;
      const Eigen::Vector3d point = c + d * ((4.0 - c.z()) / d.z());
      const Eigen::Vector2d x1 = cam_t1.Project(point);
      flow.at<cv::Vec2f>(y, x) = cv::Vec2f(x1.x() - x, x1.y() - y);
    }
  return flow;
}

double MeanDistance(const cv::Mat& a, const cv::Mat& b) {
  double sum = 0;
  for (int p = 0; p < a.rows * a.cols; ++p)
    sum += cv::norm(a.ptr<cv::Vec2f>()[p] - b.ptr<cv::Vec2f>()[p]);
  return sum / (a.rows * a.cols);
}

Eigen::Matrix3d Yaw(double degrees) {
  return Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

TEST(BackgroundFlowTest, AStillCameraHasNoFlowWhateverTheImages) {
  const Camera cam = MakeCamera(Yaw(10), {0.2, -0.1, 0});
  EXPECT_FALSE(CameraMoved(cam, cam));
  cv::Mat a(cam.height, cam.width, CV_8U), b(cam.height, cam.width, CV_8U);
  cv::randu(a, 0, 255);
  cv::randu(b, 0, 255);
  const cv::Mat flow = BackgroundFlow(cam, cam, a, b);
  EXPECT_EQ(cv::countNonZero(flow.reshape(1)), 0);
  // Any match of a still camera snaps to no motion.
  cv::Mat matches(cam.height, cam.width, CV_32FC2, cv::Scalar(3, -2));
  EXPECT_LT(cv::norm(RigidFlowFromMatches(cam, cam, matches), cv::NORM_INF), 1e-6);
}

TEST(BackgroundFlowTest, ExactMatchesGiveTheTrueRigidFlowOfAnOrbitingCamera) {
  // The camera turns and slides sideways (parallax), as a rig orbiting the stage.
  const Camera cam_t = MakeCamera(Yaw(0), {0, 0, 0});
  const Camera cam_t1 = MakeCamera(Yaw(2), {0.08, 0.02, 0.01});
  ASSERT_TRUE(CameraMoved(cam_t, cam_t1));
  const cv::Mat truth = WallFlow(cam_t, cam_t1);
  EXPECT_GT(MeanDistance(truth, cv::Mat::zeros(truth.size(), CV_32FC2)), 2.0);  // it moves
  EXPECT_LT(MeanDistance(RigidFlowFromMatches(cam_t, cam_t1, truth), truth), 1e-3);
}

TEST(BackgroundFlowTest, NoisyMatchesLoseTheirErrorAcrossTheEpipolarLine) {
  const Camera cam_t = MakeCamera(Yaw(0), {0, 0, 0});
  const Camera cam_t1 = MakeCamera(Yaw(2), {0.08, 0.02, 0.01});
  const cv::Mat truth = WallFlow(cam_t, cam_t1);
  cv::Mat noisy = truth.clone();
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0, 1.5f);
  for (int p = 0; p < noisy.rows * noisy.cols; ++p)
    noisy.ptr<cv::Vec2f>()[p] += cv::Vec2f(noise(rng), noise(rng));
  const double before = MeanDistance(noisy, truth);
  const double after = MeanDistance(RigidFlowFromMatches(cam_t, cam_t1, noisy), truth);
  std::printf("mean EPE of the matches %.3f px, of the rigid flow %.3f px\n", before, after);
  // Of an isotropic error, only the component along the line remains
  // (half the squared error; the mean shrinks to about 0.64 of the matches').
  EXPECT_LT(after, 0.75 * before);
}

TEST(BackgroundFlowTest, APureRotationNeedsNoMatch) {
  const Camera cam_t = MakeCamera(Yaw(0), {0, 0, 0});
  const Camera cam_t1 = MakeCamera(Yaw(1.5), {0, 0, 0});
  const cv::Mat truth = WallFlow(cam_t, cam_t1);
  const cv::Mat wrong(truth.size(), CV_32FC2, cv::Scalar(-9, 4));
  EXPECT_LT(MeanDistance(RigidFlowFromMatches(cam_t, cam_t1, wrong), truth), 1e-3);
}

TEST(BackgroundFlowTest, RejectsMismatchedInput) {
  const Camera cam = MakeCamera(Yaw(0), {0, 0, 0});
  Camera small = cam;
  small.width = 80;
  EXPECT_THROW(RigidFlowFromMatches(cam, small, cv::Mat(120, 160, CV_32FC2)), Error);
  EXPECT_THROW(RigidFlowFromMatches(cam, cam, cv::Mat(120, 80, CV_32FC2)), Error);
  EXPECT_THROW(RigidFlowFromMatches(cam, cam, cv::Mat(120, 160, CV_32F)), Error);
  EXPECT_THROW(BackgroundFlow(cam, cam, cv::Mat(120, 160, CV_8UC3), cv::Mat(120, 160, CV_8U)),
               Error);
  BackgroundFlowOptions bad;
  bad.min_depth_m = 0;
  EXPECT_THROW(RigidFlowFromMatches(cam, cam, cv::Mat(120, 160, CV_32FC2), bad), Error);
}

}  // namespace
}  // namespace u4d
