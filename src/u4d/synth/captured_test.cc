#include "u4d/synth/captured.h"

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/TriangleMeshIO.h>

#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/synth/contact.h"
#include "u4d/synth/generate.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d::synth {
namespace {

// A unit cube scaled to `size` with its base centred at `base`, as an OBJ.
void WriteCube(const fs::path& path, const Eigen::Vector3f& base, const Eigen::Vector3f& size) {
  std::ofstream out(path);
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3f unit((i & 1) ? 0.5f : -0.5f, (i & 2) ? 1.f : 0.f, (i & 4) ? 0.5f : -0.5f);
    const Eigen::Vector3f v = base + unit.cwiseProduct(size);
    out << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
  }
  const int faces[12][3] = {{1, 3, 2}, {2, 3, 4}, {5, 6, 7}, {6, 8, 7}, {1, 2, 5}, {2, 6, 5},
                            {3, 7, 4}, {4, 7, 8}, {1, 5, 3}, {3, 5, 7}, {2, 4, 6}, {4, 8, 6}};
  for (const auto& f : faces) out << "f " << f[0] << " " << f[1] << " " << f[2] << "\n";
}

// Frames 1..n of a box 2 units tall whose base moves by +0.1 in x per frame.
fs::path WriteMovingBox(const std::string& name, int n) {
  const fs::path dir = test_util::FreshTestDir("captured", name);
  for (int f = 0; f < n; ++f)
    WriteCube(dir / fmt::format("{}.obj", f + 1), Eigen::Vector3f(3 + 0.1f * f, 5, -1),
              Eigen::Vector3f(0.4f, 2.f, 0.2f));
  return dir;
}

TEST(CapturedTest, SourceFramesPingPong) {
  // Length 4: 0 1 2 3 2 1 0 1 ...
  const int expected[] = {0, 1, 2, 3, 2, 1, 0, 1, 2};
  for (int f = 0; f < 9; ++f) EXPECT_EQ(CapturedSourceFrame(0, 1, 4, f), expected[f]) << f;
  EXPECT_EQ(CapturedSourceFrame(2, 2, 4, 1), 2);  // 2 + 2 = 4 -> 2
  EXPECT_EQ(CapturedSourceFrame(0, 1, 1, 5), 0);
}

TEST(CapturedTest, ScaledStoodOnTheFloorAndPlaced) {
  CapturedPerformerOptions o;
  o.source = WriteMovingBox("placed", 6);
  o.stature = 1.6;
  o.position = {0.5, -0.25};
  o.yaw = M_PI / 2;
  const CapturedPerformer p = LoadCapturedPerformer(o, 4);
  ASSERT_EQ(p.source_length, 6);
  const SceneObject first = PoseCapturedPerformer(p, 0, 3);
  EXPECT_EQ(first.instance_id, 3);
  Eigen::Vector3f lo = first.mesh.vertices[0], hi = lo;
  for (const Eigen::Vector3f& v : first.mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  EXPECT_NEAR(lo.y(), 0, 1e-5);    // on the floor
  EXPECT_NEAR(hi.y(), 1.6, 1e-5);  // the stature
  EXPECT_NEAR(0.5f * (lo.x() + hi.x()), 0.5, 1e-5);
  EXPECT_NEAR(0.5f * (lo.z() + hi.z()), -0.25, 1e-5);
  // A quarter turn about +y swaps the footprint's sides: 0.4 x 0.2 units at
  // 0.8 m per unit becomes 0.16 m along x and 0.32 m along z.
  EXPECT_NEAR(hi.x() - lo.x(), 0.16, 1e-5);
  EXPECT_NEAR(hi.z() - lo.z(), 0.32, 1e-5);
  // The source moves +0.1 units in x per frame: 0.08 m along world -z after
  // the quarter turn (x -> -z).
  const SceneObject third = PoseCapturedPerformer(p, 2, 3);
  EXPECT_NEAR(third.mesh.vertices[0].z() - first.mesh.vertices[0].z(), -0.16, 1e-5);
  EXPECT_NEAR(third.mesh.vertices[0].x() - first.mesh.vertices[0].x(), 0, 1e-5);
  // Texture and parts stay those of the first frame.
  EXPECT_EQ(third.mesh.texcoords, first.mesh.texcoords);
  EXPECT_EQ(third.mesh.faces.size(), 12u);
}

TEST(CapturedTest, ClosestApproachIsTheGap) {
  CapturedPerformerOptions o;
  o.source = WriteMovingBox("approach", 3);
  o.stature = 1.7;
  const CapturedPerformer a = LoadCapturedPerformer(o, 3);
  o.position = {2.0, 0.0};
  CapturedPerformer b = LoadCapturedPerformer(o, 3);
  PlaceAtClosestApproach(a, &b, Eigen::Vector2d(1, 0), 0.03, 3, 1);
  // Both boxes move alike, so the gap between their facing sides is constant:
  // b's left side stands 3 cm from a's right side (vertex to vertex).
  for (int f = 0; f < 3; ++f) {
    const SceneObject pa = PoseCapturedPerformer(a, f, 1), pb = PoseCapturedPerformer(b, f, 2);
    double closest = 1e9;
    for (const auto& va : pa.mesh.vertices)
      for (const auto& vb : pb.mesh.vertices) closest = std::min<double>(closest, (va - vb).norm());
    EXPECT_NEAR(closest, 0.03, 1e-5) << "frame " << f;
  }
}

// The realistic preset on the shared captured meshes, small: its ground truth
// against the meshes it wrote (vertex depth against the depth maps, vertex
// motion against the flow).
TEST(CapturedTest, RealisticGroundTruthMatchesTheMeshes) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  SynthOptions o = SynthPreset("realistic");
  o.captured_meshes = data;
  o.num_frames = 3;
  o.rig.num_views = 3;
  o.rig.image_width = 480;
  o.rig.image_height = 270;
  o.seed = 5;
  const fs::path dir = test_util::RemovedAtExit(WriteCaptureToTempDir("captured_gt", o));
  const Capture capture = ReadCapture(dir);
  std::vector<double> depth_errors, flow_errors;
  for (int v = 0; v < capture.NumViews(); ++v) {
    const std::string& view = capture.views[v].name;
    const Camera& camera = capture.views[v].cameras[0];
    for (int f = 0; f + 1 < o.num_frames; ++f) {
      const cv::Mat depth = ReadPfm(dir / layout::GtDepth(view, f));
      const cv::Mat ids = ReadInstanceMask(dir / layout::GtInstances(view, f),
                                           dir / layout::GtInstancesInfo(view, f))
                              .ids;
      const cv::Mat flow = ReadFlo(dir / layout::GtFlow(view, f));
      const cv::Mat valid = ReadMaskImage(dir / layout::GtFlowValid(view, f));
      for (int id = 1; id <= 2; ++id) {
        open3d::geometry::TriangleMesh now, next;
        ASSERT_TRUE(open3d::io::ReadTriangleMesh((dir / layout::GtMesh(id, f)).string(), now));
        ASSERT_TRUE(open3d::io::ReadTriangleMesh((dir / layout::GtMesh(id, f + 1)).string(), next));
        ASSERT_EQ(now.vertices_.size(), next.vertices_.size());
        for (size_t i = 0; i < now.vertices_.size(); i += 7) {
          const Eigen::Vector2d px = camera.Project(now.vertices_[i]);
          if (!px.allFinite() || !camera.InImage(px)) continue;
          const cv::Point p(static_cast<int>(std::lround(px.x())),
                            static_cast<int>(std::lround(px.y())));
          if (ids.at<uint16_t>(p) != id) continue;
          const double z = camera.Depth(now.vertices_[i]);
          if (z > depth.at<float>(p) + 0.03) continue;  // hidden behind another surface
          depth_errors.push_back(std::abs(z - depth.at<float>(p)));
          if (!valid.at<uint8_t>(p)) continue;
          const Eigen::Vector2d moved = camera.Project(next.vertices_[i]) - px;
          const cv::Vec2f g = flow.at<cv::Vec2f>(p);
          flow_errors.push_back((moved - Eigen::Vector2d(g[0], g[1])).norm());
        }
      }
    }
  }
  // A vertex lies within half a pixel (about 1 cm here) of the pixel centre
  // whose depth and flow it is compared with: on a slanted surface, or at a
  // silhouette, the two differ by the surface's change over that distance;
  // a wrong camera, frame or scale would be off by decimetres and pixels.
  ASSERT_GT(depth_errors.size(), 500u);
  ASSERT_GT(flow_errors.size(), 300u);
  std::sort(depth_errors.begin(), depth_errors.end());
  std::sort(flow_errors.begin(), flow_errors.end());
  std::printf("depth error median %.4f m, 90th %.4f m; flow error median %.3f px, 90th %.3f px\n",
              depth_errors[depth_errors.size() / 2], depth_errors[depth_errors.size() * 9 / 10],
              flow_errors[flow_errors.size() / 2], flow_errors[flow_errors.size() * 9 / 10]);
  EXPECT_LT(depth_errors[depth_errors.size() / 2], 0.005);
  EXPECT_LT(depth_errors[depth_errors.size() * 9 / 10], 0.03);
  EXPECT_LT(flow_errors[flow_errors.size() / 2], 0.3);
  EXPECT_LT(flow_errors[flow_errors.size() * 9 / 10], 1.0);

  // The capture holds no 2D keypoints and no GT joints: the performers have
  // no skeleton.
  EXPECT_FALSE(fs::exists(dir / layout::Poses2d(capture.views[0].name, 0)));
  EXPECT_FALSE(fs::exists(dir / layout::GtJoints3d(0)));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace u4d::synth
