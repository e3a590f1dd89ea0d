#include "u4d/eval/scene_consistency.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <open3d/geometry/TriangleMesh.h>
#include <opencv2/imgproc.hpp>

#include "u4d/eval/mesh_metrics.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/scene_index.h"
#include "u4d/util/check.h"

namespace u4d::eval {

void ConsistencyOptions::Check() const {
  U4D_CHECK(depth_tolerance > 0 && depth_tolerance < 1,
            "ConsistencyOptions.depth_tolerance must be in (0, 1), found {}", depth_tolerance);
  U4D_CHECK(pixel_step >= 1, "ConsistencyOptions.pixel_step must be >= 1, found {}", pixel_step);
  propagate.Check();
}

double CrossViewCounts::DepthAgreement() const {
  const int64_t n = agree + conflict;
  return n > 0 ? static_cast<double>(agree) / n : std::numeric_limits<double>::quiet_NaN();
}

double CrossViewCounts::LabelAgreement() const {
  return agree > 0 ? static_cast<double>(label_agree) / agree
                   : std::numeric_limits<double>::quiet_NaN();
}

namespace {

struct Scene {
  const Capture& capture;
  fs::path dir;
  SceneIndex index;

  const Camera& CameraOf(int view, int frame) const { return capture.views[view].CameraAt(frame); }
  cv::Mat Ids(int view, int frame) const {
    const std::string& name = capture.views[view].name;
    const fs::path png = dir / layout::SceneInstances(name, frame);
    const InstanceMask m = ReadInstanceMask(png, dir / layout::SceneInstancesInfo(name, frame));
    CheckSize(m.ids, view, frame, png);
    return m.ids;
  }
  cv::Mat Depth(int view, int frame) const {
    const fs::path path = dir / layout::SceneDepth(capture.views[view].name, frame);
    cv::Mat d = ReadPfm(path);
    U4D_CHECK(d.type() == CV_32FC1, "{}: expected a one-channel depth map", path.string());
    CheckSize(d, view, frame, path);
    return d;
  }
  cv::Mat Flow(int view, int frame) const {
    const fs::path path = dir / layout::SceneFlow(capture.views[view].name, frame);
    cv::Mat f = ReadFlo(path);
    CheckSize(f, view, frame, path);
    return f;
  }
  void CheckSize(const cv::Mat& m, int view, int frame, const fs::path& path) const {
    const Camera& cam = CameraOf(view, frame);
    CheckImageSize(m, cam.width, cam.height, path.string());
  }
};

// Propagates each instance of `first_ids` through `flows` and adds 1 - IoU
// against `ids[k]` at every later frame k.
void AddPropagation(const cv::Mat& first_ids, const std::vector<cv::Mat>& flows,
                    const std::vector<cv::Mat>& ids, const PropagateOptions& options,
                    const std::string& context, RatioMean* se) {
  double lo = 0, hi = 0;
  cv::minMaxLoc(first_ids, &lo, &hi);
  for (int id = 1; id <= static_cast<int>(hi); ++id) {
    cv::Mat mask = first_ids == id;
    if (cv::countNonZero(mask) == 0) continue;
    for (size_t k = 0; k < flows.size(); ++k) {
      mask = PropagateMask(mask, flows[k], options, context);
      se->Add(CompareMasks(mask, ids[k + 1] == id, context).OneMinusIoU());
    }
  }
}

void SilhouetteOverlap(const Scene& s, const ConsistencyOptions& o, FrameReader* reader,
                       ConsistencyReport* r) {
  const std::vector<int>& frames = s.index.frames;
  for (const SceneSegmentInfo& seg : s.index.segments) {
    if (seg.last <= seg.first) continue;
    for (int v = 0; v < s.capture.NumViews(); ++v) {
      std::vector<cv::Mat> ids, flows, images;
      for (int f : frames) {
        if (f < seg.first || f > seg.last) continue;
        ids.push_back(s.Ids(v, f));
        if (f < seg.last) flows.push_back(s.Flow(v, f));
        if (!o.baseline_flows.empty()) images.push_back(reader->Read(v, f));
      }
      const std::string ctx =
          fmt::format("S_e segment {} view {}", seg.index, s.capture.views[v].name);
      AddPropagation(ids[0], flows, ids, o.propagate, ctx, &r->se_own_flow);
      for (baselines::FlowBaseline b : o.baseline_flows) {
        std::vector<cv::Mat> bflows;
        for (size_t k = 0; k + 1 < images.size(); ++k)
          bflows.push_back(baselines::BaselineFlow(b, images[k], images[k + 1]));
        AddPropagation(ids[0], bflows, ids, o.propagate, ctx,
                       &r->se_baseline[baselines::ToString(b)]);
      }
    }
  }
}

void CrossView(const Scene& s, const ConsistencyOptions& o, ConsistencyReport* r) {
  const int nv = s.capture.NumViews();
  for (int f : s.index.frames) {
    std::vector<cv::Mat> ids(nv), depth(nv);
    for (int v = 0; v < nv; ++v) ids[v] = s.Ids(v, f), depth[v] = s.Depth(v, f);
    for (int v = 0; v < nv; ++v) {
      CrossViewCounts& per = r->cross_view_by_view[s.capture.views[v].name];
      const Camera& cam = s.CameraOf(v, f);
      for (int y = 0; y < cam.height; y += o.pixel_step)
        for (int x = 0; x < cam.width; x += o.pixel_step) {
          const int label = ids[v].at<uint16_t>(y, x);
          const float d = depth[v].at<float>(y, x);
          if (label == 0 || !(d > 0) || !std::isfinite(d)) continue;
          const Eigen::Vector3d X = cam.Unproject(Eigen::Vector2d(x, y), d);
          for (int u = 0; u < nv; ++u) {
            if (u == v) continue;
            const Camera& other = s.CameraOf(u, f);
            const Eigen::Vector2d q = other.Project(X);
            if (!q.allFinite() || !other.InImage(q)) continue;
            // The 2x2 pixels around q: rounding q to one of them would put
            // points at a silhouette edge on the wrong side of it, so the
            // point agrees when any of them agrees and conflicts only when
            // all of them see farther.
            const double z = other.Depth(X);
            const int x0 = std::max(0, static_cast<int>(std::floor(q.x())));
            const int y0 = std::max(0, static_cast<int>(std::floor(q.y())));
            const int x1 = std::min(other.width - 1, x0 + 1);
            const int y1 = std::min(other.height - 1, y0 + 1);
            bool any_known = false, agree = false, label_agree = false, all_farther = true;
            for (int yy : {y0, y1})
              for (int xx : {x0, x1}) {
                const float dq = depth[u].at<float>(yy, xx);
                if (!(dq > 0) || !std::isfinite(dq)) continue;
                any_known = true;
                if (std::abs(dq - z) <= o.depth_tolerance * z) {
                  agree = true;
                  label_agree = label_agree || ids[u].at<uint16_t>(yy, xx) == label;
                }
                all_farther = all_farther && dq > z;
              }
            ++per.points;
            if (!any_known) {
              ++per.unseen;
            } else if (agree) {
              ++per.agree;
              if (label_agree) ++per.label_agree;
            } else if (all_farther) {
              ++per.conflict;
            } else {
              ++per.occluded;
            }
          }
        }
    }
  }
  for (const auto& [name, c] : r->cross_view_by_view) {
    r->cross_view.points += c.points;
    r->cross_view.agree += c.agree;
    r->cross_view.conflict += c.conflict;
    r->cross_view.occluded += c.occluded;
    r->cross_view.unseen += c.unseen;
    r->cross_view.label_agree += c.label_agree;
  }
}

void ProjectionError(const Scene& s, ConsistencyReport* r) {
  for (int f : s.index.frames) {
    // All objects in one z-buffer, so an object hidden by another is not
    // counted against either mask.
    std::vector<open3d::geometry::TriangleMesh> meshes;
    std::vector<int> labels;
    for (const SceneObjectInfo& obj : s.index.objects) {
      const fs::path path = s.dir / layout::SceneMesh(obj.id, f);
      if (!fs::exists(path)) continue;
      meshes.push_back(ReadMesh(path));
      labels.push_back(obj.id);
    }
    if (meshes.empty()) continue;
    std::vector<const open3d::geometry::TriangleMesh*> ptrs;
    ptrs.reserve(meshes.size());
    for (const auto& m : meshes) ptrs.push_back(&m);
    for (int v = 0; v < s.capture.NumViews(); ++v) {
      const cv::Mat rendered = RasterizeMeshes(ptrs, labels, s.CameraOf(v, f)).labels;
      const cv::Mat ids = s.Ids(v, f);
      for (int id : labels)
        r->projection_error.Add(
            CompareMasks(rendered == id, ids == id,
                         fmt::format("projection error {} frame {}", s.capture.views[v].name, f))
                .XorOverGt());
    }
  }
}

nlohmann::json Num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

nlohmann::json CountsJson(const CrossViewCounts& c) {
  return {{"points", c.points},
          {"agree", c.agree},
          {"conflict", c.conflict},
          {"occluded", c.occluded},
          {"unseen", c.unseen},
          {"depth_agreement", Num(c.DepthAgreement())},
          {"label_agreement", Num(c.LabelAgreement())}};
}

}  // namespace

ConsistencyReport EvaluateSceneConsistency(const Capture& capture, const fs::path& scene_dir,
                                           const ConsistencyOptions& options) {
  options.Check();
  const Scene s{capture, scene_dir, ReadSceneIndex(scene_dir)};
  for (const SceneViewInfo& v : s.index.views)
    U4D_CHECK(capture.ViewIndex(v.name) >= 0, "{}: view {} is not in the capture {}",
              (scene_dir / layout::SceneIndex()).string(), v.name, capture.root.string());
  U4D_CHECK(static_cast<int>(s.index.views.size()) == capture.NumViews(),
            "{}: {} views, the capture {} has {}", (scene_dir / layout::SceneIndex()).string(),
            s.index.views.size(), capture.root.string(), capture.NumViews());
  ConsistencyReport report;
  FrameReader reader(capture);
  SilhouetteOverlap(s, options, &reader, &report);
  CrossView(s, options, &report);
  if (s.index.has_meshes) ProjectionError(s, &report);
  return report;
}

nlohmann::json ConsistencyReport::ToJson() const {
  nlohmann::json j;
  j["silhouette_overlap_error"] = {{"own_flow", Num(se_own_flow.Mean())},
                                   {"frame_views", se_own_flow.count}};
  for (const auto& [name, se] : se_baseline) j["silhouette_overlap_error"][name] = Num(se.Mean());
  j["cross_view"] = CountsJson(cross_view);
  for (const auto& [name, c] : cross_view_by_view) j["cross_view_by_view"][name] = CountsJson(c);
  j["projection_error"] = {{"value", Num(projection_error.Mean())},
                           {"object_views", projection_error.count}};
  return j;
}

std::string ConsistencyReport::FormatTable() const {
  std::string s = "| consistency (no ground truth needed) | value |\n|---|---|\n";
  // No segment of two frames or more (e.g. every frame after a cut in time):
  // nothing was propagated.
  if (se_own_flow.count == 0)
    s += "| S_e, masks propagated with our flow (1 - IoU) | n/a (no segment spans two frames) |\n";
  else
    s += fmt::format(
        "| S_e, masks propagated with our flow (1 - IoU) | {:.3f} ({} instance-frames) |\n",
        se_own_flow.Mean(), se_own_flow.count);
  for (const auto& [name, se] : se_baseline)
    s += fmt::format("| S_e, masks propagated with {} | {:.3f} |\n", name, se.Mean());
  s += fmt::format("| cross-view depth agreement (agree / (agree + conflict)) | {:.3f} |\n",
                   cross_view.DepthAgreement());
  s += fmt::format("| cross-view label agreement (same id where depths agree) | {:.3f} |\n",
                   cross_view.LabelAgreement());
  s += fmt::format(
      "| cross-view points: agree / conflict / occluded / unseen | {} / {} / {} / {} |\n",
      cross_view.agree, cross_view.conflict, cross_view.occluded, cross_view.unseen);
  s += fmt::format(
      "| mesh projection error vs our masks (xor / mask) | {:.3f} ({} object-views) |\n",
      projection_error.Mean(), projection_error.count);
  return s;
}

}  // namespace u4d::eval
