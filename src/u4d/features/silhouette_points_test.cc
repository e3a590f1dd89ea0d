#include "u4d/features/silhouette_points.h"

#include <vector>

#include <gtest/gtest.h>

#include "u4d/synth/rig.h"
#include "u4d/testing/sphere_figure.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

using testing::DistanceToSpheres;
using testing::RenderSpheres;
using testing::Sphere;

// Two people of spheres, a metre apart, in the middle of the 8-camera ring
// (radius 4.5 m).
const std::vector<Sphere> kA = {
    {{-0.5, 0.5, 0}, 0.2}, {{-0.5, 0.9, 0}, 0.2}, {{-0.5, 1.3, 0}, 0.18}};
const std::vector<Sphere> kB = {{{0.5, 0.5, 0}, 0.2}, {{0.5, 0.9, 0}, 0.2}, {{0.5, 1.3, 0}, 0.18}};

struct Views {
  std::vector<Camera> cameras;
  std::vector<cv::Mat> a, b;  // CV_8U silhouettes per view
};

Views MakeViews() {
  synth::RigOptions rig;
  rig.image_width = 320;
  rig.image_height = 180;
  Views s;
  s.cameras = synth::RigCameras(rig);
  for (const Camera& cam : s.cameras) {
    s.a.push_back(RenderSpheres(cam, kA));
    s.b.push_back(RenderSpheres(cam, kB));
  }
  return s;
}

struct Found {
  int on_a = 0, on_b = 0;
  double worst = 0;  // largest distance to the true surface (m)
};

Found Classify(const std::vector<SparsePoint>& points) {
  Found f;
  for (const SparsePoint& p : points) {
    const double da = DistanceToSpheres(p.position, kA), db = DistanceToSpheres(p.position, kB);
    (da < db ? f.on_a : f.on_b) += 1;
    f.worst = std::max(f.worst, std::abs(std::min(da, db)));
  }
  return f;
}

// The hull's depth samples are even in inverse depth from 0.3 m to 13.5 m
// (1.5 x the ring's diameter): at 4.5 m they are 0.35 m apart, so a point
// may lie up to one sample in front of the surface.
constexpr double kTolerance = 0.4;

TEST(SilhouettePointsTest, BothPeopleHaveSurfacePointsWithEveryMask) {
  const Views s = MakeViews();
  std::vector<cv::Mat> masks;
  for (size_t v = 0; v < s.cameras.size(); ++v) masks.push_back(s.a[v] | s.b[v]);
  const Found f = Classify(SilhouettePoints(s.cameras, masks));
  EXPECT_GT(f.on_a, 200);
  EXPECT_GT(f.on_b, 200);
  EXPECT_LE(f.worst, kTolerance);
}

// A detector that misses person B in one view (or everybody in another)
// must not carve B out of every view's hull: the points on B stay, as
// accurate; requiring every view's foreground (share 1) loses them.
TEST(SilhouettePointsTest, APersonMissedInOneViewKeepsItsPoints) {
  const Views s = MakeViews();
  std::vector<cv::Mat> masks;
  for (size_t v = 0; v < s.cameras.size(); ++v) masks.push_back(s.a[v] | s.b[v]);
  const Found all = Classify(SilhouettePoints(s.cameras, masks));
  masks[3] = s.a[3].clone();                        // B missed in view 3
  masks[6] = cv::Mat::zeros(s.a[6].size(), CV_8U);  // nobody found in view 6
  const Found missed = Classify(SilhouettePoints(s.cameras, masks));
  SilhouettePointOptions every_view;
  every_view.min_foreground_share = 1;
  const Found strict = Classify(SilhouettePoints(s.cameras, masks, every_view));
  std::printf(
      "points on A / B: all masks %d / %d, B missed in a view and an empty view %d / %d, "
      "the same requiring every view %d / %d\n",
      all.on_a, all.on_b, missed.on_a, missed.on_b, strict.on_a, strict.on_b);
  EXPECT_GE(missed.on_b, 0.5 * all.on_b);
  EXPECT_GE(missed.on_a, 0.5 * all.on_a);
  EXPECT_LE(missed.worst, kTolerance);
  EXPECT_LT(strict.on_b, 0.1 * all.on_b);
}

// B is an object A holds, and C another object, seen in every view: in half
// the views the detector gives B as part of A (B's mask is missing there,
// A's covers it). Those views carve B away, unless A's pixels are where they
// cannot tell (`unknown`): then B keeps its points.
TEST(SilhouettePointsTest, AnObjectMergedWithItsHolderInHalfTheViewsKeepsItsPoints) {
  const Views s = MakeViews();
  const std::vector<Sphere> c = {{{0, 0.4, -1.2}, 0.25}};
  std::vector<cv::Mat> objects, people;
  for (size_t v = 0; v < s.cameras.size(); ++v) {
    const bool merged = v % 2 == 1;
    const cv::Mat on_c = RenderSpheres(s.cameras[v], c);
    objects.push_back(merged ? on_c : (s.b[v] | on_c));
    people.push_back(merged ? (s.a[v] | s.b[v]) : s.a[v].clone());
  }
  auto on_b = [](const std::vector<SparsePoint>& points) {
    int n = 0;
    for (const SparsePoint& p : points)
      n += std::abs(DistanceToSpheres(p.position, kB)) < kTolerance;
    return n;
  };
  const int carved = on_b(SilhouettePoints(s.cameras, objects));
  const int kept = on_b(SilhouettePoints(s.cameras, objects, {}, &people));
  std::printf("points on the object: %d carved by the merged views, %d with them abstaining\n",
              carved, kept);
  EXPECT_LT(carved, 20);
  EXPECT_GT(kept, 150);
  std::vector<cv::Mat> wrong(3);
  EXPECT_THROW(SilhouettePoints(s.cameras, objects, {}, &wrong), Error);
}

TEST(SilhouettePointsTest, BadOptionsAreRefused) {
  const Views s = MakeViews();
  SilhouettePointOptions o;
  o.min_foreground_share = 0;
  EXPECT_THROW(SilhouettePoints(s.cameras, s.a, o), Error);
  o.min_foreground_share = 1.5;
  EXPECT_THROW(SilhouettePoints(s.cameras, s.a, o), Error);
}

}  // namespace
}  // namespace u4d
