// The fused surfaces back into the views' depth maps, so that depth and
// meshes agree (the paper, Sec. 4 "4D scene understanding": the final model
// "fuses the semantic instance segmentation, depth information and dense
// flow across views"). Each view's depth map comes from its own
// solve, a label field with a smoothness term, so it errs in patches (a
// wrong depth label over a weak texture) and the patches differ between
// views. The per-object Poisson surface (fusion/depth_fusion.h) is a
// least-squares fit to every view's points at once, filtered by their
// cross-view agreement and trimmed by the silhouettes, so where it covers
// an object's pixel in a view it is the depth all views agree on.
//
// Per view, the fused meshes are rasterised into the camera with a z-buffer
// (eval/silhouette.h RasterizeMeshes, the meshes occluding each other); an
// object pixel (labels > 0) whose nearest surface is its own object's mesh
// takes that surface's depth. Elsewhere the depth stays: the background, a
// pixel no mesh covers (a part the fusion trimmed or could not fuse), and
// one where another object's mesh is in front (the masks and the meshes
// disagree on who is seen there; the view's own depth is its best guess).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"

namespace open3d::geometry {
class TriangleMesh;
}

namespace u4d {

// Replaces the depth of `labels`' object pixels in `depth` (CV_32F, z in
// metres in `camera`'s frame, the labels' size) by the depth of the mesh of
// their own id where that mesh is the nearest surface at the pixel centre.
// `meshes[k]` is object `ids[k]`'s fused surface (world, metres; null or
// empty meshes are skipped). Returns the number of pixels replaced. Throws
// u4d::Error when the sizes or types do not match the camera, `meshes` and
// `ids` differ in length, or an id is outside 1..65535.
int DepthFromMeshes(const std::vector<const open3d::geometry::TriangleMesh*>& meshes,
                    const std::vector<int>& ids, const Camera& camera, const cv::Mat& labels,
                    cv::Mat* depth);

}  // namespace u4d
