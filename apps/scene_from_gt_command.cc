// `u4d scene-from-gt <capture> -o <out>`: the oracle 4D scene. Writes the
// layout of a `u4d run` output (io/layout.h, docs/formats.md "The 4D scene")
// from a synthetic capture's ground truth: instance masks, depth and forward
// flow as scene maps, pictures for the viewer (downscaled input image and
// colourised maps), per-frame meshes with per-vertex colour and a `label`
// property, 3D joints as poses3d, key-frames, calibration, the evaluation of
// the ground truth against itself, and scene.json. Used by the viewer's tests
// and demos; `u4d view <out>` shows it.
#include <algorithm>
#include <map>
#include <memory>
#include <set>

#include <fmt/format.h>
#include <open3d/geometry/TriangleMesh.h>
#include <CLI/CLI.hpp>
#include <opencv2/imgproc.hpp>

#include "apps/commands.h"
#include "u4d/eval/evaluate.h"
#include "u4d/eval/mesh_metrics.h"
#include "u4d/fusion/labelled_ply.h"
#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/io/scene_index.h"
#include "u4d/io/visualize.h"
#include "u4d/util/check.h"
#include "u4d/util/progress.h"

namespace u4d::apps {
namespace {

struct SceneFromGtArgs {
  std::string capture;
  std::string out;
  int picture_width = 480;  // width of the viewer pictures (0 = the camera's)
  int keyframe_interval = 10;
  bool meshes = true;
  bool eval = true;
};

void CopyFile(const fs::path& from, const fs::path& to) {
  fs::create_directories(to.parent_path());
  fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

// Key-frames from <capture>/keyframes.json ({"keyframes", "frame_keyframe"},
// as keyframes/keyframe_similarity.h writes it) or every `interval`-th frame.
std::vector<SceneKeyframeInfo> Keyframes(const fs::path& capture, int num_frames, int interval) {
  std::vector<SceneKeyframeInfo> out;
  const fs::path path = capture / "keyframes.json";
  if (fs::exists(path)) {
    const nlohmann::json j = ReadJsonFile(path);
    const auto kfs = JsonGet<std::vector<int>>(j, "keyframes", path.string());
    const auto of = JsonGet<std::vector<int>>(j, "frame_keyframe", path.string());
    U4D_CHECK(static_cast<int>(of.size()) == num_frames,
              "{}: 'frame_keyframe' has {} entries, the capture {} frames", path.string(),
              of.size(), num_frames);
    for (int k : kfs) {
      SceneKeyframeInfo info{k, {}};
      for (int f = 0; f < num_frames; ++f)
        if (of[f] == k) info.members.push_back(f);
      out.push_back(info);
    }
    return out;
  }
  for (int k = 0; k < num_frames; k += interval) {
    SceneKeyframeInfo info{k, {}};
    for (int f = k; f < std::min(num_frames, k + interval); ++f) info.members.push_back(f);
    out.push_back(info);
  }
  return out;
}

int Run(const SceneFromGtArgs& a) {
  U4D_CHECK(a.keyframe_interval >= 1, "--keyframe-interval must be >= 1, found {}",
            a.keyframe_interval);
  U4D_CHECK(a.picture_width >= 0, "--picture-width must be >= 0, found {}", a.picture_width);
  const Capture cap = ReadCapture(a.capture);
  const fs::path gt = cap.root / "gt";
  CheckDirExists(gt, "ground truth directory");
  const fs::path out = a.out;
  fs::create_directories(out);

  SceneIndex index;
  index.name = cap.name;
  index.fps = cap.fps;
  for (int f = 0; f < cap.num_frames; ++f) index.frames.push_back(f);
  for (const CaptureView& v : cap.views)
    index.views.push_back({v.name, v.cameras.front().width, v.cameras.front().height});
  index.pictures = {"image", "instances", "depth", "flow"};
  WriteJsonFileAtomic(out / layout::SceneCalibration(), CalibrationToJson(cap));

  // Per-view maps and pictures.
  std::map<int, std::string> object_class;
  FrameReader reader(cap);
  Progress progress("scene-from-gt maps", int64_t(cap.num_frames) * cap.NumViews());
  for (int v = 0; v < cap.NumViews(); ++v) {
    const std::string& name = cap.views[v].name;
    std::pair<double, double> range{0, 0};
    for (int f = 0; f < cap.num_frames; ++f) {
      WriteImage(out / layout::ScenePicture("image", name, f),
                 DownscaleToWidth(reader.Read(v, f), a.picture_width, false));

      const cv::Mat ids = ReadLabelImage(cap.root / layout::GtInstances(name, f));
      CopyFile(cap.root / layout::GtInstances(name, f), out / layout::SceneInstances(name, f));
      const fs::path info = cap.root / layout::GtInstancesInfo(name, f);
      CopyFile(info, out / layout::SceneInstancesInfo(name, f));
      for (const nlohmann::json& inst : ReadJsonFile(info).value("instances", nlohmann::json()))
        object_class[inst.at("id").get<int>()] = inst.value("class", "person");
      WriteImage(out / layout::ScenePicture("instances", name, f),
                 DownscaleToWidth(ColorizeInstances(ids, {}), a.picture_width, true));

      const fs::path depth = cap.root / layout::GtDepth(name, f);
      const cv::Mat z = ReadPfm(depth);
      if (f == 0) range = VisibleDepthRange(z);
      CopyFile(depth, out / layout::SceneDepth(name, f));
      WriteImage(
          out / layout::ScenePicture("depth", name, f),
          DownscaleToWidth(ColorizeDepth(z, range.first, range.second), a.picture_width, true));

      const fs::path flow = cap.root / layout::GtFlow(name, f);
      if (fs::exists(flow)) {
        const cv::Mat uv = ReadFlo(flow);
        const fs::path valid_path = cap.root / layout::GtFlowValid(name, f);
        const cv::Mat valid = fs::exists(valid_path) ? ReadMaskImage(valid_path) : cv::Mat();
        CopyFile(flow, out / layout::SceneFlow(name, f));
        cv::Mat picture = ColorizeFlow(uv, MaxFlowMagnitude(uv, valid));
        if (!valid.empty()) picture.setTo(cv::Scalar::all(0), valid == 0);
        WriteImage(out / layout::ScenePicture("flow", name, f),
                   DownscaleToWidth(picture, a.picture_width, true));
      }
      progress.Tick();
    }
  }
  for (const auto& [id, cls] : object_class) {
    const cv::Vec3b c = InstanceColor(id);
    index.objects.push_back({id, cls, {c[0], c[1], c[2]}});
  }

  // 3D poses and meshes.
  for (int f = 0; f < cap.num_frames; ++f) {
    const fs::path joints = cap.root / layout::GtJoints3d(f);
    if (fs::exists(joints)) {
      CopyFile(joints, out / layout::ScenePoses3d(f));
      index.has_poses3d = true;
    }
  }
  if (a.meshes) {
    Progress mesh_progress("scene-from-gt meshes", int64_t(cap.num_frames) * index.objects.size());
    for (const SceneObjectInfo& o : index.objects)
      for (int f = 0; f < cap.num_frames; ++f) {
        const fs::path mesh = cap.root / layout::GtMesh(o.id, f);
        if (fs::exists(mesh)) {
          WriteLabelledMesh(out / layout::SceneMesh(o.id, f), eval::ReadMesh(mesh), o.id,
                            o.class_name);
          index.has_meshes = true;
        }
        mesh_progress.Tick();
      }
  }

  index.keyframes = Keyframes(cap.root, cap.num_frames, a.keyframe_interval);
  if (fs::exists(cap.root / "keyframes.json"))
    CopyFile(cap.root / "keyframes.json", out / layout::SceneKeyframes());

  if (a.eval) {
    const eval::EvalReport report = eval::EvaluateCapture({cap.root, gt, false});
    WriteJsonFileAtomic(out / layout::SceneEval(), report.ToJson());
    index.has_eval = true;
  }
  index.stages_done = {"ground-truth"};
  WriteSceneIndex(out, index);
  fmt::print("wrote the ground-truth 4D scene of {} ({} frames, {} views, {} objects) to {}\n",
             cap.root.string(), cap.num_frames, cap.NumViews(), index.objects.size(), out.string());
  return 0;
}

}  // namespace

Command MakeSceneFromGtCommand() {
  auto a = std::make_shared<SceneFromGtArgs>();
  return {
      "scene-from-gt",
      "write the oracle 4D scene (what `u4d run` writes) from a capture's ground truth",
      [=](CLI::App& app) {
        app.add_option("capture", a->capture, "capture with gt/ (e.g. from u4d synth)")->required();
        app.add_option("-o,--output", a->out, "scene directory to write")->required();
        app.add_option("--picture-width", a->picture_width,
                       "width of the viewer pictures in pixels (0 = full size)")
            ->capture_default_str();
        app.add_option("--keyframe-interval", a->keyframe_interval,
                       "key-frame spacing when the capture has no keyframes.json")
            ->capture_default_str();
        app.add_flag("!--no-meshes", a->meshes, "skip the meshes");
        app.add_flag("!--no-eval", a->eval, "skip eval.json");
      },
      [=] { return Run(*a); }};
}

}  // namespace u4d::apps
