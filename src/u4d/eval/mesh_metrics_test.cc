#include "u4d/eval/mesh_metrics.h"

#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>

#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

TEST(Chamfer, UnitOffsetPointSets) {
  // A grid with 5 m spacing and the same grid moved by 1 m: every nearest
  // neighbour is the moved copy, at distance exactly 1.
  std::vector<Eigen::Vector3d> gt, pred;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 3; ++j) {
      gt.emplace_back(5.0 * i, 5.0 * j, 0);
      pred.push_back(gt.back() + Eigen::Vector3d(1, 0, 0));
    }
  ChamferResult r = ChamferDistance(pred, gt, 0.5);
  EXPECT_NEAR(r.chamfer, 1.0, 1e-12);
  EXPECT_NEAR(r.pred_to_gt, 1.0, 1e-12);
  EXPECT_NEAR(r.gt_to_pred, 1.0, 1e-12);
  EXPECT_EQ(r.accuracy, 0.0);
  r = ChamferDistance(pred, gt, 1.5);
  EXPECT_EQ(r.accuracy, 1.0);
  EXPECT_EQ(r.completeness, 1.0);
  EXPECT_EQ(r.f_score, 1.0);
  // Asymmetric: an extra predicted point 10 m away raises only pred_to_gt.
  pred.emplace_back(100, 0, 0);
  r = ChamferDistance(pred, gt, 1.5);
  EXPECT_NEAR(r.gt_to_pred, 1.0, 1e-12);
  EXPECT_NEAR(r.pred_to_gt, (12.0 + 85.0) / 13.0, 1e-12);
  EXPECT_THROW(ChamferDistance({}, gt, 1), Error);
}

TEST(Chamfer, SamplingAndMeshes) {
  open3d::geometry::TriangleMesh square;
  square.vertices_ = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  square.triangles_ = {{0, 1, 2}, {0, 2, 3}};
  const auto points = SampleSurface(square, 20000, 3);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    ASSERT_TRUE(p.x() >= 0 && p.x() <= 1 && p.y() >= 0 && p.y() <= 1 && p.z() == 0);
    mean += p / static_cast<double>(points.size());
  }
  EXPECT_NEAR(mean.x(), 0.5, 0.01);
  EXPECT_NEAR(mean.y(), 0.5, 0.01);
  // A mesh against itself is exactly 0 (same seed); lifted by 0.3 m, about 0.3.
  EXPECT_EQ(MeshChamfer(square, square, {}).chamfer, 0.0);
  open3d::geometry::TriangleMesh lifted = square;
  for (auto& v : lifted.vertices_) v.z() += 0.3;
  const ChamferResult r = MeshChamfer(lifted, square, {});
  EXPECT_NEAR(r.chamfer, 0.3, 0.01);
  EXPECT_EQ(r.accuracy, 0.0);
  open3d::geometry::TriangleMesh empty;
  EXPECT_THROW(SampleSurface(empty, 10, 0), Error);
  EXPECT_THROW(ReadMesh("/nonexistent/mesh.ply"), Error);
}

}  // namespace
}  // namespace u4d::eval
