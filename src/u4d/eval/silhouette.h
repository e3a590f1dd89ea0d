// Silhouette metrics of the paper (Section 4): the reconstruction projection
// error and the silhouette overlap error S_e, with the two tools they need:
// a mesh rasteriser and flow-based mask propagation. docs/metrics.md defines
// both metrics precisely and explains where they depart from the paper's text.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"

namespace open3d::geometry {
class TriangleMesh;
}

namespace u4d::eval {

// Rasterises meshes into `camera` with a z-buffer: the label image (CV_16UC1)
// holds labels[k] where mesh k is the nearest surface at the pixel centre, 0
// elsewhere; the depth image (CV_32FC1) holds its z in the camera frame, 0
// elsewhere. Vertices are projected with Camera::Project (distortion applied
// to vertices; edges stay straight in the image). A pixel is covered when its
// centre lies inside or on the edge of a projected triangle. Triangles with a
// vertex behind the camera (z <= 1e-6) are skipped (no near-plane clipping).
// Labels must be in 1..65535 and one per mesh, else u4d::Error.
struct Rasterization {
  cv::Mat labels;
  cv::Mat depth;
};
Rasterization RasterizeMeshes(const std::vector<const open3d::geometry::TriangleMesh*>& meshes,
                              const std::vector<int>& labels, const Camera& camera);

// The silhouette of one mesh as a CV_8UC1 0/255 mask.
cv::Mat RasterizeSilhouette(const open3d::geometry::TriangleMesh& mesh, const Camera& camera);

// Pixel counts of two binary masks (CV_8UC1, non-zero = set).
struct MaskOverlap {
  int64_t pred = 0, gt = 0, intersection = 0, union_ = 0, xor_ = 0;
  // |P xor G| / |G|: the projection error; NaN when |G| = 0.
  double XorOverGt() const;
  // 1 - |P n G| / |P u G|: the silhouette overlap error; NaN when both empty.
  double OneMinusIoU() const;
};
// Throws u4d::Error naming `context` when the masks differ in size or type.
MaskOverlap CompareMasks(const cv::Mat& pred, const cv::Mat& gt, const std::string& context);

struct PropagateOptions {
  // Close the splatted mask with a 3x3 square (fills the one-pixel cracks that
  // forward splatting leaves where the motion stretches the region).
  bool close_cracks = true;
  void Check() const {}
};

// Forward-warps a binary mask of frame t to frame t+1 with the forward flow
// of frame t (CV_32FC2, pixels; docs/conventions.md): every set pixel p with a
// valid flow sets round(p + flow(p)) when that lies in the image; pixels with
// invalid flow (FlowValid) are dropped. Returns CV_8UC1 0/255. Throws naming
// `context` when the sizes or types differ.
cv::Mat PropagateMask(const cv::Mat& mask, const cv::Mat& flow,
                      const PropagateOptions& options = {},
                      const std::string& context = "PropagateMask");

// Mean of a ratio over many images (image-averaged, NaN entries skipped).
struct RatioMean {
  double sum = 0;
  int64_t count = 0;
  void Add(double ratio);  // ignores NaN
  void Add(const RatioMean& o) {
    sum += o.sum;
    count += o.count;
  }
  double Mean() const;  // NaN when empty
};

}  // namespace u4d::eval
