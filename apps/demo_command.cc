// `u4d demo`: synthesise a capture, run the whole pipeline on it (`u4d run`),
// evaluate the 4D scene and the initial masks against the ground truth, and
// print a summary. Everything goes under one output directory.
#include <memory>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/eval/evaluate.h"
#include "u4d/pipeline/pipeline.h"
#include "u4d/synth/generate.h"
#include "u4d/util/file.h"

namespace u4d::apps {

void PrintSynthSummary(const synth::SynthSummary& s, const std::string& dir);
synth::SynthOptions SynthOptionsFromArgs(const std::string& preset, int frames, int views,
                                         int width, int height, int people, uint64_t seed,
                                         const std::string& mocap,
                                         const std::string& captured_meshes,
                                         const std::string& degrade);

namespace {

struct DemoArgs {
  std::string out = "out/demo";
  std::string preset = "handshake";
  int frames = 5;  // a few minutes on 2 cores (docs/pipeline.md)
  int views = 6;
  int width = 480;
  int height = 270;
  uint64_t seed = 1;
};

}  // namespace

Command MakeDemoCommand() {
  auto a = std::make_shared<DemoArgs>();
  return {"demo", "synthesise a capture, run the pipeline, evaluate, print a summary",
          [=](CLI::App& app) {
            app.add_option("-o,--output", a->out, "output directory")->capture_default_str();
            app.add_option("--preset", a->preset, "synthetic preset")->capture_default_str();
            app.add_option("--frames", a->frames, "frames")->capture_default_str();
            app.add_option("--views", a->views, "cameras")->capture_default_str();
            app.add_option("--width", a->width, "image width")->capture_default_str();
            app.add_option("--height", a->height, "image height")->capture_default_str();
            app.add_option("--seed", a->seed, "random seed")->capture_default_str();
          },
          [=] {
            const fs::path out = a->out;
            const fs::path capture = out / "capture";
            const fs::path scene = out / "scene";
            fmt::print("== 1/3 synthesise ({} preset)\n", a->preset);
            const synth::SynthOptions o = SynthOptionsFromArgs(
                a->preset, a->frames, a->views, a->width, a->height, 0, a->seed, "", "", "preset");
            PrintSynthSummary(synth::WriteSyntheticCapture(o, capture, /*progress=*/true),
                              capture.string());

            fmt::print("\n== 2/3 run the pipeline (u4d run {} -o {})\n", capture.string(),
                       scene.string());
            const RunOptions run;  // writes scene/eval.json and prints its table
            const RunResult r = RunPipeline(capture, scene, run);
            fmt::print("\n{}", r.log.FormatTable());

            fmt::print("\n== 3/3 the initial masks and the 4D scene against the ground truth\n");
            const eval::EvalReport initial = eval::EvaluateCapture({capture, {}, true});
            const eval::EvalReport ours = eval::EvaluateCapture({capture, scene, false});
            WriteJsonFileAtomic(out / "eval_initial.json", initial.ToJson());
            fmt::print("\nsummary ({} frames, {} views)\n", r.frames, r.views);
            fmt::print("  mean instance IoU   initial masks {:.3f} -> u4d {:.3f}\n",
                       initial.instances->MeanInstanceIoU(), ours.instances->MeanInstanceIoU());
            if (ours.depth_people)
              fmt::print("  depth on people     within 1% {:.3f}, within 5% {:.3f}\n",
                         ours.depth_people->Delta1Pct(), ours.depth_people->Delta5Pct());
            if (ours.flow_people)
              fmt::print("  flow on people      EPE {:.3f} px\n", ours.flow_people->Epe());
            if (ours.meshes)
              fmt::print("  meshes              Chamfer {:.1f} mm ({} of {} matched)\n",
                         1000 * ours.meshes->chamfer.Mean(), ours.meshes->matched,
                         ours.meshes->gt_meshes);
            fmt::print("\nview it: u4d view {}\n", scene.string());
            fmt::print("\nwrote {}\n", out.string());
            return 0;
          }};
}

}  // namespace u4d::apps
