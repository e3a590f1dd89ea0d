#include "u4d/geometry/camera.h"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "u4d/geometry/epipolar.h"
#include "u4d/geometry/triangulation.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

Camera MakeCamera(double yaw, bool distorted) {
  Camera cam;
  cam.width = 640;
  cam.height = 480;
  cam.K << 500, 0, 320, 0, 510, 240, 0, 0, 1;
  if (distorted) cam.dist = {-0.2, 0.05, 0.001, -0.0005, 0.01};
  // Camera on a circle of radius 3 looking at the origin.
  const Eigen::Vector3d center(3 * std::sin(yaw), 0.2, -3 * std::cos(yaw));
  const Eigen::Vector3d z = (-center).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_from_cam_rot;
  world_from_cam_rot << x, y, z;
  cam.cam_from_world.rotation = world_from_cam_rot.transpose();
  cam.cam_from_world.translation = -cam.cam_from_world.rotation * center;
  return cam;
}

TEST(Camera, ProjectMatchesOpenCV) {
  const Camera cam = MakeCamera(0.4, true);
  cam.Check();
  cv::Mat rvec, tvec(3, 1, CV_64F), k(3, 3, CV_64F), d(1, 5, CV_64F), r(3, 3, CV_64F);
  for (int i = 0; i < 3; ++i) {
    tvec.at<double>(i) = cam.cam_from_world.translation(i);
    for (int j = 0; j < 3; ++j) {
      r.at<double>(i, j) = cam.cam_from_world.rotation(i, j);
      k.at<double>(i, j) = cam.K(i, j);
    }
  }
  for (int i = 0; i < 5; ++i) d.at<double>(i) = cam.dist[i];
  cv::Rodrigues(r, rvec);
  std::vector<cv::Point3d> pts = {{0, 0, 0}, {0.3, -0.2, 0.1}, {-0.5, 0.4, 0.3}};
  std::vector<cv::Point2d> expected;
  cv::projectPoints(pts, rvec, tvec, k, d, expected);
  for (size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector2d px = cam.Project({pts[i].x, pts[i].y, pts[i].z});
    EXPECT_NEAR(px.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(px.y(), expected[i].y, 1e-9);
  }
}

TEST(Camera, UnprojectInvertsProject) {
  const Camera cam = MakeCamera(1.0, true);
  const Eigen::Vector3d point(0.2, -0.3, 0.15);
  const Eigen::Vector2d px = cam.Project(point);
  const Eigen::Vector3d back = cam.Unproject(px, cam.Depth(point));
  EXPECT_LT((back - point).norm(), 1e-8);
}

TEST(Camera, CheckRejectsBadInput) {
  Camera cam = MakeCamera(0, false);
  cam.K(0, 0) = std::nan("");
  EXPECT_THROW(cam.Check("cam0"), Error);
  cam = MakeCamera(0, false);
  cam.cam_from_world.rotation(0, 0) = 2;
  EXPECT_THROW(cam.Check("cam0"), Error);
  cam = MakeCamera(0, false);
  cam.width = 0;
  EXPECT_THROW(cam.Check("cam0"), Error);
}

TEST(Geometry, TriangulationAndEpipolarAreExact) {
  const Camera a = MakeCamera(0.0, true), b = MakeCamera(0.7, true), c = MakeCamera(-0.6, false);
  const Eigen::Vector3d point(0.1, 0.25, -0.2);
  std::vector<Observation> obs = {
      {&a, a.Project(point)}, {&b, b.Project(point)}, {&c, c.Project(point)}};
  EXPECT_LT((TriangulateDlt(obs) - point).norm(), 1e-8);
  EXPECT_LT(ReprojectionRmse(point, obs), 1e-8);
  const Eigen::Matrix3d f = FundamentalFromCameras(a, b);
  EXPECT_LT(EpipolarDistance(f, UndistortPixel(a, obs[0].pixel), UndistortPixel(b, obs[1].pixel)),
            1e-6);
}

TEST(Camera, ScaledCameraFollowsThePixelCentreConvention) {
  Camera camera = MakeCamera(0.3, /*distorted=*/false);
  camera.height = 360;
  camera.K << 500, 0, 319.5, 0, 510, 179.5, 0, 0, 1;
  const Camera half = ScaledCamera(camera, 0.5);
  EXPECT_EQ(half.width, 320);
  EXPECT_EQ(half.height, 180);
  // The image centre stays the image centre.
  EXPECT_NEAR(half.K(0, 2), 159.5, 1e-12);
  EXPECT_NEAR(half.K(1, 2), 89.5, 1e-12);
  const Eigen::Vector3d point(0.3, 0.4, 1.0);
  const Eigen::Vector2d x = camera.Project(point);
  const Eigen::Vector2d x_half = half.Project(point);
  EXPECT_NEAR(x_half.x(), 0.5 * (x.x() + 0.5) - 0.5, 1e-9);
  EXPECT_NEAR(x_half.y(), 0.5 * (x.y() + 0.5) - 0.5, 1e-9);
  EXPECT_THROW(ScaledCamera(camera, 0.0), Error);
}

TEST(Camera, NearestPixelIsThePixelAPointProjectsInto) {
  const Camera cam = MakeCamera(0.3, /*distorted=*/true);
  // A point seen at a pixel centre, and just off it, gives that pixel.
  const Eigen::Vector3d at_centre = cam.Unproject({123, 45}, 2.5);
  for (const Eigen::Vector3d& point : {at_centre, cam.Unproject({123.4, 44.6}, 2.5)}) {
    const std::optional<Eigen::Vector2i> pixel = NearestPixel(cam, point);
    ASSERT_TRUE(pixel.has_value());
    EXPECT_EQ(*pixel, Eigen::Vector2i(123, 45));
  }
  // The outer half-pixel border belongs to the border pixels.
  for (const Eigen::Vector2d& border :
       {Eigen::Vector2d(-0.45, -0.45), Eigen::Vector2d(cam.width - 0.55, cam.height - 0.55)}) {
    const std::optional<Eigen::Vector2i> pixel = NearestPixel(cam, cam.Unproject(border, 2.0));
    ASSERT_TRUE(pixel.has_value()) << border.transpose();
    EXPECT_EQ(*pixel, Eigen::Vector2i(border.x() < 0 ? 0 : cam.width - 1,
                                      border.y() < 0 ? 0 : cam.height - 1));
  }
  // Outside the image, or behind the camera: not seen.
  EXPECT_FALSE(NearestPixel(cam, cam.Unproject({cam.width - 0.45, 10}, 2.0)).has_value());
  EXPECT_FALSE(NearestPixel(cam, cam.Unproject({-0.6, 10}, 2.0)).has_value());
  const Eigen::Vector3d behind = 2 * cam.Center() - at_centre;
  EXPECT_LT(cam.Depth(behind), 0);
  EXPECT_FALSE(NearestPixel(cam, behind).has_value());
}

}  // namespace
}  // namespace u4d
