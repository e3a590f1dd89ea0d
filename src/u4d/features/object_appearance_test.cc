// Object colours (object_appearance.h) on hand-made views: the bands are the
// colours above and below each object's middle row, in CIE L*a*b*.
#include "u4d/features/object_appearance.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "u4d/util/testing.h"

namespace u4d {
namespace {

// A 40x40 view holding object `id` as a 10x20 figure at column x0: `top`
// (BGR) above its middle row, `bottom` below.
struct View {
  cv::Mat image = cv::Mat(40, 40, CV_8UC3, cv::Scalar(128, 128, 128));
  cv::Mat ids = cv::Mat::zeros(40, 40, CV_16UC1);
  View& Figure(int id, int x0, cv::Scalar top, cv::Scalar bottom) {
    image(cv::Rect(x0, 10, 10, 10)).setTo(top);
    image(cv::Rect(x0, 20, 10, 10)).setTo(bottom);
    ids(cv::Rect(x0, 10, 10, 20)).setTo(id);
    return *this;
  }
};

const cv::Scalar kWhite(255, 255, 255), kBlack(0, 0, 0), kRed(0, 0, 255), kBlue(255, 0, 0);

TEST(ObjectAppearance, TheBandsAreTheColoursAboveAndBelowTheMiddle) {
  const View v = View().Figure(1, 5, kWhite, kBlack).Figure(2, 25, kRed, kBlue);
  const auto a = ObjectAppearances({v.image}, {v.ids});
  ASSERT_EQ(a.size(), 2u);
  EXPECT_NEAR(a.at(1).upper.x(), 100, 1);  // white: L* 100
  EXPECT_NEAR(a.at(1).lower.x(), 0, 1);    // black: L* 0
  EXPECT_GT(a.at(2).upper.y(), 50);        // red: a* > 0
  EXPECT_LT(a.at(2).lower.z(), -50);       // blue: b* < 0
  EXPECT_EQ(a.at(1).pixels, 200);
  // The distance is the mean of the bands' Delta E; an object is at 0 from
  // itself, and a swap of the bands is far.
  EXPECT_NEAR(AppearanceDistance(a.at(1), a.at(1)), 0, 1e-9);
  const View swapped = View().Figure(1, 5, kBlack, kWhite);
  EXPECT_NEAR(AppearanceDistance(a.at(1), ObjectAppearances({swapped.image}, {swapped.ids}).at(1)),
              100, 1);
}

TEST(ObjectAppearance, ViewsArePooledByPixelCountAndMissingMasksSkipped) {
  const View white = View().Figure(1, 5, kWhite, kWhite);
  View black = View().Figure(1, 5, kBlack, kBlack);
  black.ids(cv::Rect(5, 20, 10, 10)).setTo(0);  // only the upper half seen here
  black.ids(cv::Rect(5, 10, 10, 5)).setTo(0);   // and half of that
  const auto a =
      ObjectAppearances({white.image, black.image, white.image}, {white.ids, black.ids, cv::Mat()});
  // View 1 holds rows 15-19: rows 15-17 are above its middle (30 black
  // pixels), 18-19 below (20). View 0 adds 100 white pixels to each band.
  EXPECT_NEAR(a.at(1).upper.x(), 100.0 * 100 / 130, 0.5);
  EXPECT_NEAR(a.at(1).lower.x(), 100.0 * 100 / 120, 0.5);
  EXPECT_EQ(a.at(1).pixels, 250);
  const ObjectAppearance m =
      MeanAppearance(a.at(1), ObjectAppearances({white.image}, {white.ids}).at(1));
  EXPECT_EQ(m.pixels, a.at(1).pixels + 200);
}

TEST(ObjectAppearance, MismatchedInputsAreRefused) {
  const View v = View().Figure(1, 5, kWhite, kBlack);
  test_util::ExpectErrorMentions([&] { ObjectAppearances({v.image}, {}); }, {"1 images and 0"});
  cv::Mat gray;
  cv::cvtColor(v.image, gray, cv::COLOR_BGR2GRAY);
  test_util::ExpectErrorMentions([&] { ObjectAppearances({gray}, {v.ids}); },
                                 {"view 0", "CV_8UC3"});
}

}  // namespace
}  // namespace u4d
