#include "u4d/eval/segment_drift.h"

#include <limits>
#include <map>
#include <utility>
#include <vector>

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

#include "u4d/eval/mesh_metrics.h"
#include "u4d/fusion/gltf.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"
#include "u4d/util/stats.h"

namespace u4d::eval {

void DriftOptions::Check() const {
  U4D_CHECK(max_match_distance > 0, "DriftOptions.max_match_distance must be > 0, found {}",
            max_match_distance);
}

namespace {

// Nearest-vertex matches of `points` into `gt` and their distances.
void NearestVertices(const std::vector<Eigen::Vector3d>& points,
                     const open3d::geometry::TriangleMesh& gt, std::vector<int>* match,
                     std::vector<double>* dist) {
  open3d::geometry::PointCloud cloud;
  cloud.points_ = gt.vertices_;
  const open3d::geometry::KDTreeFlann tree(cloud);
  std::vector<int> idx(1);
  std::vector<double> d2(1);
  match->assign(points.size(), -1);
  dist->assign(points.size(), std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < points.size(); ++i)
    if (tree.SearchKNN(points[i], 1, idx, d2) > 0) {
      (*match)[i] = idx[0];
      (*dist)[i] = std::sqrt(d2[0]);
    }
}

SegmentDrift Evaluate(const AnimatedMesh& seg, const fs::path& capture_root,
                      const std::vector<int>& gt_ids, const DriftOptions& options) {
  SegmentDrift out;
  out.object_id = seg.object_id;
  out.first_frame = seg.first_frame;
  out.vertices = seg.NumVertices();
  // Match to the GT person with the smallest median vertex distance.
  double best = std::numeric_limits<double>::infinity();
  std::vector<int> match;
  std::vector<double> d0;            // distance of each vertex to its match
  std::vector<Eigen::Vector3d> gt0;  // vertices of the matched GT mesh, first frame
  for (int id : gt_ids) {
    const fs::path path = capture_root / layout::GtMesh(id, seg.first_frame);
    if (!fs::exists(path)) continue;
    open3d::geometry::TriangleMesh m = ReadMesh(path);
    std::vector<int> mi;
    std::vector<double> d;
    NearestVertices(seg.positions[0], m, &mi, &d);
    const double med = Median(d);
    if (med < best) {
      best = med;
      out.gt_id = id;
      match = std::move(mi);
      d0 = std::move(d);
      gt0 = std::move(m.vertices_);  // TriangleMesh itself has no move assignment
    }
  }
  if (out.gt_id == 0) return out;
  std::vector<int> followed;
  for (int i = 0; i < out.vertices; ++i)
    if (d0[i] <= options.max_match_distance) followed.push_back(i);
  out.followed = static_cast<int>(followed.size());
  if (followed.empty()) return out;
  out.median_drift.push_back(0);
  out.median_motion.push_back(0);
  for (int k = 1; k < seg.NumFrames(); ++k) {
    const fs::path path = capture_root / layout::GtMesh(out.gt_id, seg.first_frame + k);
    U4D_CHECK(fs::exists(path), "vertex drift: {} is missing (segment of object {} from frame {})",
              path.string(), seg.object_id, seg.first_frame);
    const open3d::geometry::TriangleMesh gtk = ReadMesh(path);
    U4D_CHECK(gtk.vertices_.size() == gt0.size(),
              "vertex drift: {} has {} vertices, frame {} had {}: GT vertex identities differ",
              path.string(), gtk.vertices_.size(), seg.first_frame, gt0.size());
    std::vector<double> drift, motion;
    for (int i : followed) {
      const int m = match[i];
      const Eigen::Vector3d expected = gtk.vertices_[m] + (seg.positions[0][i] - gt0[m]);
      drift.push_back((seg.positions[k][i] - expected).norm());
      motion.push_back((gtk.vertices_[m] - gt0[m]).norm());
    }
    out.median_drift.push_back(Median(drift));
    out.median_motion.push_back(Median(motion));
  }
  return out;
}

}  // namespace

DriftReport EvaluateSegmentDrift(const fs::path& capture_root, const fs::path& scene_dir,
                                 const DriftOptions& options) {
  options.Check();
  const SceneIndex index = ReadSceneIndex(scene_dir);
  const std::vector<int> gt_ids = MeshObjectIds(capture_root / "gt/meshes");
  DriftReport report;
  for (const SceneSegmentInfo& s : index.segments)
    for (const auto& [id, rel] : s.glb) {
      const AnimatedMesh seg = ReadSegmentGlb(scene_dir / rel);
      SegmentDrift d = Evaluate(seg, capture_root, gt_ids, options);
      d.segment = s.index;
      const int n = static_cast<int>(d.median_drift.size());
      if (n >= 2) {
        report.last_frame_drift.Add(d.median_drift.back());
        report.last_frame_motion.Add(d.median_motion.back());
        if (static_cast<int>(report.drift_at.size()) < n - 1) {
          report.drift_at.resize(n - 1);
          report.motion_at.resize(n - 1);
        }
        for (int k = 1; k < n; ++k) {
          report.drift_at[k - 1].Add(d.median_drift[k]);
          report.motion_at[k - 1].Add(d.median_motion[k]);
        }
      }
      report.segments.push_back(std::move(d));
    }
  return report;
}

nlohmann::json DriftReport::ToJson() const {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json j;
  j["last_frame_drift_m"] = num(last_frame_drift.Mean());
  j["last_frame_motion_m"] = num(last_frame_motion.Mean());
  j["segments_measured"] = last_frame_drift.count;
  nlohmann::json by_k = nlohmann::json::array();
  for (size_t k = 0; k < drift_at.size(); ++k)
    by_k.push_back({{"frames_after_first", k + 1},
                    {"drift_m", num(drift_at[k].Mean())},
                    {"motion_m", num(motion_at[k].Mean())},
                    {"segments", drift_at[k].count}});
  j["by_frame_offset"] = by_k;
  nlohmann::json segs = nlohmann::json::array();
  for (const SegmentDrift& s : segments)
    segs.push_back({{"segment", s.segment},
                    {"object_id", s.object_id},
                    {"gt_id", s.gt_id},
                    {"first_frame", s.first_frame},
                    {"vertices", s.vertices},
                    {"followed", s.followed},
                    {"median_drift_m", s.median_drift},
                    {"median_motion_m", s.median_motion}});
  j["segments"] = segs;
  return j;
}

}  // namespace u4d::eval
