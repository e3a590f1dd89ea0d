// Surface metrics between a reconstructed and a ground-truth mesh.
//
// Both surfaces are sampled uniformly by area (SampleSurface, deterministic
// for a seed) and compared point to nearest point (Open3D's KDTreeFlann):
//   pred_to_gt   mean over predicted samples of the distance to the nearest
//                GT sample (an "accuracy" distance), metres
//   gt_to_pred   mean over GT samples of the distance to the nearest
//                predicted sample (a "completeness" distance), metres
//   chamfer      (pred_to_gt + gt_to_pred) / 2, metres
//   accuracy     share of predicted samples within `threshold` of the GT
//   completeness share of GT samples within `threshold` of the prediction
//   f_score      harmonic mean of accuracy and completeness
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "u4d/util/file.h"

namespace open3d::geometry {
class TriangleMesh;
}

namespace u4d::eval {

struct ChamferOptions {
  int samples = 20000;      // points sampled on each mesh surface
  double threshold = 0.02;  // metres, for accuracy / completeness / F-score
  uint32_t seed = 1;        // sampling seed (results are deterministic)
  void Check() const;
};

struct ChamferResult {
  double pred_to_gt = 0, gt_to_pred = 0, chamfer = 0;
  double accuracy = 0, completeness = 0, f_score = 0;
  nlohmann::json ToJson() const;
};

// Throws u4d::Error when a set is empty or holds a non-finite point.
ChamferResult ChamferDistance(const std::vector<Eigen::Vector3d>& pred,
                              const std::vector<Eigen::Vector3d>& gt, double threshold);

// `n` points uniformly distributed over the surface (triangles chosen with
// probability proportional to area, uniform barycentric inside). Throws when
// the mesh has no triangle of positive area.
std::vector<Eigen::Vector3d> SampleSurface(const open3d::geometry::TriangleMesh& mesh, int n,
                                           uint32_t seed);

ChamferResult MeshChamfer(const open3d::geometry::TriangleMesh& pred,
                          const open3d::geometry::TriangleMesh& gt, const ChamferOptions& options);

// Reads a PLY (or any format Open3D reads) and throws naming the file when it
// is missing, unreadable or has no triangle.
open3d::geometry::TriangleMesh ReadMesh(const fs::path& path);

// Object ids of a meshes/ directory (layout <dir>/<id>/<frame>.ply): the
// names of its subdirectories that are decimal numbers, sorted; empty when
// `dir` does not exist.
std::vector<int> MeshObjectIds(const fs::path& dir);

}  // namespace u4d::eval
