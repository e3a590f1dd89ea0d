#include "u4d/joint/hull_support.h"

#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "u4d/synth/rig.h"
#include "u4d/testing/sphere_figure.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

using testing::RenderSpheres;
using testing::Sphere;

// A figure of spheres: a body column and an arm sticking out sideways.
const std::vector<Sphere> kBody = {
    {{0, 0.5, 0}, 0.22}, {{0, 0.9, 0}, 0.22}, {{0, 1.3, 0}, 0.2}, {{0, 1.65, 0}, 0.12}};
const std::vector<Sphere> kArm = {{{0.3, 1.35, 0}, 0.08}, {{0.45, 1.35, 0}, 0.08}};

struct Scene {
  std::vector<Camera> cameras;
  std::vector<cv::Mat> body, arm;  // CV_8U per view
  std::vector<cv::Mat> labels;     // CV_16U object 1 = body + arm
};

Scene MakeScene() {
  synth::RigOptions rig;
  rig.image_width = 320;
  rig.image_height = 180;
  Scene s;
  s.cameras = synth::RigCameras(rig);
  for (const Camera& cam : s.cameras) {
    s.body.push_back(RenderSpheres(cam, kBody));
    s.arm.push_back(RenderSpheres(cam, kArm));
    cv::Mat labels = cv::Mat::zeros(cam.height, cam.width, CV_16U);
    labels.setTo(1, s.body.back() | s.arm.back());
    s.labels.push_back(labels);
  }
  return s;
}

// Share of `part`'s pixels that `support` gives to object 1.
double Covered(const cv::Mat& support, const cv::Mat& part) {
  return static_cast<double>(cv::countNonZero((support == 1) & part)) / cv::countNonZero(part);
}

const std::vector<HullObject> kObject = {{1, 3.5, 5.5, {}}};  // the ring's radius is 4.5 m

// One other view may put a supported point on the background (the
// default is none: every other view that sees a point must agree).
HullSupportOptions OneDissent() {
  HullSupportOptions o;
  o.max_background_views = 1;
  return o;
}

// Pixels of `support` (object 1) beyond the figure dilated by 4 px, as a
// share of the figure's pixels.
double Beyond(const cv::Mat& support, const cv::Mat& figure) {
  cv::Mat near_truth;
  cv::dilate(figure, near_truth, cv::Mat::ones(9, 9, CV_8U));
  return static_cast<double>(cv::countNonZero((support == 1) & ~near_truth)) /
         cv::countNonZero(figure);
}

// The hull of 7 views is a little larger than the figure (the strict one by
// up to 5 % of its pixels); where one view may dissent, a point seen by few
// views is carved by fewer, and the hull is larger (up to 15 %): never a
// blob around the figure.
constexpr double kStrictBeyond = 0.05, kBeyond = 0.15;
// View 2 sees the arm from the side (view 0 looks along it).
constexpr int kRef = 2;

TEST(HullSupportTest, APartCutFromOneViewComesBackFromTheOthers) {
  Scene s = MakeScene();
  const int ref = kRef;
  const cv::Mat cut = s.arm[ref] & ~s.body[ref];
  ASSERT_GT(cv::countNonZero(cut), 50) << "the arm must show beside the body in the view";
  s.labels[ref].setTo(0, cut);
  const cv::Mat strict = HullSupport(s.cameras, s.labels, ref, kObject);
  const cv::Mat support = HullSupport(s.cameras, s.labels, ref, kObject, OneDissent());
  EXPECT_GE(Covered(support, cut), 0.7);
  EXPECT_GE(Covered(strict, cut), 0.7);
  // It does not spread far beyond the true silhouette.
  EXPECT_LE(Beyond(support, s.body[ref] | s.arm[ref]), kBeyond);
  EXPECT_LE(Beyond(strict, s.body[ref] | s.arm[ref]), kStrictBeyond);
  // Pixels the view already labels are not in the map.
  EXPECT_EQ(cv::countNonZero((support != 0) & (s.labels[ref] != 0)), 0);
}

TEST(HullSupportTest, APartNoOtherViewHoldsDoesNotComeBack) {
  Scene s = MakeScene();
  for (size_t v = 0; v < s.cameras.size(); ++v) s.labels[v].setTo(0, s.arm[v] & ~s.body[v]);
  const cv::Mat cut = s.arm[kRef] & ~s.body[kRef];
  EXPECT_LE(Covered(HullSupport(s.cameras, s.labels, kRef, kObject), cut), 0.1);
  // Where one view may dissent, the larger hull reaches into the arm's
  // pixels next to the body, not beyond the third of the arm nearest it.
  cv::Mat dist;
  cv::distanceTransform(~s.body[kRef], dist, cv::DIST_L2, 3);
  double reach = 0;
  cv::minMaxLoc(dist, nullptr, &reach, nullptr, nullptr, cut);
  const cv::Mat far = cut & (dist > reach / 3);
  const cv::Mat support = HullSupport(s.cameras, s.labels, kRef, kObject, OneDissent());
  std::printf("[hull] no view holds the arm: %.2f of it supported, %.2f of its far two thirds\n",
              Covered(support, cut), Covered(support, far));
  EXPECT_LE(Covered(support, far), 0.1);
}

TEST(HullSupportTest, AnOccluderInAnotherViewDoesNotVetoTheObject) {
  Scene s = MakeScene();
  const cv::Mat cut = s.arm[kRef] & ~s.body[kRef];
  s.labels[kRef].setTo(0, cut);
  // In views 4 and 6 another object (id 2) covers the whole arm.
  for (int v : {4, 6}) s.labels[v].setTo(2, s.arm[v]);
  const cv::Mat support = HullSupport(s.cameras, s.labels, kRef, kObject);
  EXPECT_GE(Covered(support, cut), 0.7);
}

// The detector dropped the arm in the reference view and in one other view
// (view 6, which sees it beside the body): with the strict hull that one
// view carves the arm away; allowing one view on the background, the five
// others that hold it outvote it and bring the arm back.
TEST(HullSupportTest, OneOtherViewThatDroppedThePartTooNeedNotVetoIt) {
  Scene s = MakeScene();
  const cv::Mat cut = s.arm[kRef] & ~s.body[kRef];
  s.labels[kRef].setTo(0, cut);
  constexpr int kAlsoDropped = 6;
  ASSERT_GT(cv::countNonZero(s.arm[kAlsoDropped] & ~s.body[kAlsoDropped]), 50);
  s.labels[kAlsoDropped].setTo(0, s.arm[kAlsoDropped] & ~s.body[kAlsoDropped]);
  EXPECT_LE(Covered(HullSupport(s.cameras, s.labels, kRef, kObject), cut), 0.1);
  const cv::Mat support = HullSupport(s.cameras, s.labels, kRef, kObject, OneDissent());
  EXPECT_GE(Covered(support, cut), 0.7);
  EXPECT_LE(Beyond(support, s.body[kRef] | s.arm[kRef]), kBeyond);
  // Over another object's pixels that the object claims, every view must
  // agree: where the view gives the arm to object 2, view 6 vetoes it.
  s.labels[kRef].setTo(2, cut);
  const std::vector<HullObject> claiming = {{1, 3.5, 5.5, {2}}};
  EXPECT_LE(Covered(HullSupport(s.cameras, s.labels, kRef, claiming, OneDissent()), cut), 0.1);
}

// The whole figure missed in the reference view (its labels empty there):
// the object is searched over the whole image, and its hull from the other
// views gives it back.
TEST(HullSupportTest, AnObjectMissedInTheViewIsFoundFromTheOthers) {
  Scene s = MakeScene();
  s.labels[kRef].setTo(0);
  const cv::Mat figure = s.body[kRef] | s.arm[kRef];
  const cv::Mat support = HullSupport(s.cameras, s.labels, kRef, kObject);
  EXPECT_GE(Covered(support, figure), 0.9);
  EXPECT_LE(Beyond(support, figure), kStrictBeyond);
  const cv::Mat tolerant = HullSupport(s.cameras, s.labels, kRef, kObject, OneDissent());
  EXPECT_GE(Covered(tolerant, figure), 0.9);
  EXPECT_LE(Beyond(tolerant, figure), kBeyond);
}

// The "arm" is an object of its own (id 2, a box the person holds) in every
// view but the reference, where the detector merged it with the person (id
// 1). Claiming the person's pixels, object 2's hull from the other views
// takes the arm back there; without the claim it gets none of them.
TEST(HullSupportTest, AnObjectMergedWithItsHolderComesBackWhereItClaimsThePerson) {
  Scene s = MakeScene();
  for (size_t v = 0; v < s.cameras.size(); ++v)
    if (static_cast<int>(v) != kRef) s.labels[v].setTo(2, s.arm[v] & ~s.body[v]);
  const cv::Mat beside = s.arm[kRef] & ~s.body[kRef];
  const HullObject person{1, 3.5, 5.5, {}};
  HullObject box{2, 3.5, 5.5, {}};
  const cv::Mat unclaimed = HullSupport(s.cameras, s.labels, kRef, {person, box});
  EXPECT_EQ(cv::countNonZero((unclaimed == 2) & (s.labels[kRef] != 0)), 0);
  box.claims = {1};
  const cv::Mat claimed = HullSupport(s.cameras, s.labels, kRef, {person, box});
  const double taken =
      static_cast<double>(cv::countNonZero((claimed == 2) & beside)) / cv::countNonZero(beside);
  const double body =
      static_cast<double>(cv::countNonZero((claimed == 2) & s.body[kRef] & ~s.arm[kRef])) /
      cv::countNonZero(s.body[kRef]);
  std::printf("claimed: %.2f of the arm beside the body, %.3f of the body\n", taken, body);
  EXPECT_GE(taken, 0.7);
  EXPECT_LE(body, 0.05);
}

// With the true labels in every view, the other views confirm the view's
// object: all of it but a rim as wide as the confirming views' inset.
TEST(HullConfirmationTest, TheOtherViewsConfirmTheTrueLabels) {
  const Scene s = MakeScene();
  cv::Mat alone;
  const cv::Mat confirmed =
      HullConfirmation(s.cameras, s.labels, kRef, kObject, {}, nullptr, &alone);
  EXPECT_EQ(cv::countNonZero(alone != (confirmed != 0)), 0);  // one object: every ray alone
  const cv::Mat figure = s.labels[kRef] == 1;
  cv::Mat core;
  cv::erode(figure, core, cv::Mat::ones(9, 9, CV_8U));
  EXPECT_GE(Covered(confirmed, core), 0.95);
  EXPECT_GE(Covered(confirmed, figure), 0.8);
  EXPECT_EQ(cv::countNonZero((confirmed != 0) & ~figure), 0);  // never beyond the view's labels
}

// A detector's errors in the view: a blob beside the figure (a false piece)
// and the figure's mask dilated by 4 px. Only the other views' labels
// confirm, so neither is confirmed.
TEST(HullConfirmationTest, TheViewsOwnErrorsAreNotConfirmed) {
  Scene s = MakeScene();
  const cv::Mat figure = s.labels[kRef] == 1;
  cv::Mat dilated;
  cv::dilate(figure, dilated, cv::getStructuringElement(cv::MORPH_ELLIPSE, {9, 9}));
  const cv::Rect box = cv::boundingRect(figure);
  cv::Mat blob = cv::Mat::zeros(figure.size(), CV_8U);
  cv::circle(blob, {box.x - 14, box.y + box.height / 2}, 9, 255, cv::FILLED);
  ASSERT_EQ(cv::countNonZero(blob & dilated), 0);
  s.labels[kRef].setTo(1, dilated | blob);
  const cv::Mat confirmed = HullConfirmation(s.cameras, s.labels, kRef, kObject);
  EXPECT_EQ(cv::countNonZero((confirmed != 0) & blob), 0);
  // Most of the rim is not confirmed: the leave-one-out hull of the other
  // views, cast on a grid coarser than the image, is a little larger than
  // the figure.
  const cv::Mat rim = dilated & ~figure;
  EXPECT_LE(Covered(confirmed, rim), 0.15);
}

// Two people, one behind the other in the view: where the front one is seen,
// the ray meets the hull of the one behind it too, but only the nearest
// object is confirmed: the pixels the view gives to the person behind there
// (a wrong split of a merged instance) are not.
TEST(HullConfirmationTest, APersonBehindTheOneSeenIsNotConfirmed) {
  const synth::RigOptions rig = [] {
    synth::RigOptions o;
    o.image_width = 320;
    o.image_height = 180;
    return o;
  }();
  const std::vector<Camera> cameras = synth::RigCameras(rig);
  // Person 2 stands 0.8 m behind person 1 as view kRef sees them.
  Eigen::Vector3d towards = -cameras[kRef].Center();
  towards.y() = 0;  // along the floor, away from the camera
  towards.normalize();
  std::vector<Sphere> front = kBody, back = kBody;
  for (Sphere& b : back) b.centre += 0.8 * towards;
  std::vector<cv::Mat> labels;
  cv::Mat seen_front;
  for (const Camera& cam : cameras) {
    const cv::Mat f = RenderSpheres(cam, front), b = RenderSpheres(cam, back);
    cv::Mat ids = cv::Mat::zeros(cam.height, cam.width, CV_16U);
    const bool front_nearer = cam.Depth(front[1].centre) < cam.Depth(back[1].centre);
    ids.setTo(front_nearer ? 2 : 1, front_nearer ? b : f);
    ids.setTo(front_nearer ? 1 : 2, front_nearer ? f : b);
    labels.push_back(ids);
    if (labels.size() == static_cast<size_t>(kRef) + 1) seen_front = f.clone();
  }
  // The view's labels give the front person's upper half to person 2.
  const cv::Rect box = cv::boundingRect(seen_front);
  cv::Mat wrong = cv::Mat::zeros(seen_front.size(), CV_8U);
  wrong(cv::Rect(box.x, box.y, box.width, box.height / 2)).setTo(255);
  wrong &= seen_front;
  labels[kRef].setTo(2, wrong);
  const std::vector<HullObject> objects = {{1, 3.0, 6.0, {}}, {2, 3.0, 6.0, {}}};
  cv::Mat alone;
  const cv::Mat confirmed = HullConfirmation(cameras, labels, kRef, objects, {}, nullptr, &alone);
  EXPECT_LE(cv::countNonZero((confirmed == 2) & wrong), 0.05 * cv::countNonZero(wrong));
  EXPECT_GE(Covered(confirmed, seen_front & ~wrong), 0.6);
  // Where the person behind stands right behind the one seen, the rays meet
  // both hulls: not alone.
  const cv::Mat both = seen_front & RenderSpheres(cameras[kRef], back);
  EXPECT_LE(cv::countNonZero(alone & both), 0.05 * cv::countNonZero(both));
}

TEST(HullSupportTest, BadInputIsAnError) {
  const Scene s = MakeScene();
  EXPECT_THROW(HullSupport(s.cameras, s.labels, 8, kObject), Error);
  EXPECT_THROW(HullSupport(s.cameras, s.labels, 0, {{1, 5.0, 4.0, {}}}), Error);
  std::vector<cv::Mat> small = s.labels;
  small[2] = cv::Mat::zeros(10, 10, CV_16U);
  EXPECT_THROW(HullSupport(s.cameras, small, 0, kObject), Error);
  HullSupportOptions bad;
  bad.min_views = 0;
  EXPECT_THROW(HullSupport(s.cameras, s.labels, 0, kObject, bad), Error);
  HullSupportOptions negative;
  negative.max_background_views = -1;
  EXPECT_THROW(negative.Check(), Error);
}

}  // namespace
}  // namespace u4d
