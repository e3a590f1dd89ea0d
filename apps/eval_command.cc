// `u4d eval <capture> [--pred <dir>] [--initial] [-o <eval.json>]`: evaluates
// a prediction (laid out like <capture>/gt) or the capture's initial masks
// against the ground truth, prints a table and writes eval.json atomically.
// When <dir> is a scene written by `u4d run`, the vertex drift of its
// segments (eval/segment_drift.h) is added. `--se-baselines deepflow,dis`
// adds S_e of the GT masks carried by OpenCV flows on the capture's images
// (eval/baseline_overlap.h), beside the prediction's. `--grabcut` evaluates
// the segmentation baseline, GrabCut seeded with the initial masks
// (eval/baseline_grabcut.h), written to <capture>/baselines/grabcut/.
#include <memory>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/eval/baseline_grabcut.h"
#include "u4d/eval/baseline_overlap.h"
#include "u4d/eval/evaluate.h"
#include "u4d/eval/segment_drift.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d::apps {

namespace {
struct EvalArgs {
  std::string capture;
  std::string pred;
  bool initial = false;
  bool grabcut = false;
  std::string output;
  int keyframe_interval = 10;
  std::vector<std::string> se_baselines;
};
}  // namespace

Command MakeEvalCommand() {
  auto args = std::make_shared<EvalArgs>();
  return {"eval", "evaluate a prediction or the initial masks against a capture's ground truth",
          [=](CLI::App& app) {
            app.add_option("capture", args->capture, "capture directory (with gt/)")->required();
            app.add_option("--pred", args->pred,
                           "prediction directory laid out like gt/ (instances/, depth/, flow/, "
                           "joints3d/, meshes/)");
            app.add_flag("--initial", args->initial,
                         "evaluate the capture's initial masks (masks/) as instance predictions");
            app.add_flag("--grabcut", args->grabcut,
                         "evaluate GrabCut seeded with the initial masks (the segmentation "
                         "baseline), written to <capture>/baselines/grabcut/");
            app.add_option("-o,--output", args->output,
                           "eval.json to write (default: <pred>/eval.json, or "
                           "<capture>/eval_initial.json with --initial)");
            app.add_option("--keyframe-interval", args->keyframe_interval,
                           "key-frame spacing for the silhouette overlap error S_e")
                ->capture_default_str();
            app.add_option("--se-baselines", args->se_baselines,
                           "also S_e of the GT masks carried by these OpenCV flows on the "
                           "capture's images: deepflow, dis, farneback")
                ->delimiter(',');
          },
          [=] {
            U4D_CHECK(int(args->initial) + int(args->grabcut) + int(!args->pred.empty()) == 1,
                      "give exactly one of --pred <dir>, --initial and --grabcut");
            eval::EvalInput input;
            input.capture = args->capture;
            input.pred = args->pred;
            if (args->grabcut) {
              input.pred = input.capture / "baselines/grabcut";
              const int n = eval::WriteGrabCutPrediction(ReadCapture(input.capture), input.pred);
              fmt::print("GrabCut of the initial masks: {} view-frames in {}\n", n,
                         input.pred.string());
            }
            input.initial_masks = args->initial;
            eval::EvalOptions options;
            options.keyframe_interval = args->keyframe_interval;
            const eval::EvalReport report = eval::EvaluateCapture(input, options);
            nlohmann::json j = report.ToJson();
            // A scene written by `u4d run` also has temporally coherent
            // segments: their vertex drift against the GT vertex identities.
            if (!args->initial && fs::exists(input.pred / layout::SceneIndex()) &&
                fs::is_directory(input.capture / "gt/meshes")) {
              const eval::DriftReport drift = eval::EvaluateSegmentDrift(input.capture, input.pred);
              j["vertex_drift"] = drift.ToJson();
              fmt::print(
                  "vertex drift at the segments' last frames: {:.1f} mm (a static mesh: {:.1f} "
                  "mm, {} segments)\n",
                  drift.last_frame_drift.Mean() * 1e3, drift.last_frame_motion.Mean() * 1e3,
                  drift.last_frame_drift.count);
            }
            if (!args->se_baselines.empty()) {
              std::vector<baselines::FlowBaseline> flows;
              for (const std::string& name : args->se_baselines)
                flows.push_back(baselines::FlowBaselineFromString(name));
              const auto se =
                  eval::BaselineSilhouetteOverlap(ReadCapture(input.capture), flows, options);
              for (const auto& [name, r] : se) {
                j["silhouette_overlap_error_baselines"][name] = {{"value", r.Mean()},
                                                                 {"frame_views", r.count}};
                fmt::print("S_e of the GT masks carried by {}: {:.4f} ({} view-frames)\n", name,
                           r.Mean(), r.count);
              }
            }
            const fs::path out = !args->output.empty() ? fs::path(args->output)
                                 : args->initial       ? input.capture / "eval_initial.json"
                                                       : input.pred / "eval.json";
            WriteJsonFileAtomic(out, j);
            fmt::print("{}wrote {}\n", report.FormatTable(), out.string());
            return 0;
          }};
}

}  // namespace u4d::apps
