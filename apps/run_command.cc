// `u4d run <capture> -o <scene>`: the whole pipeline (u4d/pipeline/pipeline.h)
// with a progress bar per stage and a time and memory summary at the end.
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/init/init.h"
#include "u4d/io/layout.h"
#include "u4d/io/output_dir.h"
#include "u4d/joint/parameters.h"
#include "u4d/pipeline/pipeline.h"
#include "u4d/util/file.h"

namespace u4d::apps {
namespace {

struct RunArgs {
  std::string capture;
  std::string out;
  std::string masks = "auto";
  std::string poses = "auto";
  std::string config;  // JSON with "weights" and/or "terms" overrides
  std::string box_fill = "empty-views";
  RunOptions options;
};

int Run(RunArgs& a) {
  RunOptions& o = a.options;
  OutputDirOptions out_dir;
  out_dir.command = "u4d run";
  out_dir.input_roots = {a.capture};
  out_dir.markers = {layout::SceneRunLog().string(), layout::SceneParams().string()};
  CheckOutputDir(a.out, out_dir);
  o.masks = MaskSourceFromString(a.masks);
  o.poses = PoseSourceFromString(a.poses);
  o.init.box_fill = BoxFillFromString(a.box_fill);
  if (!a.config.empty()) {
    // Weights from a file replace the paper's table.
    const nlohmann::json j = ReadJsonFile(a.config);
    if (j.contains("weights")) {
      UpdateFromJson(j.at("weights"), a.config, &o.joint.weights);
      o.paper_weights = false;
    }
  }
  const RunResult r = RunPipeline(a.capture, a.out, o);
  fmt::print("\n{} frames, {} views, {} objects, {} key-frames, {} segments ({} done earlier)\n",
             r.frames, r.views, r.objects, r.keyframes, r.segments, r.segments_skipped);
  if (!r.empty_frames.empty())
    fmt::print("frames with no object in any view (left empty): {}\n",
               fmt::join(r.empty_frames, ", "));
  fmt::print("inputs used: masks {}, poses {}\n\n{}", r.log.masks, r.log.poses,
             r.log.FormatTable());
  fmt::print("\nwrote the 4D scene to {} (view it with `u4d view {}`)\n", a.out, a.out);
  return 0;
}

}  // namespace

Command MakeRunCommand() {
  auto a = std::make_shared<RunArgs>();
  return {"run", "run the whole pipeline on a capture and write the 4D scene",
          [=](CLI::App& app) {
            RunOptions& o = a->options;
            app.add_option("capture", a->capture, "capture directory (capture.json)")->required();
            app.add_option("-o,--output", a->out, "scene directory to write")->required();
            app.add_option("--first-frame", o.first_frame, "first frame")
                ->check(CLI::NonNegativeNumber)
                ->capture_default_str();
            app.add_option("--frames", o.num_frames, "frames to run (-1 = to the end)")
                ->check(CLI::Range(-1, 10000000))
                ->capture_default_str();
            app.add_option("--masks", a->masks, "initial masks: auto, given, unsupervised")
                ->capture_default_str();
            app.add_option("--poses", a->poses, "3D poses: auto, given3d, from2d, none")
                ->capture_default_str();
            app.add_option("--ablation", o.ablation, "energy: full, P_M, P_P, P_PM, P_S, P_PS")
                ->capture_default_str();
            app.add_option("--working-width", o.frame_setup.working_width,
                           "width at which the joint optimisation runs")
                ->check(CLI::Range(16, 100000))
                ->capture_default_str();
            app.add_option("--rounds", o.joint.rounds, "alternations of the l, d, m blocks")
                ->check(CLI::Range(1, 100))
                ->capture_default_str();
            app.add_option("--motion-candidates", o.joint.motion_candidates_per_pixel,
                           "motions a pixel may take in the motion block (0 = all)")
                ->check(CLI::Range(0, 10000))
                ->capture_default_str();
            app.add_option("--poisson-depth", o.fusion.poisson_depth,
                           "octree depth of each object's Poisson surface")
                ->check(CLI::Range(1, 16))
                ->capture_default_str();
            app.add_option("--picture-width", o.picture_width, "viewer picture width (0 = full)")
                ->check(CLI::Range(0, 100000))
                ->capture_default_str();
            app.add_option("--threads", o.threads, "views solved in parallel (0 = all cores)")
                ->check(CLI::Range(0, 4096))
                ->capture_default_str();
            app.add_option("--config", a->config,
                           "JSON file with \"weights\" overriding the paper's");
            app.add_option("--pose-smoothing", o.pose_smoothing.window_seconds,
                           "seconds of the window smoothing poses from 2D over time (0 = off)")
                ->check(CLI::Range(0.0, 60.0))
                ->capture_default_str();
            app.add_flag("!--no-joint-tracks", o.tracks.add_joint_tracks,
                         "do not add the projected 3D joints to the sparse tracks");
            app.add_flag("!--no-resume", o.resume, "recompute everything in the output directory");
            app.add_flag("!--no-eval", o.evaluate, "skip eval.json even with ground truth");
            app.add_flag("!--no-progress", o.progress, "no progress bars");
            app.add_option("--box-fill", a->box_fill,
                           "unsupervised masks: GrabCut in HOG people boxes the background "
                           "leaves empty: never, empty-views, always")
                ->capture_default_str();
            app.add_flag("--allow-empty", o.allow_empty,
                         "succeed even when no object is found in any frame");
          },
          [=] { return Run(*a); }};
}

}  // namespace u4d::apps
