// `u4d consistency <scene> [--capture <dir>] [--baselines dis,farneback]
// [-o <consistency.json>]`: the figures of a 4D scene that need no ground
// truth (eval/scene_consistency.h): S_e of the scene's masks propagated by
// its own flow (and by OpenCV flows), cross-view depth and label agreement,
// and the meshes' projection error against the scene's masks. `u4d run`
// writes the same file; this command recomputes it for an existing scene.
#include <memory>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/eval/scene_consistency.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d::apps {

namespace {
struct ConsistencyArgs {
  std::string scene;
  std::string capture;
  std::vector<std::string> baselines;
  std::string output;
  double depth_tolerance = 0.02;
  int pixel_step = 2;
};
}  // namespace

Command MakeConsistencyCommand() {
  auto args = std::make_shared<ConsistencyArgs>();
  return {
      "consistency",
      "consistency figures of a 4D scene that need no ground truth (S_e, cross-view, "
      "projection error)",
      [=](CLI::App& app) {
        app.add_option("scene", args->scene, "scene directory written by `u4d run`")->required();
        app.add_option("--capture", args->capture,
                       "capture directory (default: the one in the scene's params.json)");
        app.add_option("--baselines", args->baselines,
                       "OpenCV flows to propagate the masks with as well: deepflow, dis, "
                       "farneback")
            ->delimiter(',');
        app.add_option("--depth-tolerance", args->depth_tolerance,
                       "relative depth difference counted as agreement across views")
            ->capture_default_str();
        app.add_option("--pixel-step", args->pixel_step,
                       "sample every n-th pixel for the cross-view check")
            ->capture_default_str();
        app.add_option("-o,--output", args->output,
                       "file to write (default: <scene>/consistency.json)");
      },
      [=] {
        const fs::path scene = args->scene;
        fs::path capture = args->capture;
        if (capture.empty()) {
          const fs::path params = scene / layout::SceneParams();
          const nlohmann::json j = ReadJsonFile(params);
          U4D_CHECK(j.contains("capture") && j["capture"].is_string(),
                    "{}: no \"capture\" field; give --capture", params.string());
          capture = j["capture"].get<std::string>();
        }
        eval::ConsistencyOptions options;
        options.depth_tolerance = args->depth_tolerance;
        options.pixel_step = args->pixel_step;
        for (const std::string& b : args->baselines)
          options.baseline_flows.push_back(baselines::FlowBaselineFromString(b));
        const eval::ConsistencyReport report =
            eval::EvaluateSceneConsistency(ReadCapture(capture), scene, options);
        const fs::path out =
            args->output.empty() ? scene / layout::SceneConsistency() : fs::path(args->output);
        WriteJsonFileAtomic(out, report.ToJson());
        fmt::print("{}wrote {}\n", report.FormatTable(), out.string());
        return 0;
      }};
}

}  // namespace u4d::apps
