// Trimming a fused surface by the object's silhouettes (docs/fusion.md,
// "Trimming"): the visual-hull test of the paper's fusion step ("combined
// across views", Sec. 4), applied to the vertices of the Poisson surface.
//
// Screened Poisson returns a closed surface; where the depth maps hold no
// point (a limb seen obliquely, the top of the head, a gap between the views'
// depths) it bridges the gap. That bridge is right where it stays inside the
// object's silhouettes and wrong (a balloon) where it leaves them. So a
// vertex is removed when the views say it is not the object. A view says
// "off" when the vertex, projected into it, falls farther than `margin_px`
// from every pixel of the object's mask and no nearer surface hides it there
// (the pixel's object, of another id, is not in front of it by more than
// `occlusion_tolerance`); it says "on" when the vertex falls within the
// margin. Where no depth point is near (Poisson's bridge over a gap, the
// trim's target), the vertex is removed when at least `min_views` views say
// off. Where one is (within `support_factor` median point spacings: the
// views' depth holds the surface there), it is removed only when, besides,
// more views say off than on: estimated masks miss a limb in a view or two
// (most often where one person crosses another) while the other views'
// depth and masks hold it, and two views off would cut it from the mesh.
//
// A view gives no evidence where the vertex projects outside the image or
// behind the camera, or where the object has no pixel at all (a detector's
// miss). Inputs as for FuseObject (depth_fusion.h): one camera, depth map
// (CV_32FC1, 0 = unknown; empty: no occluder is known) and instance-id map
// (CV_16UC1) per view, of the camera's size; other lengths, sizes or types
// throw u4d::Error naming the view and map.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"

namespace u4d {

struct SilhouetteTrimOptions {
  int min_views = 2;                  // views that must see the vertex outside (0 = off)
  double margin_px = 1.5;             // within this of the mask (pixels) counts as inside
  double occlusion_tolerance = 0.04;  // metres; a nearer other object by more hides the vertex
  // A vertex this many median point spacings from a depth point is on the
  // observed surface: the views vote (above). Twice: the spacing is the
  // points' median distance to their nearest neighbour, and a noisy depth
  // scatters them about the surface Poisson passes through.
  double support_factor = 2.0;

  void Check() const;  // throws u4d::Error naming the bad field
};

// For every vertex, whether at least `options.min_views` views see it
// outside the silhouette of `object_id` and, where `supported` (a depth
// point within support_factor spacings, per vertex; empty = none), more
// views see it off than on (false for all when min_views is 0). Throws
// u4d::Error when `supported` is neither empty nor one per vertex.
std::vector<bool> OutsideSilhouettes(const std::vector<Eigen::Vector3d>& vertices,
                                     const std::vector<bool>& supported,
                                     const std::vector<Camera>& cameras,
                                     const std::vector<cv::Mat>& depths,
                                     const std::vector<cv::Mat>& instance_ids, int object_id,
                                     const SilhouetteTrimOptions& options);

}  // namespace u4d
