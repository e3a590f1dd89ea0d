// Tests of step 4b (init.h: PeopleFromBoxes, BoxesOfPeople) against people
// placed on a known floor and seen by a ring of calibrated cameras.
#include <gtest/gtest.h>

#include <vector>

#include "u4d/init/init.h"
#include "u4d/synth/rig.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

// Five cameras on a ring of 4.5 m around the origin, 1.6 m above a floor
// at height 0.3 (the floor is not at the rig's centre or at zero), looking
// at a point 0.9 m above the floor.
constexpr double kFloor = 0.3;

std::vector<Camera> Ring() {
  std::vector<Camera> cameras;
  for (int k = 0; k < 5; ++k) {
    const double a = 2 * M_PI * k / 5 + 0.3;
    cameras.push_back(synth::MakeLookAtCamera(
        Eigen::Vector3d(4.5 * std::cos(a), kFloor + 1.6, 4.5 * std::sin(a)),
        Eigen::Vector3d(0, kFloor + 0.9, 0), Eigen::Vector3d::UnitY(), 640, 480, 60));
  }
  return cameras;
}

// A HOG-like detection of a 1.75 m person standing at `foot`: the person
// fills 7/8 of the box's height, with 1/16 of it below the feet (as
// PeopleFromBoxes assumes), half as wide as tall, shifted by `jitter` px.
PersonBox HogLikeBox(const Camera& camera, const Eigen::Vector3d& foot, int jitter) {
  const Eigen::Vector2d f = camera.Project(foot);
  const Eigen::Vector2d h = camera.Project(foot + 1.75 * Eigen::Vector3d::UnitY());
  const double height = (f.y() - h.y()) * 8.0 / 7.0;
  PersonBox b;
  b.box = cv::Rect(static_cast<int>(f.x() - height / 4 + jitter),
                   static_cast<int>(f.y() + height / 16 - height - jitter),
                   static_cast<int>(height / 2), static_cast<int>(height));
  b.score = 1;
  return b;
}

TEST(PeopleFromBoxesTest, FindsPeopleTwoViewsConfirmAndBoxesThemEverywhere) {
  const std::vector<Camera> cameras = Ring();
  const std::vector<Eigen::Vector3d> truth = {
      {0.5, kFloor, 0.2}, {-0.6, kFloor, -0.4}, {0.1, kFloor, 1.1}};
  std::vector<std::vector<PersonBox>> boxes(cameras.size());
  for (size_t v = 0; v < cameras.size(); ++v) {
    const int jitter = static_cast<int>(v % 3) - 1;
    boxes[v].push_back(HogLikeBox(cameras[v], truth[0], jitter));
    // The second person: missed by the detector in views 1 and 3.
    if (v != 1 && v != 3) boxes[v].push_back(HogLikeBox(cameras[v], truth[1], -jitter));
    // The third: found in two views only.
    if (v == 0 || v == 2) boxes[v].push_back(HogLikeBox(cameras[v], truth[2], jitter));
  }
  // False boxes on the background: one view's alone, and two views' whose
  // foot rays meet far below the floor.
  boxes[4].push_back({cv::Rect(20, 30, 60, 120), 0.5});
  boxes[1].push_back({cv::Rect(560, 300, 70, 140), 0.2});

  const std::vector<FloorPerson> people = PeopleFromBoxes(cameras, boxes);
  ASSERT_EQ(people.size(), truth.size());
  for (size_t k = 0; k < truth.size(); ++k) {
    double nearest = 1e9;
    const FloorPerson* match = nullptr;
    for (const FloorPerson& p : people)
      if ((p.foot - truth[k]).norm() < nearest) nearest = (p.foot - truth[k]).norm(), match = &p;
    EXPECT_LT(nearest, 0.1) << "person " << k;
    EXPECT_EQ(match->num_views, k == 0 ? 5 : k == 1 ? 3 : 2) << "person " << k;
  }

  // Every view boxes every person, also where the detector missed them: the
  // box holds the projected feet and head.
  const std::vector<std::vector<PersonBox>> projected = BoxesOfPeople(cameras, people);
  ASSERT_EQ(projected.size(), cameras.size());
  for (size_t v = 0; v < cameras.size(); ++v) {
    ASSERT_EQ(projected[v].size(), truth.size()) << "view " << v;
    for (const Eigen::Vector3d& foot : truth) {
      bool held = false;
      for (const PersonBox& b : projected[v]) {
        const Eigen::Vector2d f = cameras[v].Project(foot);
        const Eigen::Vector2d h = cameras[v].Project(foot + 1.75 * Eigen::Vector3d::UnitY());
        held = held || (b.box.contains(cv::Point(f.x(), f.y() - 1)) &&
                        b.box.contains(cv::Point(h.x(), h.y())));
      }
      EXPECT_TRUE(held) << "view " << v;
    }
  }
}

TEST(PeopleFromBoxesTest, OneViewOrNoPairMakesNoPerson) {
  const std::vector<Camera> cameras = Ring();
  const Eigen::Vector3d foot(0.2, kFloor, 0.1);
  std::vector<std::vector<PersonBox>> boxes(cameras.size());
  boxes[2].push_back(HogLikeBox(cameras[2], foot, 0));
  EXPECT_TRUE(PeopleFromBoxes(cameras, boxes).empty());
  EXPECT_TRUE(PeopleFromBoxes({cameras[2]}, {boxes[2]}).empty());
  EXPECT_TRUE(BoxesOfPeople(cameras, {}).at(0).empty());
  test_util::ExpectErrorMentions([&] { PeopleFromBoxes(cameras, {boxes[2]}); },
                                 {"5 cameras", "1 views"});
  InitOptions bad;
  bad.people.person_radius_m = 0;
  test_util::ExpectErrorMentions([&] { PeopleFromBoxes(cameras, boxes, bad); },
                                 {"person_radius_m"});
}

}  // namespace
}  // namespace u4d
