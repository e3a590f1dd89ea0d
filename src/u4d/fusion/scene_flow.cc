#include "u4d/fusion/scene_flow.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include <open3d/geometry/TriangleMesh.h>

#include "u4d/fusion/depth_sampling.h"
#include "u4d/util/check.h"

namespace u4d {

using fusion_internal::CheckMap;
using fusion_internal::SampleId;
using fusion_internal::SampleObjectDepth;
using fusion_internal::SampleObjectFlow;

void TrackOptions::Check() const {
  U4D_CHECK(visibility_tolerance > 0, "TrackOptions.visibility_tolerance must be > 0, found {}",
            visibility_tolerance);
  U4D_CHECK(max_depth_jump > 0, "TrackOptions.max_depth_jump must be > 0, found {}",
            max_depth_jump);
  U4D_CHECK(consistency_tolerance > 0, "TrackOptions.consistency_tolerance must be > 0, found {}",
            consistency_tolerance);
  U4D_CHECK(refine_iterations >= 0, "TrackOptions.refine_iterations must be >= 0, found {}",
            refine_iterations);
  U4D_CHECK(flow_sigma_px > 0, "TrackOptions.flow_sigma_px must be > 0, found {}", flow_sigma_px);
  U4D_CHECK(depth_sigma_rel > 0, "TrackOptions.depth_sigma_rel must be > 0, found {}",
            depth_sigma_rel);
  U4D_CHECK(diffusion_iterations >= 0, "TrackOptions.diffusion_iterations must be >= 0, found {}",
            diffusion_iterations);
}

namespace {

void CheckView(const SceneFlowView& v, int i) {
  const std::string ctx = fmt::format("TrackVertices: view {}", i);
  v.camera_t.Check(ctx + " camera_t");
  v.camera_t1.Check(ctx + " camera_t1");
  const int w = v.camera_t.width, h = v.camera_t.height;
  CheckMap(v.depth_t, CV_32FC1, w, h, ctx + " depth_t");
  CheckMap(v.flow, CV_32FC2, w, h, ctx + " flow");
  if (!v.instances_t.empty()) CheckMap(v.instances_t, CV_16UC1, w, h, ctx + " instances_t");
  CheckMap(v.depth_t1, CV_32FC1, v.camera_t1.width, v.camera_t1.height, ctx + " depth_t1");
  if (!v.instances_t1.empty())
    CheckMap(v.instances_t1, CV_16UC1, v.camera_t1.width, v.camera_t1.height,
             ctx + " instances_t1");
}

// One view's evidence on where a vertex is at t+1: it projects to `q` and
// lies at depth `z1` there (the depth map at q plus the vertex's offset from
// the surface at t).
struct ViewObservation {
  const Camera* camera_t1 = nullptr;
  Eigen::Vector2d q;
  double z1 = 0;
};

// Index of the most consistent candidate: the one with the most others
// within tol (ties: the smaller spread).
int MostConsistent(const std::vector<Eigen::Vector3d>& c, double tol) {
  int best = -1, best_n = -1;
  double best_spread = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < c.size(); ++i) {
    int n = 0;
    double spread = 0;
    for (size_t j = 0; j < c.size(); ++j) {
      const double d = (c[i] - c[j]).norm();
      if (d <= tol) {
        ++n;
        spread += d;
      }
    }
    if (n > best_n || (n == best_n && spread < best_spread)) {
      best = static_cast<int>(i);
      best_n = n;
      best_spread = spread;
    }
  }
  return best;
}

// Iteratively reweighted Gauss-Newton from y on the sum over views of
// rho(|Project(y) - q|^2 / sigma_px^2 + (Depth(y) - z1)^2 / (sigma_rel z1)^2)
// with Huber's rho (threshold kHuber standard deviations), so a view whose
// flow disagrees with the others loses its weight. Jacobians by central
// differences (the cameras may be distorted).
Eigen::Vector3d RefineByReprojection(Eigen::Vector3d y, const std::vector<ViewObservation>& obs,
                                     const TrackOptions& o) {
  constexpr double kStep = 1e-4;  // metres
  constexpr double kHuber = 2.0;
  const double wp = 1.0 / (o.flow_sigma_px * o.flow_sigma_px);
  for (int it = 0; it < o.refine_iterations; ++it) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const ViewObservation& ob : obs) {
      const Camera& cam = *ob.camera_t1;
      Eigen::Matrix3d J;  // rows: u, v, z
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d a = y, b = y;
        a[k] += kStep;
        b[k] -= kStep;
        J.block<2, 1>(0, k) = (cam.Project(a) - cam.Project(b)) / (2 * kStep);
        J(2, k) = (cam.Depth(a) - cam.Depth(b)) / (2 * kStep);
      }
      Eigen::Vector3d r;
      r.head<2>() = cam.Project(y) - ob.q;
      r[2] = cam.Depth(y) - ob.z1;
      if (!r.allFinite() || !J.allFinite()) continue;
      const double wz = 1.0 / std::pow(o.depth_sigma_rel * ob.z1, 2);
      const double norm = std::sqrt(r.head<2>().squaredNorm() * wp + r[2] * r[2] * wz);
      const double robust = norm <= kHuber ? 1.0 : kHuber / norm;
      const Eigen::Vector3d w = robust * Eigen::Vector3d(wp, wp, wz);
      H += J.transpose() * w.asDiagonal() * J;
      g += J.transpose() * w.asDiagonal() * r;
    }
    const Eigen::Vector3d step = H.ldlt().solve(-g);
    if (!step.allFinite()) break;
    y += step;
    if (step.norm() < 1e-6) break;
  }
  return y;
}

}  // namespace

TrackResult TrackVertices(const std::vector<Eigen::Vector3d>& vertices,
                          const std::vector<Eigen::Vector3i>& triangles,
                          const std::vector<SceneFlowView>& views, int object_id,
                          const TrackOptions& options) {
  options.Check();
  U4D_CHECK(!views.empty(), "TrackVertices: no views given");
  U4D_CHECK(object_id >= 1 && object_id <= 65535,
            "TrackVertices: object_id must be an instance id in [1, 65535], found {}", object_id);
  for (size_t i = 0; i < views.size(); ++i) CheckView(views[i], static_cast<int>(i));
  const int nv = static_cast<int>(vertices.size());
  for (const Eigen::Vector3i& t : triangles)
    for (int k = 0; k < 3; ++k)
      U4D_CHECK(t[k] >= 0 && t[k] < nv, "TrackVertices: triangle index {} out of range [0, {})",
                t[k], nv);

  TrackResult r;
  r.positions = vertices;
  r.tracked.assign(nv, 0);
  r.candidates.assign(nv, 0);
  std::vector<Eigen::Vector3d> disp(nv, Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> cand;
  std::vector<ViewObservation> obs;
  for (int i = 0; i < nv; ++i) {
    const Eigen::Vector3d& x = vertices[i];
    cand.clear();
    obs.clear();
    for (const SceneFlowView& v : views) {
      const Eigen::Vector2d p = v.camera_t.Project(x);
      if (!std::isfinite(p.x()) || !v.camera_t.InImage(p)) continue;
      if (!v.instances_t.empty() && SampleId(v.instances_t, p) != object_id) continue;
      const double d0 =
          SampleObjectDepth(v.depth_t, v.instances_t, object_id, p, options.max_depth_jump);
      const double z = v.camera_t.Depth(x);
      if (d0 <= 0 ||
          std::abs(z - d0) > options.visibility_tolerance + 2 * options.depth_sigma_rel * z)
        continue;
      const Eigen::Vector2d q = p + SampleObjectFlow(v.flow, v.instances_t, object_id, p);
      if (!std::isfinite(q.x()) || !v.camera_t1.InImage(q)) continue;
      if (!v.instances_t1.empty() && SampleId(v.instances_t1, q) != object_id) continue;
      const double d1 =
          SampleObjectDepth(v.depth_t1, v.instances_t1, object_id, q, options.max_depth_jump);
      if (d1 <= 0) continue;
      cand.push_back(v.camera_t1.Unproject(q, d1) - v.camera_t.Unproject(p, d0));
      obs.push_back({&v.camera_t1, q, d1 + z - d0});
    }
    r.candidates[i] = static_cast<int>(cand.size());
    if (cand.empty()) continue;
    // The mean of the candidates that agree with the most consistent one,
    // refined by all the views' reprojections (robustly weighted).
    const int best = MostConsistent(cand, options.consistency_tolerance);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int agree = 0;
    for (const Eigen::Vector3d& c : cand)
      if ((c - cand[best]).norm() <= options.consistency_tolerance) {
        sum += c;
        ++agree;
      }
    disp[i] = sum / static_cast<double>(agree);
    if (options.refine_iterations > 0)
      disp[i] = RefineByReprojection(x + disp[i], obs, options) - x;
    r.tracked[i] = 1;
    ++r.num_tracked;
  }
  r.num_interpolated = nv - r.num_tracked;

  if (r.num_interpolated > 0 && r.num_tracked > 0) {
    std::vector<std::vector<int>> nbr(nv);
    for (const Eigen::Vector3i& t : triangles)
      for (int k = 0; k < 3; ++k) {
        nbr[t[k]].push_back(t[(k + 1) % 3]);
        nbr[t[k]].push_back(t[(k + 2) % 3]);
      }
    for (auto& n : nbr) {
      std::sort(n.begin(), n.end());
      n.erase(std::unique(n.begin(), n.end()), n.end());
    }
    // Start: displacement of the nearest tracked vertex (breadth-first).
    std::vector<uint8_t> known(r.tracked);
    std::deque<int> queue;
    for (int i = 0; i < nv; ++i)
      if (known[i]) queue.push_back(i);
    while (!queue.empty()) {
      const int i = queue.front();
      queue.pop_front();
      for (int j : nbr[i])
        if (!known[j]) {
          known[j] = 1;
          disp[j] = disp[i];
          queue.push_back(j);
        }
    }
    // Jacobi iterations of the Laplacian with the tracked vertices fixed.
    std::vector<Eigen::Vector3d> next = disp;
    for (int it = 0; it < options.diffusion_iterations; ++it) {
      for (int i = 0; i < nv; ++i) {
        if (r.tracked[i] || !known[i] || nbr[i].empty()) continue;
        Eigen::Vector3d s = Eigen::Vector3d::Zero();
        for (int j : nbr[i]) s += disp[j];
        next[i] = s / static_cast<double>(nbr[i].size());
      }
      std::swap(disp, next);
    }
  }
  for (int i = 0; i < nv; ++i) r.positions[i] = vertices[i] + disp[i];
  return r;
}

std::shared_ptr<open3d::geometry::TriangleMesh> AnimatedMesh::MeshAt(int k) const {
  U4D_CHECK(k >= 0 && k < NumFrames(), "AnimatedMesh::MeshAt: frame index {} not in [0, {})", k,
            NumFrames());
  auto m = std::make_shared<open3d::geometry::TriangleMesh>();
  m->vertices_ = positions[k];
  m->triangles_ = triangles;
  m->vertex_colors_ = colors;
  m->ComputeVertexNormals();
  return m;
}

AnimatedMesh TrackSegment(const open3d::geometry::TriangleMesh& keyframe_mesh, int object_id,
                          int first_frame, int num_steps,
                          const std::function<std::vector<SceneFlowView>(int step)>& step_views,
                          const TrackOptions& options) {
  U4D_CHECK(!keyframe_mesh.vertices_.empty() && !keyframe_mesh.triangles_.empty(),
            "TrackSegment: the key-frame mesh of object {} is empty", object_id);
  U4D_CHECK(num_steps >= 0, "TrackSegment: num_steps must be >= 0, found {}", num_steps);
  AnimatedMesh a;
  a.object_id = object_id;
  a.first_frame = first_frame;
  a.triangles = keyframe_mesh.triangles_;
  if (keyframe_mesh.vertex_colors_.size() == keyframe_mesh.vertices_.size())
    a.colors = keyframe_mesh.vertex_colors_;
  a.positions.push_back(keyframe_mesh.vertices_);
  for (int k = 0; k < num_steps; ++k) {
    const TrackResult r =
        TrackVertices(a.positions.back(), a.triangles, step_views(k), object_id, options);
    a.positions.push_back(r.positions);
    a.tracked_fraction.push_back(static_cast<double>(r.num_tracked) /
                                 std::max<size_t>(1, r.positions.size()));
  }
  return a;
}

}  // namespace u4d
