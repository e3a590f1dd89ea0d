#include "u4d/pipeline/mesh_depth.h"

#include <open3d/geometry/TriangleMesh.h>

#include "u4d/eval/silhouette.h"
#include "u4d/util/check.h"

namespace u4d {

int DepthFromMeshes(const std::vector<const open3d::geometry::TriangleMesh*>& meshes,
                    const std::vector<int>& ids, const Camera& camera, const cv::Mat& labels,
                    cv::Mat* depth) {
  U4D_CHECK(depth != nullptr, "DepthFromMeshes: no depth map");
  U4D_CHECK(meshes.size() == ids.size(), "DepthFromMeshes: {} meshes for {} ids", meshes.size(),
            ids.size());
  const cv::Size size(camera.width, camera.height);
  U4D_CHECK(labels.type() == CV_16UC1 && labels.size() == size,
            "DepthFromMeshes: the labels must be CV_16U of the camera's size {}x{}", size.width,
            size.height);
  U4D_CHECK(depth->type() == CV_32FC1 && depth->size() == size,
            "DepthFromMeshes: the depth must be CV_32F of the camera's size {}x{}", size.width,
            size.height);
  std::vector<const open3d::geometry::TriangleMesh*> present;
  std::vector<int> present_ids;
  for (size_t k = 0; k < meshes.size(); ++k) {
    U4D_CHECK(ids[k] >= 1 && ids[k] <= 65535, "DepthFromMeshes: object id {} is not in 1..65535",
              ids[k]);
    if (meshes[k] && !meshes[k]->triangles_.empty())
      present.push_back(meshes[k]), present_ids.push_back(ids[k]);
  }
  if (present.empty()) return 0;
  const eval::Rasterization surface = eval::RasterizeMeshes(present, present_ids, camera);
  int replaced = 0;
  for (int y = 0; y < labels.rows; ++y) {
    const uint16_t* own = labels.ptr<uint16_t>(y);
    const uint16_t* seen = surface.labels.ptr<uint16_t>(y);
    const float* z = surface.depth.ptr<float>(y);
    float* out = depth->ptr<float>(y);
    for (int x = 0; x < labels.cols; ++x)
      if (own[x] != 0 && seen[x] == own[x]) out[x] = z[x], ++replaced;
  }
  return replaced;
}

}  // namespace u4d
