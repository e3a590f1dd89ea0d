#include "u4d/pipeline/mesh_depth.h"

#include <cstdio>

#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>

#include "u4d/fusion/depth_fusion.h"
#include "u4d/fusion/fusion_test_util.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

class MeshDepthTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fusion_test::WriteSmallCapture("mesh_depth_test");
    maps_ = fusion_test::ReadGtFrame(ReadCapture(dir_), 0);
  }
  static inline fs::path dir_;
  static inline fusion_test::FrameMaps maps_;
};

// Each view's depth as a solve's errs: smooth noise of 0.6 % (the spread of
// the solve's depth error) and, per person, patches where a wrong depth label
// won (discs of 8 px, 5 % too far), at places that differ between views.
std::vector<cv::Mat> PatchyDepth(const fusion_test::FrameMaps& maps) {
  std::vector<cv::Mat> depths(maps.depths.size());
  cv::RNG rng(7);
  for (size_t v = 0; v < depths.size(); ++v) {
    const cv::Mat noise = fusion_test::SmoothNoise(maps.depths[v].size(), 1, 0.006, 4.0, rng);
    depths[v] = maps.depths[v].mul(1.0f + noise);
    std::vector<cv::Point> people;
    cv::findNonZero(maps.ids[v], people);
    for (int k = 0; k < 3 && !people.empty(); ++k) {
      const cv::Point c = people[rng.uniform(0, static_cast<int>(people.size()))];
      cv::Mat disc = cv::Mat::zeros(depths[v].size(), CV_8U);
      cv::circle(disc, c, 8, cv::Scalar(255), cv::FILLED);
      cv::Mat far = depths[v] * 1.05;
      far.copyTo(depths[v], disc & (maps.ids[v] > 0));
    }
  }
  return depths;
}

struct DepthError {
  double abs_rel = 0, within_1pc = 0;
};

// Over every view's GT person pixels.
DepthError ErrorOf(const fusion_test::FrameMaps& maps, const std::vector<cv::Mat>& depths) {
  DepthError e;
  long n = 0;
  for (size_t v = 0; v < depths.size(); ++v)
    for (int y = 0; y < depths[v].rows; ++y)
      for (int x = 0; x < depths[v].cols; ++x) {
        const float gt = maps.depths[v].at<float>(y, x);
        if (maps.ids[v].at<uint16_t>(y, x) == 0 || !(gt > 0)) continue;
        const double rel = std::abs(depths[v].at<float>(y, x) - gt) / gt;
        e.abs_rel += rel, e.within_1pc += rel < 0.01, ++n;
      }
  e.abs_rel /= n, e.within_1pc /= n;
  return e;
}

// The fused surface agrees with all views at once, so where a view's own
// depth is off (its patches, its noise) the surface is nearer the truth.
TEST_F(MeshDepthTest, TheFusedSurfaceBringsEachViewsDepthNearerTheTruth) {
  const std::vector<cv::Mat> patchy = PatchyDepth(maps_);
  std::vector<FusedMesh> fused;
  std::vector<const open3d::geometry::TriangleMesh*> meshes;
  const std::vector<int> ids = {1, 2};
  for (int id : ids) {
    fused.push_back(FuseObject(maps_.cameras, patchy, maps_.ids, maps_.images, id, {}));
    ASSERT_FALSE(fused.back().Empty());
    meshes.push_back(fused.back().mesh.get());
  }
  std::vector<cv::Mat> fed_back(patchy.size());
  int replaced = 0, people = 0;
  for (size_t v = 0; v < patchy.size(); ++v) {
    fed_back[v] = patchy[v].clone();
    replaced += DepthFromMeshes(meshes, ids, maps_.cameras[v], maps_.ids[v], &fed_back[v]);
    people += cv::countNonZero(maps_.ids[v]);
    // The background keeps its depth.
    EXPECT_EQ(cv::norm(fed_back[v], patchy[v], cv::NORM_INF, maps_.ids[v] == 0), 0.0);
  }
  const DepthError before = ErrorOf(maps_, patchy), after = ErrorOf(maps_, fed_back);
  std::printf("AbsRel %.4f -> %.4f, within 1 %% %.3f -> %.3f, %d of %d person pixels replaced\n",
              before.abs_rel, after.abs_rel, before.within_1pc, after.within_1pc, replaced, people);
  EXPECT_GT(replaced, 0.9 * people);
  EXPECT_LT(after.abs_rel, 0.6 * before.abs_rel);
  EXPECT_GT(after.within_1pc, before.within_1pc + 0.1);
}

// Where the labels and the meshes disagree on who is seen (another object's
// surface is nearest) or no mesh covers a pixel, the view's own depth stays.
TEST_F(MeshDepthTest, APixelOfAnotherObjectsSurfaceKeepsItsDepth) {
  const std::vector<int> ids = {1};
  const FusedMesh one = FuseObject(maps_.cameras, maps_.depths, maps_.ids, maps_.images, 1, {});
  ASSERT_FALSE(one.Empty());
  cv::Mat labels = maps_.ids[0].clone();
  labels.setTo(2, labels == 1);  // person 1's pixels said to be person 2's
  cv::Mat depth(labels.size(), CV_32F, cv::Scalar(7.0f));
  EXPECT_EQ(DepthFromMeshes({one.mesh.get()}, ids, maps_.cameras[0], labels, &depth), 0);
  EXPECT_EQ(cv::countNonZero(depth != 7.0f), 0);
  EXPECT_EQ(DepthFromMeshes({nullptr}, ids, maps_.cameras[0], maps_.ids[0], &depth), 0);
}

TEST_F(MeshDepthTest, BadInputIsAnError) {
  const Camera& camera = maps_.cameras[0];
  cv::Mat depth = maps_.depths[0].clone();
  const cv::Mat small = cv::Mat::zeros(10, 10, CV_16U);
  EXPECT_THROW(DepthFromMeshes({}, {}, camera, small, &depth), Error);
  EXPECT_THROW(DepthFromMeshes({nullptr}, {}, camera, maps_.ids[0], &depth), Error);
  EXPECT_THROW(DepthFromMeshes({nullptr}, {0}, camera, maps_.ids[0], &depth), Error);
  cv::Mat wrong_type = cv::Mat::zeros(depth.size(), CV_64F);
  EXPECT_THROW(DepthFromMeshes({}, {}, camera, maps_.ids[0], &wrong_type), Error);
  EXPECT_THROW(DepthFromMeshes({}, {}, camera, maps_.ids[0], nullptr), Error);
}

}  // namespace
}  // namespace u4d
