#include "u4d/eval/fused_reconstruction.h"

#include <cmath>
#include <set>

#include <fmt/format.h>
#include <open3d/geometry/TriangleMesh.h>

#include "u4d/eval/mesh_metrics.h"
#include "u4d/io/label_ids.h"
#include "u4d/util/check.h"

namespace u4d::eval {

FusedReconstruction EvaluateFusedDepth(
    const std::vector<Camera>& cameras, const std::vector<cv::Mat>& depths,
    const std::vector<cv::Mat>& instance_ids, const std::vector<cv::Mat>& images,
    const std::map<int, const open3d::geometry::TriangleMesh*>& gt_meshes,
    const FusionOptions& fusion) {
  const size_t n = cameras.size();
  U4D_CHECK(depths.size() == n && instance_ids.size() == n && images.size() == n,
            "EvaluateFusedDepth: {} cameras but {} depth maps, {} id maps, {} images", n,
            depths.size(), instance_ids.size(), images.size());
  std::vector<cv::Mat> clean(n);
  std::set<int> ids;
  for (size_t v = 0; v < n; ++v) {
    const cv::Size size(cameras[v].width, cameras[v].height);
    U4D_CHECK(instance_ids[v].type() == CV_16UC1 && instance_ids[v].size() == size,
              "EvaluateFusedDepth: view {}: instance ids must be CV_16UC1 {}x{}", v, size.width,
              size.height);
    U4D_CHECK(depths[v].type() == CV_32FC1 && depths[v].size() == size,
              "EvaluateFusedDepth: view {}: depth must be CV_32FC1 {}x{}", v, size.width,
              size.height);
    clean[v] = depths[v].clone();
    clean[v].forEach<float>([](float& z, const int*) {
      if (!std::isfinite(z) || z < 0) z = 0;
    });
    ids.merge(IdsIn(instance_ids[v]));
  }
  FusedReconstruction r;
  std::vector<FusedMesh> fused;
  std::vector<const open3d::geometry::TriangleMesh*> meshes;
  std::vector<int> labels;
  for (int id : ids) {
    ++r.objects;
    fused.push_back(FuseObject(cameras, clean, instance_ids, images, id, fusion));
    const FusedMesh& fm = fused.back();
    if (fm.Empty()) {
      ++r.empty;
      continue;
    }
    meshes.push_back(fm.mesh.get());
    labels.push_back(id);
    if (const auto it = gt_meshes.find(id); it != gt_meshes.end() && it->second != nullptr)
      r.chamfer_m.Add(MeshChamfer(*fm.mesh, *it->second, {}).chamfer);
  }
  for (size_t v = 0; v < n; ++v) {
    const cv::Mat rendered = meshes.empty() ? cv::Mat::zeros(instance_ids[v].size(), CV_16UC1)
                                            : RasterizeMeshes(meshes, labels, cameras[v]).labels;
    for (int id : ids) {
      const cv::Mat mask = instance_ids[v] == id;
      if (cv::countNonZero(mask) == 0) continue;
      r.projection_error.Add(
          CompareMasks(rendered == id, mask, fmt::format("view {} object {}", v, id)).XorOverGt());
    }
  }
  return r;
}

}  // namespace u4d::eval
