#include "u4d/pipeline/scene_outputs.h"

#include <cstdio>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {
namespace {

// A camera-size truth: two people (a disc with a thin arm, an ellipse)
// whose boundaries fall between the pixels of a half-size working image.
cv::Mat TwoPeople(cv::Size size) {
  cv::Mat ids = cv::Mat::zeros(size, CV_16U);
  cv::circle(ids, {61, 83}, 37, 1, cv::FILLED);
  cv::line(ids, {61, 83}, {141, 21}, 1, 3);
  cv::ellipse(ids, {{171.f, 101.f}, {53.f, 121.f}, 17.f}, 2, cv::FILLED);
  return ids;
}

double Iou(const cv::Mat& a, const cv::Mat& b) {
  const double inter = cv::countNonZero((a == b) & (a > 0));
  const double uni = cv::countNonZero((a > 0) | (b > 0));
  return inter / uni;
}

// The working-resolution input as the frame setup makes it (nearest neighbour).
cv::Mat Working(const cv::Mat& full) {
  cv::Mat out;
  cv::resize(full, out, full.size() / 2, 0, 0, cv::INTER_NEAREST);
  return out;
}

JointViewResult SolveThatKept(const cv::Mat& working_labels) {
  JointViewResult r;
  r.labels = working_labels.clone();
  r.depth = cv::Mat::zeros(working_labels.size(), CV_32F);
  r.depth.setTo(3.0f, working_labels == 1);
  r.depth.setTo(4.0f, working_labels == 2);
  return r;
}

TEST(KeepInitialDetail, ASolveThatKeptPerfectMasksGivesThemBackAtCameraSize) {
  const cv::Mat truth = TwoPeople({240, 180});
  const cv::Mat working = Working(truth);
  const JointViewResult solve = SolveThatKept(working);
  const ViewMaps nearest = ToCameraSize(solve, 240, 180, 0.5);
  const ViewMaps detail = ToCameraSize(solve, 240, 180, 0.5, working, truth);
  EXPECT_LT(Iou(nearest.labels, truth), 0.97);  // the working pixel's jagged, shifted boundary
  EXPECT_EQ(cv::countNonZero(detail.labels != truth), 0);
  // Every pixel of a person has that person's depth, the background none.
  EXPECT_EQ(cv::countNonZero((detail.labels == 1) & (detail.depth != 3.0f)), 0);
  EXPECT_EQ(cv::countNonZero((detail.labels == 2) & (detail.depth != 4.0f)), 0);
  EXPECT_EQ(cv::countNonZero((detail.labels == 0) & (detail.depth != 0.0f)), 0);
}

TEST(KeepInitialDetail, WhereTheSolveChangedTheLabelsItsLabelsStay) {
  const cv::Mat truth = TwoPeople({240, 180});
  const cv::Mat given = truth.clone();
  cv::rectangle(given, {20, 130}, {70, 170}, 1, cv::FILLED);  // a false piece the solve removes
  const cv::Mat working_given = Working(given);
  const JointViewResult solve = SolveThatKept(Working(truth));
  const ViewMaps detail = ToCameraSize(solve, 240, 180, 0.5, working_given, given);
  const ViewMaps nearest = ToCameraSize(solve, 240, 180, 0.5);
  // Around the removed piece (working pixels the solve changed, and their
  // neighbours) the solve's labels; elsewhere the given detail.
  cv::Mat changed;
  cv::dilate(solve.labels != working_given, changed, cv::Mat::ones(3, 3, CV_8U));
  cv::resize(changed, changed, truth.size(), 0, 0, cv::INTER_NEAREST);
  EXPECT_EQ(cv::countNonZero((detail.labels != nearest.labels) & changed), 0);
  EXPECT_EQ(cv::countNonZero((detail.labels != truth) & ~changed), 0);
  EXPECT_EQ(cv::countNonZero(detail.labels(cv::Rect(24, 134, 40, 30)) != 0), 0);
}

// A red figure (the two people's shapes) on a textured green background at
// camera size; the solve at half size labelled every working pixel by the
// majority of its four camera pixels. Guided by the camera-size image, the
// upscaled labels follow the figure's colour edge: far fewer wrong pixels
// than nearest neighbour.
TEST(GuidedLabels, TheUpscaledBoundaryFollowsTheColourEdge) {
  const cv::Mat truth = TwoPeople({240, 180});
  cv::Mat image(truth.size(), CV_8UC3);
  cv::randu(image, cv::Scalar(40, 120, 40), cv::Scalar(70, 160, 70));
  image.setTo(cv::Scalar(40, 40, 200), truth != 0);
  cv::Mat working_image, share;
  cv::resize(image, working_image, truth.size() / 2, 0, 0, cv::INTER_AREA);
  cv::Mat person;
  cv::resize(truth, person, truth.size() / 2, 0, 0, cv::INTER_NEAREST);  // the ids
  cv::resize(cv::Mat(truth != 0), share, truth.size() / 2, 0, 0, cv::INTER_AREA);
  person.setTo(0, share < 128);
  const JointViewResult solve = SolveThatKept(person);
  const ViewMaps nearest = ToCameraSize(solve, 240, 180, 0.5);
  const ViewMaps guided = ToCameraSize(solve, 240, 180, 0.5, {}, {}, working_image, image);
  const int wrong_nearest = cv::countNonZero(nearest.labels != truth);
  const int wrong_guided = cv::countNonZero(guided.labels != truth);
  std::printf("wrong pixels: nearest %d, guided %d\n", wrong_nearest, wrong_guided);
  EXPECT_LT(wrong_guided, wrong_nearest / 2);
  EXPECT_EQ(cv::countNonZero((guided.labels == 1) & (guided.depth != 3.0f)), 0);
  EXPECT_EQ(cv::countNonZero((guided.labels == 0) & (guided.depth != 0.0f)), 0);
}

TEST(KeepInitialDetail, RefusesMapsOfTheWrongSizeOrType) {
  const cv::Mat truth = TwoPeople({240, 180});
  const JointViewResult solve = SolveThatKept(Working(truth));
  EXPECT_THROW(ToCameraSize(solve, 240, 180, 0.5, Working(truth), Working(truth)), Error);
  cv::Mat as_float;
  truth.convertTo(as_float, CV_32F);
  EXPECT_THROW(ToCameraSize(solve, 240, 180, 0.5, Working(truth), as_float), Error);
  const cv::Mat image = cv::Mat::zeros(truth.size(), CV_8UC3);
  EXPECT_THROW(ToCameraSize(solve, 240, 180, 0.5, {}, {}, image, image), Error);
}

}  // namespace
}  // namespace u4d
