// Closing trimmed holes (hole_fill.h) on a sphere with caps cut off, whose
// true surface is known: the patch must close the hole, follow the border's
// shape and be oriented as the rest.
#include "u4d/fusion/hole_fill.h"

#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>

#include "u4d/util/check.h"

namespace u4d {
namespace {

constexpr double kRadius = 0.5;

// A unit-density sphere of radius kRadius with the caps above `top` and
// below `bottom` (z) cut off: two holes of radius sqrt(R^2 - z^2).
std::shared_ptr<open3d::geometry::TriangleMesh> CutSphere(double top, double bottom) {
  auto sphere = open3d::geometry::TriangleMesh::CreateSphere(kRadius, 40);
  std::vector<bool> remove(sphere->vertices_.size());
  for (size_t i = 0; i < remove.size(); ++i)
    remove[i] = sphere->vertices_[i].z() > top || sphere->vertices_[i].z() < bottom;
  sphere->RemoveVerticesByMask(remove);
  return sphere;
}

int BoundaryEdges(const open3d::geometry::TriangleMesh& mesh) {
  return static_cast<int>(mesh.GetNonManifoldEdges(/*allow_boundary_edges=*/false).size());
}

TEST(HoleFill, ACutCapIsClosedFlatAndOrientedAsTheSphere) {
  auto mesh = CutSphere(0.4, -1.0);  // one hole of radius 0.3 in the plane z = 0.4
  const size_t old_vertices = mesh->vertices_.size(), old_triangles = mesh->triangles_.size();
  ASSERT_GT(BoundaryEdges(*mesh), 0);
  EXPECT_EQ(FillHoles(0.35, mesh.get()), 1);
  EXPECT_EQ(BoundaryEdges(*mesh), 0);
  EXPECT_TRUE(mesh->IsWatertight());
  EXPECT_TRUE(mesh->IsOrientable());
  // The border is flat, so the patch is the disc it bounds: in its plane and
  // of its area, facing out of the sphere as the sphere's own triangles do.
  double area = 0;
  for (size_t t = old_triangles; t < mesh->triangles_.size(); ++t) {
    const Eigen::Vector3i& tri = mesh->triangles_[t];
    const Eigen::Vector3d a = mesh->vertices_[tri[0]], b = mesh->vertices_[tri[1]],
                          c = mesh->vertices_[tri[2]];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    area += 0.5 * n.norm();
    EXPECT_GE(n.z(), 0) << "patch triangle " << t << " faces into the sphere";
  }
  // The border is the sphere's last ring at or below the cut.
  const double border_z = mesh->vertices_[old_vertices].z();
  EXPECT_GT(border_z, 0.35);
  EXPECT_LE(border_z, 0.4);
  for (size_t v = old_vertices; v < mesh->vertices_.size(); ++v)
    EXPECT_NEAR(mesh->vertices_[v].z(), border_z, 1e-9) << "vertex " << v;
  const double disc = M_PI * (kRadius * kRadius - border_z * border_z);
  EXPECT_NEAR(area, disc, 0.02 * disc);
}

TEST(HoleFill, HolesWiderThanTheRadiusStayOpen) {
  auto mesh = CutSphere(0.45, -0.3);  // a hole of radius ~0.22 above, ~0.4 below
  const int before = BoundaryEdges(*mesh);
  EXPECT_EQ(FillHoles(0.3, mesh.get()), 1);  // the small one
  const int after = BoundaryEdges(*mesh);
  EXPECT_GT(after, 0);
  EXPECT_LT(after, before);
  EXPECT_EQ(FillHoles(0.5, mesh.get()), 1);  // now the large one
  EXPECT_EQ(BoundaryEdges(*mesh), 0);
  auto closed = open3d::geometry::TriangleMesh::CreateSphere(kRadius, 40);
  EXPECT_EQ(FillHoles(1.0, closed.get()), 0);  // nothing to close
}

TEST(HoleFill, ZeroRadiusClosesNothingAndBadInputThrows) {
  auto mesh = CutSphere(0.4, -1.0);
  const size_t triangles = mesh->triangles_.size();
  EXPECT_EQ(FillHoles(0.0, mesh.get()), 0);
  EXPECT_EQ(mesh->triangles_.size(), triangles);
  EXPECT_THROW(FillHoles(-1.0, mesh.get()), Error);
  EXPECT_THROW(FillHoles(std::nan(""), mesh.get()), Error);
  EXPECT_THROW(FillHoles(1.0, nullptr), Error);
  open3d::geometry::TriangleMesh empty;
  EXPECT_EQ(FillHoles(1.0, &empty), 0);
}

}  // namespace
}  // namespace u4d
