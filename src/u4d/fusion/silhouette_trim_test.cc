// The silhouette test of fused vertices (silhouette_trim.h) on hand-made
// views: one camera looking at the origin, masks drawn around its pixel.
#include "u4d/fusion/silhouette_trim.h"

#include <gtest/gtest.h>

#include "u4d/util/testing.h"

namespace u4d {
namespace {

constexpr int kSize = 100;

Camera CameraFiveMetresAway() {
  Camera c;
  c.width = c.height = kSize;
  c.K << 100, 0, 50, 0, 100, 50, 0, 0, 1;
  c.cam_from_world.translation = Eigen::Vector3d(0, 0, 5);
  return c;
}

// A view whose object `id` covers the square [x0, x1) x [40, 60) at depth
// `z` (the vertex at the origin projects to pixel (50, 50) at depth 5).
struct View {
  cv::Mat ids = cv::Mat::zeros(kSize, kSize, CV_16UC1);
  cv::Mat depth = cv::Mat::zeros(kSize, kSize, CV_32FC1);
  View Copy() const { return {ids.clone(), depth.clone()}; }
  View& Square(int id, int x0, int x1, float z) {
    ids(cv::Rect(x0, 40, x1 - x0, 20)).setTo(id);
    depth(cv::Rect(x0, 40, x1 - x0, 20)).setTo(z);
    return *this;
  }
};

// Whether the vertex at the origin, off the observed surface (or on it:
// `supported`), is outside.
bool Outside(const std::vector<View>& views, const SilhouetteTrimOptions& o = {},
             bool supported = false) {
  std::vector<cv::Mat> ids, depths;
  for (const View& v : views) {
    ids.push_back(v.ids);
    depths.push_back(v.depth);
  }
  const std::vector<Camera> cameras(views.size(), CameraFiveMetresAway());
  return OutsideSilhouettes({Eigen::Vector3d::Zero()}, {supported}, cameras, depths, ids, 1, o)[0];
}

TEST(SilhouetteTrim, AVertexTwoViewsSeeOffTheObjectIsOutside) {
  const View off = View().Square(1, 0, 30, 5.f);  // the object ends 20 px left of the vertex
  const View on = View().Square(1, 30, 70, 5.f);
  EXPECT_TRUE(Outside({off, off, on, on}));
  EXPECT_FALSE(Outside({off, on, on}));  // one view's mask may miss a part
  SilhouetteTrimOptions one;
  one.min_views = 1;
  EXPECT_TRUE(Outside({off, on, on}, one));
  SilhouetteTrimOptions none;
  none.min_views = 0;
  EXPECT_FALSE(Outside({off, off, off}, none));
}

// On the observed surface (a depth point near), two views' masks that miss
// a part the others hold do not cut it: more views must see it off than on.
TEST(SilhouetteTrim, AVertexOnTheObservedSurfaceGoesOnlyWhenMostViewsSeeItOff) {
  const View off = View().Square(1, 0, 30, 5.f);
  const View on = View().Square(1, 30, 70, 5.f);
  EXPECT_FALSE(Outside({off, off, on, on}, {}, /*supported=*/true));
  EXPECT_TRUE(Outside({off, off, off, on, on}, {}, true));
  SilhouetteTrimOptions one;
  one.min_views = 1;
  EXPECT_TRUE(Outside({off}, one, true));
  EXPECT_FALSE(Outside({off, on}, one, true));
  // Without support flags no vertex is on the observed surface.
  const std::vector<Camera> cameras(4, CameraFiveMetresAway());
  EXPECT_TRUE(OutsideSilhouettes({Eigen::Vector3d::Zero()}, {}, cameras,
                                 {off.depth, off.depth, on.depth, on.depth},
                                 {off.ids, off.ids, on.ids, on.ids}, 1, {})[0]);
  test_util::ExpectErrorMentions(
      [&] {
        OutsideSilhouettes({Eigen::Vector3d::Zero()}, {true, true}, cameras,
                           {off.depth, off.depth, on.depth, on.depth},
                           {off.ids, off.ids, on.ids, on.ids}, 1, {});
      },
      {"2 support flags for 1 vertices"});
}

TEST(SilhouetteTrim, TheMarginCountsAsInside) {
  const View near = View().Square(1, 0, 50, 5.f);  // 1 px from the vertex's pixel
  EXPECT_FALSE(Outside({near, near}));
  SilhouetteTrimOptions tight;
  tight.margin_px = 0.5;
  EXPECT_TRUE(Outside({near, near}, tight));
  const View two_away = View().Square(1, 0, 48, 5.f);
  EXPECT_TRUE(Outside({two_away, two_away}));
}

TEST(SilhouetteTrim, ANearerObjectHidesTheVertexAFartherOneDoesNot) {
  const View off = View().Square(1, 0, 30, 5.f);
  View hidden = off.Copy();
  hidden.Square(2, 40, 60, 4.f);  // another object 1 m in front of the vertex
  View behind = off.Copy();
  behind.Square(2, 40, 60, 6.f);  // another object behind it: the vertex floats in front
  EXPECT_FALSE(Outside({off, hidden}));
  EXPECT_TRUE(Outside({off, behind}));
}

TEST(SilhouetteTrim, AViewWithoutTheObjectOrNotSeeingTheVertexGivesNoEvidence) {
  const View off = View().Square(1, 0, 30, 5.f);
  const View missed = View().Square(2, 0, 30, 5.f);  // the detector missed object 1 here
  EXPECT_FALSE(Outside({off, missed}));
  std::vector<cv::Mat> ids{off.ids, off.ids}, depths{off.depth, off.depth};
  const std::vector<Camera> cameras(2, CameraFiveMetresAway());
  const std::vector<Eigen::Vector3d> vertices{{0, 0, -6}, {10, 0, 0}};  // behind, out of the image
  const std::vector<bool> outside =
      OutsideSilhouettes(vertices, {}, cameras, depths, ids, 1, SilhouetteTrimOptions{});
  EXPECT_FALSE(outside[0]);
  EXPECT_FALSE(outside[1]);
}

TEST(SilhouetteTrim, BadInputsThrow) {
  const View view = View().Square(1, 0, 30, 5.f);
  const std::vector<Camera> cameras(2, CameraFiveMetresAway());
  const std::vector<Eigen::Vector3d> vertex{Eigen::Vector3d::Zero()};
  const SilhouetteTrimOptions o;
  test_util::ExpectErrorMentions(
      [&] {
        OutsideSilhouettes(vertex, {}, cameras, {view.depth}, {view.ids, view.ids}, 1, o);
      },
      {"one depth and instance map per camera"});
  const cv::Mat small = cv::Mat::zeros(50, 50, CV_16UC1);
  test_util::ExpectErrorMentions(
      [&] {
        OutsideSilhouettes(vertex, {}, cameras, {view.depth, view.depth}, {view.ids, small}, 1, o);
      },
      {"instance ids of view 1", "100x100", "50x50"});
  const cv::Mat bytes = cv::Mat::zeros(kSize, kSize, CV_8UC1);
  test_util::ExpectErrorMentions(
      [&] {
        OutsideSilhouettes(vertex, {}, cameras, {bytes, view.depth}, {view.ids, view.ids}, 1, o);
      },
      {"depth of view 0", "CV_32FC1"});
}

TEST(SilhouetteTrim, BadOptionsThrow) {
  SilhouetteTrimOptions o;
  o.min_views = -1;
  test_util::ExpectErrorMentions([&] { o.Check(); }, {"min_views"});
  o = {};
  o.margin_px = -1;
  test_util::ExpectErrorMentions([&] { o.Check(); }, {"margin_px"});
  o = {};
  o.occlusion_tolerance = 0;
  test_util::ExpectErrorMentions([&] { o.Check(); }, {"occlusion_tolerance"});
  o = {};
  o.support_factor = -1;
  test_util::ExpectErrorMentions([&] { o.Check(); }, {"support_factor"});
}

}  // namespace
}  // namespace u4d
