// The paper's reconstruction evaluation (Sec. 4, Table "Reconstruction
// evaluation": projection error of the fused surface) for any per-view depth
// maps, so that depth baselines (winner-take-all plane sweep, SGBM) are
// measured through the same fusion as the joint method: per object, the
// views' depth maps restricted to the object's pixels in `instance_ids` are
// fused into a mesh (fusion/depth_fusion.h, FuseObject), the meshes of all
// objects are rendered together (z-buffered, eval/silhouette.h) into every
// view, and per (view, object) |render xor mask| / |mask| is taken against the
// object's mask in `instance_ids`; with a GT mesh for the object, the Chamfer
// distance too (eval/mesh_metrics.h).
//
// Inputs: one entry per view in each vector, all maps of the camera's size:
// depth CV_32FC1 (z metres; 0 or non-finite = unknown), instance ids
// CV_16UC1 (0 = background; the same object has the same id in every view),
// image CV_8UC3. An object whose fusion finds too few points gives no mesh:
// it counts as `empty` and its masks as wholly missed (error 1). Throws
// u4d::Error on vectors of different lengths or maps of the wrong size/type.
#pragma once

#include <map>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/eval/silhouette.h"
#include "u4d/fusion/depth_fusion.h"
#include "u4d/geometry/camera.h"

namespace open3d::geometry {
class TriangleMesh;
}

namespace u4d::eval {

struct FusedReconstruction {
  RatioMean projection_error;  // |render xor mask| / |mask| per (view, object)
  RatioMean chamfer_m;         // per object with a GT mesh (metres)
  int objects = 0;             // objects with a mask in some view
  int empty = 0;               // of those, fused into no mesh
};

FusedReconstruction EvaluateFusedDepth(
    const std::vector<Camera>& cameras, const std::vector<cv::Mat>& depths,
    const std::vector<cv::Mat>& instance_ids, const std::vector<cv::Mat>& images,
    const std::map<int, const open3d::geometry::TriangleMesh*>& gt_meshes = {},
    const FusionOptions& fusion = {});

}  // namespace u4d::eval
