// Temporal coherence (paper Sec. 4): fused vertices tracked with the GT scene
// flow must follow the GT surface points (GT mesh vertex i is the same body
// point in every frame, docs/synthetic.md).
#include "u4d/fusion/scene_flow.h"

#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>
#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <opencv2/imgproc.hpp>

#include "u4d/eval/mesh_metrics.h"
#include "u4d/fusion/depth_fusion.h"
#include "u4d/fusion/fusion_test_util.h"
#include "u4d/util/stats.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

// The GT frames with what a per-frame estimate gets wrong: every frame's
// depth maps carry their own relative error (sigma depth_rel) and the flows
// an error of sigma flow_px.
std::vector<fusion_test::FrameMaps> Perturbed(const std::vector<fusion_test::FrameMaps>& frames,
                                              double depth_rel, double flow_px) {
  cv::RNG rng(7);
  std::vector<fusion_test::FrameMaps> out = frames;
  for (fusion_test::FrameMaps& f : out) {
    for (cv::Mat& d : f.depths) {
      d = d.clone();
      const cv::Mat n = fusion_test::SmoothNoise(d.size(), 1, depth_rel, 3.0, rng);
      d = d.mul(1 + n);  // 0 (no depth) stays 0
    }
    for (cv::Mat& m : f.flows) {
      cv::Mat noisy;  // a new buffer: the input frames share theirs
      cv::add(m, fusion_test::SmoothNoise(m.size(), 2, flow_px, 3.0, rng), noisy);
      m = noisy;
    }
  }
  return out;
}

std::vector<SceneFlowView> GtStep(const fusion_test::FrameMaps& a, const fusion_test::FrameMaps& b,
                                  bool zero_flow) {
  std::vector<SceneFlowView> views;
  for (size_t v = 0; v < a.cameras.size(); ++v) {
    SceneFlowView s;
    s.camera_t = a.cameras[v];
    s.camera_t1 = b.cameras[v];
    s.depth_t = a.depths[v];
    s.depth_t1 = b.depths[v];
    s.flow = zero_flow ? cv::Mat(a.flows[v].size(), CV_32FC2, cv::Scalar::all(0)) : a.flows[v];
    s.instances_t = a.ids[v];
    s.instances_t1 = b.ids[v];
    views.push_back(s);
  }
  return views;
}

class SceneFlowTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fusion_test::WriteSmallCapture("fusion_flow_test");
    capture_ = ReadCapture(dir_);
    for (int f = 0; f < 3; ++f) frames_.push_back(fusion_test::ReadGtFrame(capture_, f));
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  // Median over fused vertices of |tracked(k) - (gt_k[match] + offset)| for
  // k = 1, 2, where match is the nearest GT vertex at frame 0.
  static std::vector<double> Drift(const FusedMesh& fused, bool zero_flow, double* tracked_share,
                                   double* gt_motion,
                                   const std::vector<fusion_test::FrameMaps>* maps = nullptr,
                                   const TrackOptions& options = {}) {
    const std::vector<fusion_test::FrameMaps>& frames = maps ? *maps : frames_;
    const int id = fused.object_id;
    std::vector<open3d::geometry::TriangleMesh> gt;
    for (int f = 0; f < 3; ++f) gt.push_back(eval::ReadMesh(dir_ / layout::GtMesh(id, f)));
    open3d::geometry::PointCloud gt0;
    gt0.points_ = gt[0].vertices_;
    open3d::geometry::KDTreeFlann tree(gt0);
    const auto& verts = fused.mesh->vertices_;
    std::vector<int> match(verts.size());
    std::vector<int> idx(1);
    std::vector<double> d2(1);
    for (size_t i = 0; i < verts.size(); ++i) {
      tree.SearchKNN(verts[i], 1, idx, d2);
      match[i] = idx[0];
    }
    const AnimatedMesh seg = TrackSegment(
        *fused.mesh, id, 0, 2, [&](int k) { return GtStep(frames[k], frames[k + 1], zero_flow); },
        options);
    EXPECT_EQ(seg.NumFrames(), 3);
    EXPECT_EQ(seg.colors.size(), verts.size());
    *tracked_share = seg.tracked_fraction[0];
    std::vector<double> out, motion;
    for (int k = 1; k <= 2; ++k) {
      std::vector<double> drift;
      for (size_t i = 0; i < verts.size(); ++i) {
        const Eigen::Vector3d expected =
            gt[k].vertices_[match[i]] + (verts[i] - gt[0].vertices_[match[i]]);
        drift.push_back((seg.positions[k][i] - expected).norm());
        motion.push_back((gt[k].vertices_[match[i]] - gt[0].vertices_[match[i]]).norm());
      }
      out.push_back(Median(drift));
    }
    *gt_motion = Median(motion);
    return out;
  }

  static inline fs::path dir_;
  static inline Capture capture_;
  static inline std::vector<fusion_test::FrameMaps> frames_;
};

// With exact flow and depth the only errors are the sampling of the maps
// (bilinear depth and flow on a ~16 mm pixel grid at 320x180) and the change
// of a vertex's offset from the surface when its body part rotates, both of
// a few millimetres: the median drift after two frames must stay below 5 mm
// (a third of a pixel's footprint). Without flow every vertex keeps its
// frame-0 position (plus depth re-sampling), so the drift is the body's own
// motion: it must be at least 3x larger, which the GT motion printed shows.
TEST_F(SceneFlowTest, GtFlowFollowsGtVertices) {
  for (int id = 1; id <= 2; ++id) {
    double share = 0, motion = 0, share0 = 0, motion0 = 0;
    const FusedMesh fused = FuseObject(frames_[0].cameras, frames_[0].depths, frames_[0].ids,
                                       frames_[0].images, id, FusionOptions{});
    ASSERT_FALSE(fused.Empty());
    const std::vector<double> d = Drift(fused, false, &share, &motion);
    const std::vector<double> d0 = Drift(fused, true, &share0, &motion0);
    std::printf(
        "person %d: tracked %.1f%% of vertices; median drift frame 1 %.2f mm, frame 2 %.2f mm; "
        "zero flow %.2f / %.2f mm; median GT motion over 2 frames %.1f mm\n",
        id, 100 * share, d[0] * 1e3, d[1] * 1e3, d0[0] * 1e3, d0[1] * 1e3, motion * 1e3);
    EXPECT_GT(share, 0.5);
    EXPECT_LT(d[1], 0.005);
    EXPECT_GT(d0[1], 3 * d[1]);
  }
}

// Depth maps solved frame by frame carry independent errors of about 1 % (4-5
// cm at these distances; about half of the joint solve's depths are within
// 1 %); flows err by a fraction of a pixel (joint flow EPE on people 0.25-0.65
// px). A vertex moved by one view's depth difference inherits both frames'
// depth errors, and a 3 cm visibility test rejects most views; the
// reprojection refinement lets the flows of all views triangulate the motion
// instead. On the same perturbed maps (1 % depth, 0.3 px flow) the refined
// drift after two frames must be at most half the former one (no refinement,
// 3 cm visibility), and below one pixel's footprint (~16 mm at 320x180).
TEST_F(SceneFlowTest, ReprojectionRefinementResistsPerFrameDepthNoise) {
  const std::vector<fusion_test::FrameMaps> noisy = Perturbed(frames_, 0.01, 0.3);
  TrackOptions former;  // the tracking before the refinement: 3 cm visibility, no refinement
  former.refine_iterations = 0;
  former.depth_sigma_rel = 1e-9;
  for (int id = 1; id <= 2; ++id) {
    const FusedMesh fused = FuseObject(frames_[0].cameras, frames_[0].depths, frames_[0].ids,
                                       frames_[0].images, id, FusionOptions{});
    ASSERT_FALSE(fused.Empty());
    double share = 0, motion = 0;
    const std::vector<double> refined = Drift(fused, false, &share, &motion, &noisy, {});
    const std::vector<double> unrefined = Drift(fused, false, &share, &motion, &noisy, former);
    const std::vector<double> exact = Drift(fused, false, &share, &motion, nullptr, {});
    std::printf(
        "person %d: median drift after 1 / 2 frames with 1%% depth and 0.3 px flow noise: "
        "refined %.2f / %.2f mm, former (no refinement, 3 cm visibility) %.2f / %.2f mm; exact "
        "maps (refined) %.2f / %.2f mm; "
        "GT motion %.1f mm\n",
        id, refined[0] * 1e3, refined[1] * 1e3, unrefined[0] * 1e3, unrefined[1] * 1e3,
        exact[0] * 1e3, exact[1] * 1e3, motion * 1e3);
    EXPECT_LT(refined[1], 0.5 * unrefined[1]);
    EXPECT_LT(refined[1], 0.016);
  }
}

// Untracked vertices take their neighbours' displacement: a mesh strip whose
// vertices see no view moves with the tracked ones.
TEST(SceneFlowUnit, InterpolatesUntrackedVerticesFromNeighbours) {
  Camera cam;
  cam.width = 64;
  cam.height = 48;
  cam.K << 50, 0, 31.5, 0, 50, 23.5, 0, 0, 1;
  SceneFlowView v;
  v.camera_t = v.camera_t1 = cam;
  v.depth_t = cv::Mat(48, 64, CV_32FC1, cv::Scalar(2.0f));
  v.depth_t1 = v.depth_t.clone();
  v.flow = cv::Mat(48, 64, CV_32FC2, cv::Scalar(2.5f, 0.0f));  // 2.5 px right = 0.1 m at 2 m
  // A row of vertices at x = -0.6 ... 1.65 m, z = 2 m (u = 16.5 ... 72.75 px):
  // the first four are seen and move inside the image (tracked), the fifth
  // moves out of it and the sixth is outside (no candidate: interpolated).
  std::vector<Eigen::Vector3d> verts;
  for (int i = 0; i < 6; ++i) verts.emplace_back(-0.6 + 0.45 * i, 0, 2.0);
  std::vector<Eigen::Vector3i> tris;
  for (int i = 0; i + 2 < 6; ++i) tris.emplace_back(i, i + 1, i + 2);
  const TrackResult r = TrackVertices(verts, tris, {v}, 1, TrackOptions{});
  ASSERT_EQ(r.positions.size(), 6u);
  EXPECT_EQ(r.num_tracked + r.num_interpolated, 6);
  EXPECT_EQ(r.num_tracked, 4);
  EXPECT_EQ(r.num_interpolated, 2);
  for (int i = 0; i < 6; ++i)
    EXPECT_LT((r.positions[i] - verts[i] - Eigen::Vector3d(0.1, 0, 0)).norm(), 1e-6) << i;
}

TEST(SceneFlowUnit, BadInputsThrow) {
  Camera cam;
  cam.width = 64;
  cam.height = 48;
  cam.K << 50, 0, 31.5, 0, 50, 23.5, 0, 0, 1;
  SceneFlowView v;
  v.camera_t = v.camera_t1 = cam;
  v.depth_t = cv::Mat(48, 64, CV_32FC1, cv::Scalar(2.0f));
  v.depth_t1 = v.depth_t.clone();
  v.flow = cv::Mat(24, 32, CV_32FC2, cv::Scalar::all(0));
  const std::vector<Eigen::Vector3d> verts = {{0, 0, 2}};
  test_util::ExpectErrorMentions([&] { TrackVertices(verts, {}, {v}, 1, TrackOptions{}); },
                                 {"view 0 flow", "64x48", "32x24"});
  v.flow = cv::Mat(48, 64, CV_32FC2, cv::Scalar::all(0));
  test_util::ExpectErrorMentions(
      [&] { TrackVertices(verts, {Eigen::Vector3i(0, 1, 2)}, {v}, 1, TrackOptions{}); },
      {"triangle index"});
  test_util::ExpectErrorMentions([&] { TrackVertices(verts, {}, {}, 1, TrackOptions{}); },
                                 {"no views"});
  test_util::ExpectErrorMentions(
      [&] {
        TrackSegment(
            open3d::geometry::TriangleMesh(), 1, 0, 1,
            [&](int) { return std::vector<SceneFlowView>{v}; }, TrackOptions{});
      },
      {"empty"});
}

}  // namespace
}  // namespace u4d
