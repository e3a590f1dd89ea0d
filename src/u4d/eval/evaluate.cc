#include "u4d/eval/evaluate.h"

#include <cmath>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <open3d/geometry/TriangleMesh.h>

#include "u4d/eval/hungarian.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

nlohmann::json Num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// The prediction's path for a GT-relative path: gt/x/y -> <pred>/x/y.
fs::path PredPath(const fs::path& pred_dir, const fs::path& gt_relative) {
  return pred_dir / gt_relative.lexically_relative("gt");
}

fs::path Sidecar(const fs::path& png) { return fs::path(png).replace_extension(".json"); }

InstanceMask EmptyMask(const cv::Mat& like) {
  return InstanceMask{cv::Mat::zeros(like.size(), CV_16UC1), {}};
}

// Binary mask of the GT pixels whose instance has class `label`.
cv::Mat ClassMask(const InstanceMask& gt, const std::string& label) {
  cv::Mat mask = cv::Mat::zeros(gt.ids.size(), CV_8UC1);
  for (const InstanceInfo& info : gt.instances)
    if (info.label == label) mask.setTo(255, gt.ids == info.id);
  return mask;
}

struct Context {
  const Capture& capture;
  const EvalInput& input;
  const EvalOptions& options;
  EvalReport& report;
  fs::path root;
  bool HasGt(const char* sub) const { return fs::is_directory(root / "gt" / sub); }
  bool HasPred(const char* sub) const {
    return !input.initial_masks && fs::is_directory(input.pred / sub);
  }
};

// The mesh of object `id` at `frame` under a directory laid out like gt/.
fs::path MeshPath(const fs::path& base, int id, int frame) {
  return base / layout::GtMesh(id, frame).lexically_relative("gt");
}

// The ids among `ids` that have a mesh file at `frame` under `base`.
std::vector<int> MeshIdsAt(const fs::path& base, const std::vector<int>& ids, int frame) {
  std::vector<int> at;
  for (int id : ids)
    if (fs::exists(MeshPath(base, id, frame))) at.push_back(id);
  return at;
}

InstanceMask ReadGtInstances(const fs::path& root, const std::string& view, int frame) {
  return ReadInstanceMask(root / layout::GtInstances(view, frame),
                          root / layout::GtInstancesInfo(view, frame));
}

// gt/contacts.json, when the capture has it: per frame, the pairs (a < b) of
// GT ids whose surfaces are in contact (docs/formats.md).
std::optional<std::map<int, std::set<std::pair<int, int>>>> ReadGtContacts(const fs::path& root) {
  const fs::path path = root / layout::GtContacts();
  if (!fs::exists(path)) return std::nullopt;
  const nlohmann::json j = ReadJsonFile(path);
  U4D_CHECK(j.is_object() && j.contains("frames") && j["frames"].is_array(),
            "{}: expected an object with a 'frames' array", path.string());
  std::map<int, std::set<std::pair<int, int>>> contacts;
  for (const nlohmann::json& frame : j["frames"]) {
    U4D_CHECK(frame.is_object() && frame.contains("frame") && frame["frame"].is_number_integer() &&
                  frame.contains("pairs") && frame["pairs"].is_array(),
              "{}: each frame needs an integer 'frame' and a 'pairs' array", path.string());
    auto& pairs = contacts[frame["frame"].get<int>()];
    for (const nlohmann::json& p : frame["pairs"]) {
      U4D_CHECK(
          p.is_array() && p.size() == 2 && p[0].is_number_integer() && p[1].is_number_integer(),
          "{}: a pair must be two integer ids", path.string());
      const int a = p[0].get<int>(), b = p[1].get<int>();
      pairs.emplace(std::min(a, b), std::max(a, b));
    }
  }
  return contacts;
}

// Whether a pair of `r.touching_pairs` is in `contacts` at that frame.
bool TouchingInContact(const InstanceSegResult& r, const std::set<std::pair<int, int>>& contacts) {
  for (const auto& pair : r.touching_pairs)
    if (contacts.count(pair)) return true;
  return false;
}

// Instance IoU per view-frame, and the identity figures from the same matches.
void EvaluateInstanceMasks(Context& c) {
  InstanceSegAccumulator acc;
  const auto contacts = ReadGtContacts(c.root);
  acc.touch_in_contact = contacts.has_value();
  IdentityAccumulator identity(c.options.instances.match_iou);
  for (int vi = 0; vi < c.capture.NumViews(); ++vi) {
    const CaptureView& v = c.capture.views[vi];
    for (int f = 0; f < c.capture.num_frames; ++f) {
      const InstanceMask gt = ReadGtInstances(c.root, v.name, f);
      const fs::path png = c.input.initial_masks
                               ? c.root / layout::Mask(v.name, f)
                               : PredPath(c.input.pred, layout::GtInstances(v.name, f));
      InstanceMask pred = EmptyMask(gt.ids);
      if (fs::exists(png))
        pred = ReadInstanceMask(png, Sidecar(png));
      else
        ++c.report.missing_predictions["instances"];
      InstanceSegResult r = EvaluateInstances(
          pred, gt, c.options.instances,
          fmt::format("{} vs {}", png.string(), layout::GtInstances(v.name, f).string()));
      if (contacts) {
        const auto at = contacts->find(f);
        r.touching = at != contacts->end() && TouchingInContact(r, at->second);
      }
      acc.Add(r);
      identity.Add(vi, f, r.matches);
    }
  }
  // Which of the matched ids have a mesh: the mesh files of the prediction's
  // meshes/ (the layout EvaluateMeshes reads), per frame.
  if (c.HasPred("meshes")) {
    const std::vector<int> pred_ids = MeshObjectIds(c.input.pred / "meshes");
    const std::vector<int> gt_ids = MeshObjectIds(c.root / "gt/meshes");
    for (int f = 0; f < c.capture.num_frames; ++f)
      identity.AddMeshes(f, MeshIdsAt(c.root / "gt", gt_ids, f),
                         MeshIdsAt(c.input.pred, pred_ids, f));
  }
  c.report.instances = acc;
  c.report.identity = identity;
}

void EvaluateDepthMaps(Context& c) {
  DepthMetrics all, people;
  const bool with_people = c.HasGt("instances");
  for (const CaptureView& v : c.capture.views)
    for (int f = 0; f < c.capture.num_frames; ++f) {
      const fs::path gt_path = c.root / layout::GtDepth(v.name, f);
      const cv::Mat gt = ReadPfm(gt_path);
      const fs::path pred_path = PredPath(c.input.pred, layout::GtDepth(v.name, f));
      cv::Mat pred;
      if (fs::exists(pred_path))
        pred = ReadPfm(pred_path);
      else
        ++c.report.missing_predictions["depth"];
      const std::string ctx = fmt::format("{} vs {}", pred_path.string(), gt_path.string());
      all.Add(EvaluateDepth(pred, gt, {}, ctx));
      if (with_people) {
        const cv::Mat mask = ClassMask(ReadGtInstances(c.root, v.name, f), c.options.people_class);
        U4D_CHECK(mask.size() == gt.size(), "{}: size differs from the GT instances",
                  gt_path.string());
        people.Add(EvaluateDepth(pred, gt, mask, ctx));
      }
    }
  c.report.depth = all;
  if (with_people) c.report.depth_people = people;
}

// The GT flow of (view, frame), or an empty Mat when the file is optional and absent.
cv::Mat ReadGtFlow(const Context& c, const std::string& view, int frame, cv::Mat* valid) {
  const fs::path path = c.root / layout::GtFlow(view, frame);
  if (frame == c.capture.num_frames - 1 && !fs::exists(path)) return {};
  cv::Mat flow = ReadFlo(path);
  valid->release();
  if (c.HasGt("flow_valid")) {
    *valid = ReadMaskImage(c.root / layout::GtFlowValid(view, frame));
    CheckImageSize(*valid, flow.cols, flow.rows,
                   (c.root / layout::GtFlowValid(view, frame)).string());
  }
  return flow;
}

cv::Mat ReadPredFlow(Context& c, const std::string& view, int frame, bool count_missing) {
  const fs::path path = PredPath(c.input.pred, layout::GtFlow(view, frame));
  if (fs::exists(path)) return ReadFlo(path);
  if (count_missing) ++c.report.missing_predictions["flow"];
  return {};
}

void EvaluateFlowMaps(Context& c) {
  FlowMetrics all, people, background;
  const bool with_people = c.HasGt("instances");
  for (const CaptureView& v : c.capture.views)
    for (int f = 0; f < c.capture.num_frames; ++f) {
      cv::Mat valid;
      const cv::Mat gt = ReadGtFlow(c, v.name, f, &valid);
      if (gt.empty()) continue;
      const cv::Mat pred = ReadPredFlow(c, v.name, f, true);
      const std::string ctx =
          fmt::format("{} vs {}", PredPath(c.input.pred, layout::GtFlow(v.name, f)).string(),
                      (c.root / layout::GtFlow(v.name, f)).string());
      all.Add(EvaluateFlow(pred, gt, valid, {}, ctx));
      if (with_people) {
        const cv::Mat mask = ClassMask(ReadGtInstances(c.root, v.name, f), c.options.people_class);
        CheckImageSize(mask, gt.cols, gt.rows, ctx);
        people.Add(EvaluateFlow(pred, gt, valid, mask, ctx));
        background.Add(EvaluateFlow(pred, gt, valid, mask == 0, ctx));
      }
    }
  c.report.flow = all;
  if (with_people) {
    c.report.flow_people = people;
    c.report.flow_background = background;
  }
}

// S_e of the prediction's flow (a missing flow file drops every pixel).
void EvaluateSilhouetteOverlap(Context& c) {
  c.report.silhouette_overlap_error = GtSilhouetteOverlap(
      c.capture,
      [&](int view, int frame) {
        return ReadPredFlow(c, c.capture.views[view].name, frame, false);
      },
      c.options);
}

std::vector<Limb> LimbsFor(const std::string& skeleton, int num_joints, const std::string& ctx) {
  if (skeleton == "h36m17" || (skeleton.empty() && num_joints == 17)) return H36m17Limbs();
  if (skeleton == "shelf14" || skeleton == "shelf15" || (skeleton.empty() && num_joints == 14))
    return Shelf14Limbs();
  ThrowError(
      fmt::format("{}: no limb list for skeleton '{}' with {} joints", ctx, skeleton, num_joints));
}

void EvaluateJoints(Context& c) {
  PoseMetrics acc;
  for (int f = 0; f < c.capture.num_frames; ++f) {
    const fs::path gt_path = c.root / layout::GtJoints3d(f);
    if (!fs::exists(gt_path)) continue;
    std::string skeleton;
    const std::vector<Person3d> gt = ReadPoses3dJson(gt_path, &skeleton);
    const fs::path pred_path = PredPath(c.input.pred, layout::GtJoints3d(f));
    std::vector<Person3d> pred;
    if (fs::exists(pred_path))
      pred = ReadPoses3dJson(pred_path);
    else
      ++c.report.missing_predictions["joints3d"];
    const int num_joints = gt.empty() ? 17 : static_cast<int>(gt[0].joints.size());
    const std::string ctx = fmt::format("{} vs {}", pred_path.string(), gt_path.string());
    acc.Add(EvaluatePoses(pred, gt, LimbsFor(skeleton, num_joints, gt_path.string()),
                          c.options.pose, ctx));
  }
  c.report.poses = acc;
}

std::map<int, open3d::geometry::TriangleMesh> ReadMeshes(const fs::path& base,
                                                         const std::vector<int>& ids, int frame) {
  std::map<int, open3d::geometry::TriangleMesh> meshes;
  for (int id : ids) {
    const fs::path path = MeshPath(base, id, frame);
    if (fs::exists(path)) meshes.emplace(id, ReadMesh(path));
  }
  return meshes;
}

// Chamfer against GT meshes (matched by minimal Chamfer distance) and the
// projection error against GT instances (matched by IoU pooled over views).
void EvaluateMeshes(Context& c, bool chamfer, bool projection) {
  MeshEval mesh_eval;
  RatioMean proj;
  const std::vector<int> pred_ids = MeshObjectIds(c.input.pred / "meshes");
  const std::vector<int> gt_ids =
      chamfer ? MeshObjectIds(c.root / "gt/meshes") : std::vector<int>{};
  for (int f = 0; f < c.capture.num_frames; ++f) {
    const auto pred = ReadMeshes(c.input.pred, pred_ids, f);
    if (chamfer) {
      const auto gt = ReadMeshes(c.root / "gt", gt_ids, f);
      mesh_eval.gt_meshes += static_cast<int>(gt.size());
      mesh_eval.pred_meshes += static_cast<int>(pred.size());
      std::vector<ChamferResult> results;
      Eigen::MatrixXd cost(gt.size(), pred.size());
      int i = 0;
      for (const auto& [gid, gmesh] : gt) {
        int j = 0;
        for (const auto& [pid, pmesh] : pred) {
          results.push_back(MeshChamfer(pmesh, gmesh, c.options.chamfer));
          cost(i, j++) = results.back().chamfer;
        }
        ++i;
      }
      const std::vector<int> match = MinCostAssignment(cost);
      for (int gi = 0; gi < static_cast<int>(gt.size()); ++gi) {
        if (match[gi] < 0) continue;
        const ChamferResult& r = results[gi * pred.size() + match[gi]];
        ++mesh_eval.matched;
        mesh_eval.chamfer.Add(r.chamfer);
        mesh_eval.pred_to_gt.Add(r.pred_to_gt);
        mesh_eval.gt_to_pred.Add(r.gt_to_pred);
        mesh_eval.accuracy.Add(r.accuracy);
        mesh_eval.completeness.Add(r.completeness);
        mesh_eval.f_score.Add(r.f_score);
      }
    }
    if (projection) {
      std::vector<const open3d::geometry::TriangleMesh*> meshes;
      std::vector<int> labels;
      for (const auto& [pid, m] : pred) {
        meshes.push_back(&m);
        labels.push_back(pid);
      }
      std::vector<InstanceMask> gts;
      std::vector<cv::Mat> rendered;
      std::set<int> gt_objects;
      for (int v = 0; v < c.capture.NumViews(); ++v) {
        gts.push_back(ReadGtInstances(c.root, c.capture.views[v].name, f));
        const Camera& cam = c.capture.views[v].CameraAt(f);
        CheckImageSize(gts.back().ids, cam.width, cam.height,
                       (c.root / layout::GtInstances(c.capture.views[v].name, f)).string());
        rendered.push_back(RasterizeMeshes(meshes, labels, cam).labels);
        for (const InstanceInfo& info : gts.back().instances) gt_objects.insert(info.id);
      }
      // Match meshes to GT objects by intersection-over-union pooled over views.
      const std::vector<int> objects(gt_objects.begin(), gt_objects.end());
      Eigen::MatrixXd inter = Eigen::MatrixXd::Zero(objects.size(), labels.size());
      Eigen::MatrixXd uni = inter;
      std::vector<std::vector<MaskOverlap>> overlaps(objects.size(),
                                                     std::vector<MaskOverlap>(labels.size()));
      for (size_t v = 0; v < gts.size(); ++v)
        for (size_t i = 0; i < objects.size(); ++i)
          for (size_t j = 0; j < labels.size(); ++j) {
            const MaskOverlap o =
                CompareMasks(rendered[v] == labels[j], gts[v].ids == objects[i], "projection");
            inter(i, j) += static_cast<double>(o.intersection);
            uni(i, j) += static_cast<double>(o.union_);
          }
      const Eigen::MatrixXd iou = inter.cwiseQuotient(uni.cwiseMax(1.0));
      const std::vector<int> match = MaxScoreAssignment(iou);
      for (size_t v = 0; v < gts.size(); ++v)
        for (size_t i = 0; i < objects.size(); ++i) {
          const cv::Mat g = gts[v].ids == objects[i];
          const cv::Mat p = match[i] >= 0 && iou(i, match[i]) > 0
                                ? cv::Mat(rendered[v] == labels[match[i]])
                                : cv::Mat(cv::Mat::zeros(g.size(), CV_8UC1));
          proj.Add(CompareMasks(p, g, "projection").XorOverGt());
        }
    }
  }
  if (chamfer) c.report.meshes = mesh_eval;
  if (projection) c.report.projection_error = proj;
}

}  // namespace

void EvalOptions::Check() const {
  instances.Check();
  pose.Check();
  chamfer.Check();
  propagate.Check();
  U4D_CHECK(keyframe_interval >= 1, "EvalOptions: keyframe_interval must be >= 1");
}

RatioMean GtSilhouetteOverlap(const Capture& capture, const FlowSource& flow,
                              const EvalOptions& options) {
  options.Check();
  RatioMean se;
  const int k = options.keyframe_interval;
  for (int vi = 0; vi < capture.NumViews(); ++vi) {
    const std::string& view = capture.views[vi].name;
    for (int key = 0; key < capture.num_frames; key += k) {
      const InstanceMask key_gt = ReadGtInstances(capture.root, view, key);
      std::map<int, cv::Mat> propagated;
      for (const InstanceInfo& info : key_gt.instances) {
        cv::Mat m = key_gt.ids == info.id;
        if (cv::countNonZero(m) > 0) propagated[info.id] = m;
      }
      const int end = std::min(key + k, capture.num_frames);
      for (int f = key + 1; f < end; ++f) {
        cv::Mat forward = flow(vi, f - 1);
        if (forward.empty())
          forward = cv::Mat(key_gt.ids.size(), CV_32FC2, cv::Scalar(1e10f, 1e10f));
        const InstanceMask gt = ReadGtInstances(capture.root, view, f);
        RatioMean frame_error;
        for (auto& [id, mask] : propagated) {
          const std::string ctx = fmt::format("S_e {} frame {} instance {}", view, f, id);
          mask = PropagateMask(mask, forward, options.propagate, ctx);
          frame_error.Add(CompareMasks(mask, gt.ids == id, ctx).OneMinusIoU());
        }
        se.Add(frame_error.Mean());
      }
    }
  }
  return se;
}

EvalReport EvaluateCapture(const EvalInput& input, const EvalOptions& options) {
  options.Check();
  const Capture capture = ReadCapture(input.capture);
  CheckDirExists(input.capture / "gt", "ground-truth directory");
  if (!input.initial_masks) CheckDirExists(input.pred, "prediction directory");
  EvalReport report;
  report.source = input.initial_masks ? "initial masks" : input.pred.string();
  Context c{capture, input, options, report, input.capture};
  if (c.HasGt("instances") && (input.initial_masks || c.HasPred("instances")))
    EvaluateInstanceMasks(c);
  if (c.HasGt("depth") && c.HasPred("depth")) EvaluateDepthMaps(c);
  if (c.HasGt("flow") && c.HasPred("flow")) EvaluateFlowMaps(c);
  if (c.HasGt("instances") && c.HasPred("flow")) EvaluateSilhouetteOverlap(c);
  if (c.HasGt("joints3d") && c.HasPred("joints3d")) EvaluateJoints(c);
  if (c.HasPred("meshes") && (c.HasGt("meshes") || c.HasGt("instances")))
    EvaluateMeshes(c, c.HasGt("meshes"), c.HasGt("instances"));
  return report;
}

nlohmann::json EvalReport::ToJson() const {
  nlohmann::json j = {{"format", "u4d-eval"}, {"source", source}};
  if (instances) j["instances"] = instances->ToJson();
  if (identity) j["identity"] = identity->ToJson();
  if (depth) j["depth"] = depth->ToJson();
  if (depth_people) j["depth_people"] = depth_people->ToJson();
  if (flow) j["flow"] = flow->ToJson();
  if (flow_people) j["flow_people"] = flow_people->ToJson();
  if (flow_background) j["flow_background"] = flow_background->ToJson();
  if (silhouette_overlap_error)
    j["silhouette_overlap_error"] = {{"value", Num(silhouette_overlap_error->Mean())},
                                     {"frame_views", silhouette_overlap_error->count}};
  if (poses) j["joints3d"] = poses->ToJson();
  if (meshes)
    j["meshes"] = {{"gt_meshes", meshes->gt_meshes},
                   {"pred_meshes", meshes->pred_meshes},
                   {"matched", meshes->matched},
                   {"chamfer_m", Num(meshes->chamfer.Mean())},
                   {"pred_to_gt_m", Num(meshes->pred_to_gt.Mean())},
                   {"gt_to_pred_m", Num(meshes->gt_to_pred.Mean())},
                   {"accuracy", Num(meshes->accuracy.Mean())},
                   {"completeness", Num(meshes->completeness.Mean())},
                   {"f_score", Num(meshes->f_score.Mean())}};
  if (projection_error)
    j["projection_error"] = {{"value", Num(projection_error->Mean())},
                             {"object_views", projection_error->count}};
  j["missing_predictions"] = missing_predictions;
  return j;
}

std::string EvalReport::FormatTable() const {
  std::string s = fmt::format("evaluation of {}\n", source);
  auto row = [&s](const std::string& name, double value, const char* unit) {
    s += std::isfinite(value) ? fmt::format("  {:<34} {:>10.4f} {}\n", name, value, unit)
                              : fmt::format("  {:<34} {:>10} {}\n", name, "n/a", unit);
  };
  if (instances) {
    s += fmt::format("instances ({} images, {} GT, {} predicted)\n", instances->num_images,
                     instances->num_gt, instances->num_pred);
    row("mean instance IoU", instances->MeanInstanceIoU(), "");
    row("mean class IoU", instances->MeanClassIoU(), "");
    for (const auto& [label, o] : instances->per_class) row("IoU " + label, o.IoU(), "");
    if (instances->per_class_instances.size() > 1)
      for (const auto& [label, c] : instances->per_class_instances)
        row("instance IoU " + label, c.MeanIoU(), "");
    s += fmt::format("  {:<34} {:>10} / {} / {} / {}\n", "missed / false pos. / merged / split",
                     instances->missed, instances->false_positives, instances->merged,
                     instances->split);
    if (instances->touching_images > 0)
      s += fmt::format("  {:<34} {:>10.4f} ({} of {} view-frames; {})\n",
                       "merge rate where people touch", instances->MergeRateWhereTouching(),
                       instances->merged_touching_images, instances->touching_images,
                       instances->touch_in_contact ? "in 3D contact" : "masks adjacent");
    if (instances->objects > 0)
      s += fmt::format("  {:<34} {:>10.4f} ({} of {} object instances)\n",
                       "objects merged with a person", instances->ObjectMergeRate(),
                       instances->objects_merged_with_person, instances->objects);
  }
  if (identity) {
    const IdentitySummary id = identity->Summarize();
    s += fmt::format("identity ({} GT people, {} predicted ids, match IoU >= {})\n",
                     id.people.size(), id.people_of_pred_id.size(), id.match_iou);
    row("ids per person (ideal 1)", id.mean_ids_per_person, "");
    row("people per predicted id (ideal 1)", id.mean_people_per_pred_id, "");
    s += fmt::format("  {:<34} {:>10} / {} / {}\n", "switches / cross-view / shared ids",
                     id.switches, id.cross_view_disagreements, id.shared_pred_ids);
    if (id.with_meshes)
      s += fmt::format("  {:<34} {:>10} / {} ({} unmatched)\n", "frames without mesh / visible",
                       id.no_mesh_frames, id.visible_frames, id.unmatched_frames);
    for (const IdentityPerson& p : id.people) {
      std::string line =
          fmt::format("  person {:<5} {:>3} ids, {} switches, {} cross-view", p.gt_id,
                      p.pred_ids.size(), p.switches, p.cross_view_disagreements);
      if (id.with_meshes)
        line += fmt::format(", {} / {} frames without mesh", p.no_mesh_frames, p.visible_frames);
      s += line + "\n";
    }
  }
  auto depth_rows = [&](const char* title, const DepthMetrics& d) {
    s += fmt::format("{}\n", title);
    row("AbsRel", d.AbsRel(), "");
    row("RMSE", d.Rmse(), "m");
    row("within 1%", d.Delta1Pct(), "");
    row("within 5%", d.Delta5Pct(), "");
    row("completeness", d.Completeness(), "");
  };
  if (depth) depth_rows("depth (all pixels)", *depth);
  if (depth_people) depth_rows("depth (people)", *depth_people);
  auto flow_rows = [&](const char* title, const FlowMetrics& f) {
    s += fmt::format("{}\n", title);
    row("EPE", f.Epe(), "px");
    row("EPE < 1 px", f.Within1Px(), "");
    row("EPE < 3 px", f.Within3Px(), "");
    row("EPE > 10 px", f.Beyond10Px(), "");
    row("motion scale", f.MotionScale(), "(1 = unbiased)");
    row("completeness", f.Completeness(), "");
  };
  if (flow) flow_rows("flow (all pixels)", *flow);
  if (flow_people) flow_rows("flow (people)", *flow_people);
  if (flow_background) flow_rows("flow (background)", *flow_background);
  if (silhouette_overlap_error) {
    s += "temporal coherence\n";
    row("silhouette overlap error S_e", silhouette_overlap_error->Mean(), "(1 - IoU)");
  }
  if (poses) {
    s += fmt::format("3D pose ({} frames, {} GT people, {} missed, {} false pos.)\n", poses->frames,
                     poses->gt_people, poses->missed, poses->false_positives);
    row("MPJPE", poses->Mpjpe() * 1000.0, "mm");
    row("PCP", poses->pcp.Rate(), "");
    for (const auto& [limb, cnt] : poses->pcp_per_limb) row("PCP " + limb, cnt.Rate(), "");
  }
  if (meshes) {
    s += fmt::format("meshes ({} GT, {} predicted, {} matched)\n", meshes->gt_meshes,
                     meshes->pred_meshes, meshes->matched);
    row("Chamfer", meshes->chamfer.Mean() * 1000.0, "mm");
    row("accuracy", meshes->accuracy.Mean(), "");
    row("completeness", meshes->completeness.Mean(), "");
    row("F-score", meshes->f_score.Mean(), "");
  }
  if (projection_error) {
    s += "reconstruction\n";
    row("projection error |P xor G| / |G|", projection_error->Mean(), "");
  }
  for (const auto& [what, n] : missing_predictions)
    s += fmt::format("  missing {} predictions: {}\n", what, n);
  return s;
}

}  // namespace u4d::eval
