// 4D temporal coherence: moving one mesh through time with the multi-view
// scene flow (paper Sec. 4: "4D temporally coherent meshes are obtained by
// combining the most consistent motion information from all views for each
// 3D point").
//
// TrackVertices moves the vertices of a mesh at frame t (world, metres) to
// frame t+1. For every view and every vertex X:
//   visible  project X with the camera at t to pixel p (inside the image);
//            the object's depth at t at p (bilinear, depth_sampling.h) d0
//            must be known and |z(X) - d0| <= visibility_tolerance + 2
//            depth_sigma_rel z(X) (the depth maps' own error must not hide a
//            vertex), and the instance at t at p must be object_id (when ids
//            are given);
//   moved    q = p + flow(p) (flow t -> t+1, bilinear); the object's depth
//            at t+1 at q, d1, must be known and the instance at t+1 at q
//            must be object_id (otherwise the view gives no candidate);
//   candidate displacement = Unproject_{t+1}(q, d1) - Unproject_t(p, d0),
//            so a vertex slightly off the depth surface keeps its offset.
// The views that agree are those whose candidates lie within
// consistency_tolerance of the most consistent candidate (the one with the
// most others that close; ties: the smaller spread). The displacement is the
// mean of their candidates, refined (refine_iterations > 0) by Gauss-Newton
// on the agreeing views' reprojections: y at t+1 must project to q in each
// (sigma flow_sigma_px) and lie at d1 + (z(X) - d0) along each optical axis
// (sigma depth_sigma_rel * depth). With two or more views the flows
// triangulate the motion, so the per-frame noise of the depth maps (solved
// independently each frame) weighs little where the flows agree. Vertices without a candidate
// (hidden everywhere, or inconsistent flow) are "interpolated": their displacement comes from the
// mesh neighbours by iterative Laplacian diffusion (Jacobi iterations of "mean of the neighbours'
// displacements", tracked vertices fixed, starting from the nearest tracked vertex's displacement
// along the mesh). A connected component without any tracked vertex keeps a zero displacement.
//
// TrackSegment applies TrackVertices frame after frame from a key-frame mesh:
// one topology (triangles, colours, label) moving in time.
//
// Inputs per view: CV_32FC1 depths (z metres, 0 = unknown), CV_32FC2 forward
// flow in pixels, CV_16UC1 instance ids (optional: empty = no instance test),
// each of the size of the camera it belongs to. Mismatches throw u4d::Error
// naming the view and map.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"

namespace open3d::geometry {
class TriangleMesh;
}

namespace u4d {

// One view's data for the step t -> t+1.
struct SceneFlowView {
  Camera camera_t;       // camera at t
  Camera camera_t1;      // camera at t+1 (the same for a static view)
  cv::Mat depth_t;       // CV_32FC1
  cv::Mat depth_t1;      // CV_32FC1
  cv::Mat flow;          // CV_32FC2, t -> t+1, pixels
  cv::Mat instances_t;   // CV_16UC1 or empty
  cv::Mat instances_t1;  // CV_16UC1 or empty
};

struct TrackOptions {
  double visibility_tolerance = 0.03;   // metres between vertex depth and the depth map at t,
                                        // plus 2 depth_sigma_rel of the depth
  double max_depth_jump = 0.05;         // metres; bilinear depth only across smaller steps
  double consistency_tolerance = 0.02;  // metres; candidates this close agree
  int refine_iterations = 3;            // Gauss-Newton steps on the reprojections (0 = off)
  double flow_sigma_px = 0.5;  // expected flow error, pixels (joint flow EPE on people 0.25-0.65)
  double depth_sigma_rel = 0.01;   // expected depth error, fraction of the depth (about half the
                                   // joint depths are within 1 %)
  int diffusion_iterations = 100;  // Jacobi iterations for untracked vertices
  void Check() const;              // throws u4d::Error naming the bad field
};

struct TrackResult {
  std::vector<Eigen::Vector3d> positions;  // at t+1, one per input vertex
  std::vector<uint8_t> tracked;            // 1: from the flow, 0: interpolated
  std::vector<int> candidates;             // views giving a candidate per vertex
  int num_tracked = 0;
  int num_interpolated = 0;
};

TrackResult TrackVertices(const std::vector<Eigen::Vector3d>& vertices,
                          const std::vector<Eigen::Vector3i>& triangles,
                          const std::vector<SceneFlowView>& views, int object_id,
                          const TrackOptions& options);

// A mesh of fixed topology over consecutive frames.
struct AnimatedMesh {
  int object_id = 0;
  int first_frame = 0;     // frame of positions[0]
  std::string class_name;  // the object's class (glTF extras "class"); empty = not known
  std::vector<Eigen::Vector3i> triangles;               // shared by all frames
  std::vector<Eigen::Vector3d> colors;                  // RGB in [0,1] per vertex (or empty)
  std::vector<std::vector<Eigen::Vector3d>> positions;  // per frame, per vertex, world
  std::vector<double> tracked_fraction;                 // per step k -> k+1

  int NumFrames() const { return static_cast<int>(positions.size()); }
  int NumVertices() const { return positions.empty() ? 0 : static_cast<int>(positions[0].size()); }
  // The mesh at frame index k (0-based within the segment) with colours and normals.
  std::shared_ptr<open3d::geometry::TriangleMesh> MeshAt(int k) const;
};

// Moves `keyframe_mesh` (at frame first_frame) through num_steps steps;
// `step_views(k)` returns the views for frame first_frame + k -> + k + 1 (so
// only one step's maps need to be in memory). Throws u4d::Error on an empty
// mesh or when step_views throws.
AnimatedMesh TrackSegment(const open3d::geometry::TriangleMesh& keyframe_mesh, int object_id,
                          int first_frame, int num_steps,
                          const std::function<std::vector<SceneFlowView>(int step)>& step_views,
                          const TrackOptions& options);

}  // namespace u4d
