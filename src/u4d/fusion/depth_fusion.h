// Per-object surface fusion of per-view depth maps (paper Sec. 4, "4D scene
// understanding": "The depth information is combined across views using
// Poisson surface reconstruction [Kazhdan 2006] to obtain a mesh for each
// object in the scene").
//
// Inputs, one entry per view and all of the same length: the view's camera
// (u4d::Camera, cam_from_world), its depth map (CV_32FC1, z in metres in the
// camera frame, 0 = unknown), its instance-id map (CV_16UC1, 0 = background,
// ids >= 1 the same object in every view) and its image (CV_8UC3 BGR, or
// empty for a grey mesh). Every map has the camera's size.
//
// Method (docs/fusion.md):
//  1. Oriented points: every pixel of `object_id` with a known depth is
//     back-projected to world. Its normal is the cross product of the
//     depth-map tangents (central differences of the back-projected
//     neighbours, one-sided at the object's border; neighbours of another
//     object or across a depth jump > max_depth_jump are not used) and is
//     oriented towards the camera. Colour is the pixel's.
//  2. Confidence per point = cos(angle between normal and viewing ray) x
//     agreement, with agreement = agree / (agree + conflict) over the other
//     views that see the spot: projected there, the object's depth (bilinear,
//     depth_sampling.h) is within `consistency_tolerance` (agree) or farther
//     than the point by more than it, i.e. the point would float in front of
//     the surface that view sees (conflict). A spot hidden behind a nearer
//     surface in the other view is no evidence. Unseen elsewhere: 0.5.
//  3. Optional consistency filter: a point needs >= min_agreeing_views
//     agreeing views, and points viewed at more than max_view_angle_deg or
//     with confidence < min_confidence are dropped.
//  4. Open3D screened Poisson (CreateFromPointCloudPoisson, octree depth
//     poisson_depth); colours are interpolated from the points.
//  5. Trimming: vertices whose Poisson density is below the
//     density_quantile quantile, vertices farther from the nearest point
//     than trim_distance_factor x the median point spacing (0 = off), and
//     vertices the views see outside the object's silhouette
//     (silhouette_trim.h) are removed; then connected components with fewer
//     than min_component_fraction of the triangles.
//  6. Holes the trims left, up to fill_hole_radius, are closed by smooth
//     membranes over their borders (hole_fill.h).
//
// Output: a mesh in world coordinates (metres) with per-vertex colour (RGB in
// [0,1]) and normals. Failure modes: size/type mismatches and bad options
// throw u4d::Error naming the view and map; an object with fewer than
// min_points oriented points (e.g. absent from every view) gives an EMPTY
// result (mesh with no triangle, num_points as found), not an error.
#pragma once

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/fusion/silhouette_trim.h"
#include "u4d/geometry/camera.h"

namespace open3d::geometry {
class TriangleMesh;
}

namespace u4d {

struct FusionOptions {
  int pixel_step = 1;                   // use every pixel_step-th row and column
  double max_depth_jump = 0.05;         // metres; larger neighbour differences are edges
  double max_view_angle_deg = 80.0;     // drop points seen more obliquely than this
  bool consistency_filter = true;       // drop points no other view confirms
  int min_agreeing_views = 1;           // with the filter: other views that must agree
  double consistency_tolerance = 0.04;  // metres counted as agreement (> the maps' own error)
  double min_confidence = 0.0;          // drop points with a lower confidence (in [0, 1])
  int min_points = 100;                 // fewer oriented points: empty result
  // Octree depth of the Poisson reconstruction. 7 takes about half the time
  // (Open3D's surface extraction starts a thread per octree slice) for a
  // quarter of the vertices and a slightly higher projection error
  // (docs/fusion.md, "Octree depth"): a speed setting
  // (`u4d run --poisson-depth 7`), not the default.
  int poisson_depth = 8;
  double poisson_scale = 1.1;  // Poisson bounding-cube scale over the points
  int poisson_threads = 1;     // Open3D Poisson threads (-1 = all; 1 is deterministic)
  // Trimming where the depth is merely sparse (low Poisson density, a few
  // point spacings from every point) tears holes into the surface that the
  // silhouettes keep. So the density trim is off, and the distance trim only
  // catches what lies far from every point: balloons the views give no
  // evidence on (an object missing from most views' masks, few views), which
  // `silhouette` cannot judge (docs/fusion.md).
  double density_quantile = 0.0;      // trim vertices below this density quantile (0 = off)
  double trim_distance_factor = 6.0;  // trim vertices farther than this x point spacing (0 = off)
  double min_component_fraction = 0.02;  // drop components with fewer triangles (share)
  SilhouetteTrimOptions silhouette;      // trim what the views' masks say is not the object
  // The trims leave holes; those up to a body part's cross-section (a head
  // about 0.1 m, a torso about 0.15 m in radius) are closed (hole_fill.h).
  // A wider border runs between parts (the inner sides of two legs whose
  // bridge was trimmed): a membrane there would put the bridge back.
  double fill_hole_radius = 0.15;  // metres; close holes whose border is this close to its centre
  // The pipeline's written depth maps take the fused surface's depth where
  // it covers the object's own pixels (pipeline/mesh_depth.h): the depth all
  // views agree on replaces the view's own, which errs in patches.
  bool depth_from_meshes = true;

  void Check() const;  // throws u4d::Error naming the bad field
};

struct FusedMesh {
  std::shared_ptr<open3d::geometry::TriangleMesh> mesh;  // world, colours, normals
  int object_id = 0;
  int num_points = 0;          // oriented points found (before the filter)
  int num_points_used = 0;     // given to Poisson (after filter and angle limit)
  double mean_confidence = 0;  // over the points used
  double point_spacing = 0;    // median nearest-neighbour distance of the points, metres
  int vertices_trimmed = 0;    // removed by density, distance and small components
  int holes_filled = 0;        // trimmed holes closed (hole_fill.h)
  bool Empty() const;          // no mesh or no triangle
};

// One oriented, coloured point of an object (step 1-2 above).
struct OrientedPoint {
  Eigen::Vector3d position;  // world, metres
  Eigen::Vector3d normal;    // unit, towards the camera that saw it
  Eigen::Vector3d color;     // RGB in [0, 1]
  double confidence = 0;     // cos(view angle) x agreement, in [0, 1]
  int view = -1;             // the view the pixel is from
  int agreeing_views = 0;    // other views within consistency_tolerance
};

// Steps 1-3: the oriented points of `object_id` (after the filter when enabled).
std::vector<OrientedPoint> ObjectPoints(const std::vector<Camera>& cameras,
                                        const std::vector<cv::Mat>& depths,
                                        const std::vector<cv::Mat>& instance_ids,
                                        const std::vector<cv::Mat>& images, int object_id,
                                        const FusionOptions& options, int* num_found = nullptr);

// Steps 1-5.
FusedMesh FuseObject(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& depths,
                     const std::vector<cv::Mat>& instance_ids, const std::vector<cv::Mat>& images,
                     int object_id, const FusionOptions& options);

}  // namespace u4d
