#include "u4d/eval/silhouette.h"

#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>

#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

Camera TestCamera() {
  Camera cam;
  cam.width = 40;
  cam.height = 40;
  cam.K << 100, 0, 19.5, 0, 100, 19.5, 0, 0, 1;
  return cam;
}

// A square of half-size h at depth z facing the camera.
open3d::geometry::TriangleMesh Square(double h, double z) {
  open3d::geometry::TriangleMesh m;
  m.vertices_ = {{-h, -h, z}, {h, -h, z}, {h, h, z}, {-h, h, z}};
  m.triangles_ = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TEST(Rasterize, SquareHasTheAnalyticArea) {
  // Half-size 0.2 at 2 m with f = 100: edges at 19.5 +- 10 = 9.5 and 29.5,
  // so exactly the 20 x 20 pixel centres 10..29 are inside.
  const cv::Mat sil = RasterizeSilhouette(Square(0.2, 2), TestCamera());
  EXPECT_EQ(cv::countNonZero(sil), 400);
  EXPECT_EQ(sil.at<uint8_t>(10, 10), 255);
  EXPECT_EQ(sil.at<uint8_t>(9, 10), 0);
  EXPECT_EQ(sil.at<uint8_t>(29, 29), 255);
  EXPECT_EQ(sil.at<uint8_t>(30, 29), 0);
  // A nearer, smaller square (10 x 10 pixels) occludes the far one.
  const auto far = Square(0.2, 2), near = Square(0.05, 1);
  const Rasterization r = RasterizeMeshes({&far, &near}, {1, 2}, TestCamera());
  EXPECT_EQ(cv::countNonZero(r.labels == 2), 100);
  EXPECT_EQ(cv::countNonZero(r.labels == 1), 300);
  EXPECT_FLOAT_EQ(r.depth.at<float>(20, 20), 1.0f);
  EXPECT_FLOAT_EQ(r.depth.at<float>(10, 10), 2.0f);
  // Behind the camera: nothing.
  EXPECT_EQ(cv::countNonZero(RasterizeSilhouette(Square(0.2, -2), TestCamera())), 0);
}

TEST(Propagate, ConstantFlowShiftsTheMask) {
  cv::Mat mask = cv::Mat::zeros(20, 30, CV_8UC1);
  mask(cv::Rect(5, 6, 8, 4)).setTo(255);
  const cv::Mat flow(20, 30, CV_32FC2, cv::Scalar(3.0f, -2.0f));
  const cv::Mat moved = PropagateMask(mask, flow);
  cv::Mat expected = cv::Mat::zeros(20, 30, CV_8UC1);
  expected(cv::Rect(8, 4, 8, 4)).setTo(255);
  EXPECT_EQ(cv::countNonZero(moved != expected), 0);
  // Leaving the image drops pixels; invalid flow drops pixels.
  const cv::Mat out(20, 30, CV_32FC2, cv::Scalar(20.0f, 0.0f));
  EXPECT_EQ(cv::countNonZero(PropagateMask(mask, out)), 5 * 4);  // columns 25..29 remain
  EXPECT_EQ(
      cv::countNonZero(PropagateMask(mask, cv::Mat(20, 30, CV_32FC2, cv::Scalar(1e10f, 0.0f)))), 0);
  EXPECT_THROW(PropagateMask(mask, cv::Mat(20, 31, CV_32FC2)), Error);
}

TEST(Overlap, ProjectionAndSilhouetteErrors) {
  cv::Mat a = cv::Mat::zeros(10, 20, CV_8UC1), b = a.clone();
  a(cv::Rect(0, 0, 10, 10)).setTo(255);
  b(cv::Rect(5, 0, 10, 10)).setTo(255);
  EXPECT_EQ(CompareMasks(a, a, "t").OneMinusIoU(), 0.0);
  EXPECT_EQ(CompareMasks(a, a, "t").XorOverGt(), 0.0);
  const MaskOverlap o = CompareMasks(b, a, "t");
  EXPECT_NEAR(o.OneMinusIoU(), 1.0 - 50.0 / 150.0, 1e-12);
  EXPECT_NEAR(o.XorOverGt(), 100.0 / 100.0, 1e-12);
  EXPECT_THROW(CompareMasks(a, cv::Mat::zeros(10, 21, CV_8UC1), "t"), Error);
  RatioMean mean;
  mean.Add(0.25);
  mean.Add(std::numeric_limits<double>::quiet_NaN());
  mean.Add(0.75);
  EXPECT_DOUBLE_EQ(mean.Mean(), 0.5);
}

}  // namespace
}  // namespace u4d::eval
