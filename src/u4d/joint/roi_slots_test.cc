#include "u4d/joint/roi_slots.h"

#include <gtest/gtest.h>

#include "u4d/util/check.h"

namespace u4d {
namespace {

TEST(RoiSlotsTest, NumbersTheRoiPixelsRowMajorAndBoundsThem) {
  cv::Mat roi = cv::Mat::zeros(4, 5, CV_8U);
  roi.at<uint8_t>(1, 3) = 1;
  roi.at<uint8_t>(2, 1) = 255;
  roi.at<uint8_t>(2, 2) = 7;
  const RoiSlots s = MakeRoiSlots(roi, 5, 4);
  EXPECT_EQ(s.count, 3);
  ASSERT_EQ(s.slot.size(), 20u);
  EXPECT_EQ(s.slot[1 * 5 + 3], 0);
  EXPECT_EQ(s.slot[2 * 5 + 1], 1);
  EXPECT_EQ(s.slot[2 * 5 + 2], 2);
  int outside = 0;
  for (int v : s.slot) outside += v < 0;
  EXPECT_EQ(outside, 17);
  EXPECT_EQ(s.box, cv::Rect(1, 1, 3, 2));

  const RoiSlots all = MakeRoiSlots(cv::Mat(), 5, 4);
  EXPECT_EQ(all.count, 20);
  for (int p = 0; p < 20; ++p) EXPECT_EQ(all.slot[p], p);
  EXPECT_EQ(all.box, cv::Rect(0, 0, 5, 4));

  const RoiSlots none = MakeRoiSlots(cv::Mat::zeros(4, 5, CV_8U), 5, 4);
  EXPECT_EQ(none.count, 0);
  EXPECT_TRUE(none.box.empty());
}

TEST(RoiSlotsTest, RejectsAWrongRoiOrSize) {
  EXPECT_THROW(MakeRoiSlots(cv::Mat::zeros(4, 4, CV_8U), 5, 4), Error);
  EXPECT_THROW(MakeRoiSlots(cv::Mat::zeros(4, 5, CV_32F), 5, 4), Error);
  EXPECT_THROW(MakeRoiSlots(cv::Mat(), 0, 4), Error);
}

}  // namespace
}  // namespace u4d
