#include "u4d/eval/mesh_metrics.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/TriangleMeshIO.h>

#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

// Mean nearest distance from `from` to `to`, and the share within `threshold`.
std::pair<double, double> Directed(const std::vector<Eigen::Vector3d>& from,
                                   const open3d::geometry::KDTreeFlann& to, double threshold) {
  double sum = 0;
  int64_t within = 0;
  std::vector<int> index(1);
  std::vector<double> dist2(1);
  for (const Eigen::Vector3d& p : from) {
    const int found = to.SearchKNN(p, 1, index, dist2);
    U4D_ASSERT(found == 1);
    const double d = std::sqrt(dist2[0]);
    sum += d;
    if (d <= threshold) ++within;
  }
  return {sum / static_cast<double>(from.size()),
          static_cast<double>(within) / static_cast<double>(from.size())};
}

void CheckPoints(const std::vector<Eigen::Vector3d>& points, const char* which) {
  U4D_CHECK(!points.empty(), "ChamferDistance: the {} point set is empty", which);
  for (const Eigen::Vector3d& p : points)
    U4D_CHECK(p.allFinite(), "ChamferDistance: the {} point set holds a non-finite point", which);
}

}  // namespace

void ChamferOptions::Check() const {
  U4D_CHECK(samples > 0, "ChamferOptions: samples must be positive");
  U4D_CHECK(threshold > 0, "ChamferOptions: threshold must be positive");
}

nlohmann::json ChamferResult::ToJson() const {
  return {{"chamfer_m", chamfer}, {"pred_to_gt_m", pred_to_gt},   {"gt_to_pred_m", gt_to_pred},
          {"accuracy", accuracy}, {"completeness", completeness}, {"f_score", f_score}};
}

ChamferResult ChamferDistance(const std::vector<Eigen::Vector3d>& pred,
                              const std::vector<Eigen::Vector3d>& gt, double threshold) {
  CheckPoints(pred, "predicted");
  CheckPoints(gt, "ground-truth");
  open3d::geometry::PointCloud pred_cloud(pred), gt_cloud(gt);
  const open3d::geometry::KDTreeFlann pred_tree(pred_cloud), gt_tree(gt_cloud);
  ChamferResult r;
  std::tie(r.pred_to_gt, r.accuracy) = Directed(pred, gt_tree, threshold);
  std::tie(r.gt_to_pred, r.completeness) = Directed(gt, pred_tree, threshold);
  r.chamfer = 0.5 * (r.pred_to_gt + r.gt_to_pred);
  r.f_score = r.accuracy + r.completeness > 0
                  ? 2 * r.accuracy * r.completeness / (r.accuracy + r.completeness)
                  : 0.0;
  return r;
}

std::vector<Eigen::Vector3d> SampleSurface(const open3d::geometry::TriangleMesh& mesh, int n,
                                           uint32_t seed) {
  const auto& v = mesh.vertices_;
  std::vector<double> cumulative;
  cumulative.reserve(mesh.triangles_.size());
  double total = 0;
  for (const Eigen::Vector3i& t : mesh.triangles_) {
    for (int k = 0; k < 3; ++k)
      U4D_CHECK(t[k] >= 0 && t[k] < static_cast<int>(v.size()),
                "SampleSurface: a triangle names vertex {} of {}", t[k], v.size());
    const double area = 0.5 * (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).norm();
    U4D_CHECK(std::isfinite(area), "SampleSurface: the mesh holds a non-finite vertex");
    total += area;
    cumulative.push_back(total);
  }
  U4D_CHECK(total > 0, "SampleSurface: the mesh has no triangle of positive area");
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  points.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double r = uniform(rng) * total;
    const size_t k = std::min<size_t>(
        std::upper_bound(cumulative.begin(), cumulative.end(), r) - cumulative.begin(),
        cumulative.size() - 1);
    const Eigen::Vector3i& t = mesh.triangles_[k];
    double a = uniform(rng), b = uniform(rng);
    if (a + b > 1) {  // fold the square onto the triangle
      a = 1 - a;
      b = 1 - b;
    }
    points.push_back(v[t[0]] + a * (v[t[1]] - v[t[0]]) + b * (v[t[2]] - v[t[0]]));
  }
  return points;
}

ChamferResult MeshChamfer(const open3d::geometry::TriangleMesh& pred,
                          const open3d::geometry::TriangleMesh& gt, const ChamferOptions& options) {
  options.Check();
  return ChamferDistance(SampleSurface(pred, options.samples, options.seed),
                         SampleSurface(gt, options.samples, options.seed), options.threshold);
}

open3d::geometry::TriangleMesh ReadMesh(const fs::path& path) {
  CheckFileExists(path, "mesh");
  open3d::geometry::TriangleMesh mesh;
  open3d::io::ReadTriangleMeshOptions options;
  options.print_progress = false;
  U4D_CHECK(open3d::io::ReadTriangleMesh(path.string(), mesh, options),
            "{}: cannot read the mesh (corrupt or unsupported format)", path.string());
  U4D_CHECK(!mesh.triangles_.empty(), "{}: the mesh has no triangle", path.string());
  return mesh;
}

std::vector<int> MeshObjectIds(const fs::path& dir) {
  std::vector<int> ids;
  if (!fs::is_directory(dir)) return ids;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (const auto id = ParseIndexName(name); entry.is_directory() && id) ids.push_back(*id);
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

}  // namespace u4d::eval
