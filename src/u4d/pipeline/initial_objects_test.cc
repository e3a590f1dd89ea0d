#include "u4d/pipeline/initial_objects.h"

#include <gtest/gtest.h>

#include "u4d/util/check.h"

namespace u4d {
namespace {

TEST(KeepGivenPixelsTest, DroppedPixelsOfANamedInstanceComeBackWithItsId) {
  // Instance 3 (rows 0-3) was named 7 except for row 3 (a hand the hull
  // missed) and one pixel named 8 (split off); instance 5 (rows 6-7) was
  // named nowhere (a false positive); background stays background.
  cv::Mat given = cv::Mat::zeros(8, 6, CV_16UC1), named = given.clone();
  given.rowRange(0, 4).setTo(3);
  given.rowRange(6, 8).setTo(5);
  named.rowRange(0, 3).setTo(7);
  named.at<uint16_t>(0, 0) = 8;
  const cv::Mat kept = KeepGivenPixels(given, named);
  for (int x = 0; x < 6; ++x) {
    EXPECT_EQ(kept.at<uint16_t>(3, x), 7) << x;  // restored with the majority id
    EXPECT_EQ(kept.at<uint16_t>(4, x), 0) << x;  // background
    EXPECT_EQ(kept.at<uint16_t>(6, x), 0) << x;  // the false positive stays dropped
  }
  EXPECT_EQ(kept.at<uint16_t>(0, 0), 8);  // named pixels keep their names
  EXPECT_EQ(kept.at<uint16_t>(1, 1), 7);
}

TEST(KeepGivenPixelsTest, MismatchedMasksAreRefused) {
  const cv::Mat a = cv::Mat::zeros(4, 4, CV_16UC1);
  EXPECT_THROW(KeepGivenPixels(a, cv::Mat::zeros(4, 5, CV_16UC1)), Error);
  EXPECT_THROW(KeepGivenPixels(a, cv::Mat::zeros(4, 4, CV_8UC1)), Error);
}

}  // namespace
}  // namespace u4d
