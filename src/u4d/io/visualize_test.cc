#include "u4d/io/visualize.h"

#include <set>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {
namespace {

cv::Vec3b Bgr(const cv::Mat& image, int x, int y) { return image.at<cv::Vec3b>(y, x); }
cv::Vec3b Rgb(uint8_t r, uint8_t g, uint8_t b) { return {r, g, b}; }
cv::Vec3b ToBgr(const cv::Vec3b& rgb) { return {rgb[2], rgb[1], rgb[0]}; }

TEST(InstanceColor, BackgroundBlackTableauThenDistinctAndStable) {
  EXPECT_EQ(InstanceColor(0), Rgb(0, 0, 0));
  EXPECT_EQ(InstanceColor(1), Rgb(31, 119, 180));  // Tableau blue
  EXPECT_EQ(InstanceColor(2), Rgb(255, 127, 14));  // Tableau orange
  EXPECT_EQ(InstanceColor(3), Rgb(44, 160, 44));   // Tableau green
  std::set<std::tuple<int, int, int>> seen;
  for (int id = 1; id <= 60; ++id) {
    const cv::Vec3b c = InstanceColor(id);
    EXPECT_EQ(c, InstanceColor(id));  // stable
    EXPECT_TRUE(seen.insert({c[0], c[1], c[2]}).second) << "id " << id << " repeats a colour";
    EXPECT_GT(c[0] + c[1] + c[2], 60) << "id " << id << " is too dark to tell from background";
  }
}

TEST(ColorizeInstances, PaletteThenDefaultColoursInBgrOrder) {
  cv::Mat ids = (cv::Mat_<uint16_t>(1, 4) << 0, 1, 2, 300);
  const cv::Mat out = ColorizeInstances(ids, {Rgb(10, 20, 30)});
  ASSERT_EQ(out.type(), CV_8UC3);
  EXPECT_EQ(Bgr(out, 0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(Bgr(out, 1, 0), cv::Vec3b(30, 20, 10));    // palette[0], BGR
  EXPECT_EQ(Bgr(out, 2, 0), ToBgr(InstanceColor(2)));  // beyond the palette
  EXPECT_EQ(Bgr(out, 3, 0), ToBgr(InstanceColor(300)));
  EXPECT_THROW(ColorizeInstances(cv::Mat(2, 2, CV_32F), {}), Error);
}

TEST(ColorizeDepth, NearRedFarBlueUnknownBlack) {
  cv::Mat z = (cv::Mat_<float>(1, 5) << 0.f, 2.f, 6.f, 4.f, std::nanf(""));
  const cv::Mat out = ColorizeDepth(z, 2.0, 6.0);
  cv::Mat ends = (cv::Mat_<uint8_t>(1, 3) << 255, 0, 128), turbo;
  cv::applyColorMap(ends, turbo, cv::COLORMAP_TURBO);
  EXPECT_EQ(Bgr(out, 0, 0), cv::Vec3b(0, 0, 0));  // 0 = unknown
  EXPECT_EQ(Bgr(out, 4, 0), cv::Vec3b(0, 0, 0));  // NaN = unknown
  EXPECT_EQ(Bgr(out, 1, 0), Bgr(turbo, 0, 0));    // near = top of the map
  EXPECT_EQ(Bgr(out, 2, 0), Bgr(turbo, 1, 0));    // far = bottom
  // Turbo's top end is red, its bottom end blue-purple (BGR order).
  EXPECT_GT(Bgr(out, 1, 0)[2], Bgr(out, 1, 0)[0]);
  EXPECT_GT(Bgr(out, 2, 0)[0], Bgr(out, 2, 0)[2]);
  // Mid-range is the middle of the map, and beyond far clamps to far.
  EXPECT_LE(cv::norm(Bgr(out, 3, 0), Bgr(turbo, 2, 0), cv::NORM_INF), 8);
  cv::Mat beyond = (cv::Mat_<float>(1, 1) << 100.f);
  EXPECT_EQ(Bgr(ColorizeDepth(beyond, 2.0, 6.0), 0, 0), Bgr(turbo, 1, 0));
  EXPECT_THROW(ColorizeDepth(z, 3.0, 3.0), Error);
}

TEST(ColorizeFlow, MiddleburyWheel) {
  // Zero motion is white; a vector of the full scale is the wheel's pure hue:
  // +x (right) is red, +y (down) lies between yellow and green
  // (Middlebury's colour code).
  EXPECT_EQ(FlowColor(0, 0, 1), Rgb(255, 255, 255));
  EXPECT_EQ(FlowColor(1, 0, 1), Rgb(255, 0, 0));
  const cv::Vec3b down = FlowColor(0, 1, 1);
  EXPECT_GT(down[1], 200);  // green-ish/yellow-ish: high green, no blue
  EXPECT_EQ(down[2], 0);
  const cv::Vec3b left = FlowColor(-1, 0, 1);  // cyan-ish: low red
  EXPECT_LT(left[0], 40);
  // Half the scale: halfway to white.
  EXPECT_EQ(FlowColor(0.5f, 0, 1), Rgb(255, 127, 127));
  // Beyond the scale: full hue at 75% brightness.
  EXPECT_EQ(FlowColor(4, 0, 1), Rgb(191, 0, 0));
  // The .flo "unknown" value and NaN are black.
  EXPECT_EQ(FlowColor(1e10f, 0, 1), Rgb(0, 0, 0));
  EXPECT_EQ(FlowColor(std::nanf(""), 0, 1), Rgb(0, 0, 0));

  cv::Mat flow(1, 2, CV_32FC2);
  flow.at<cv::Vec2f>(0, 0) = {0, 0};
  flow.at<cv::Vec2f>(0, 1) = {3, 0};
  const cv::Mat out = ColorizeFlow(flow, 3.0);
  EXPECT_EQ(Bgr(out, 0, 0), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(Bgr(out, 1, 0), cv::Vec3b(0, 0, 255));  // red in BGR
  EXPECT_THROW(ColorizeFlow(flow, 0.0), Error);
  EXPECT_THROW(ColorizeFlow(cv::Mat(1, 1, CV_32F), 1.0), Error);
}

}  // namespace
}  // namespace u4d
