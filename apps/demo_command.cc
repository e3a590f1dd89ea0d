// `u4d demo`: synthesise a capture, run what exists of the pipeline, evaluate,
// and print a summary. Everything goes under one output directory.
#include <memory>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/eval/evaluate.h"
#include "u4d/synth/generate.h"
#include "u4d/util/file.h"

namespace u4d::apps {

void PrintSynthSummary(const synth::SynthSummary& s, const std::string& dir);
synth::SynthOptions SynthOptionsFromArgs(const std::string& preset, int frames, int views,
                                         int width, int height, int people, uint64_t seed,
                                         const std::string& mocap, const std::string& degrade);

namespace {

struct DemoArgs {
  std::string out = "out/demo";
  std::string preset = "handshake";
  int frames = 24;
  int views = 8;
  int width = 640;
  int height = 360;
  uint64_t seed = 1;
};

}  // namespace

Command MakeDemoCommand() {
  auto a = std::make_shared<DemoArgs>();
  return {
      "demo", "synthesise a capture, run the pipeline, evaluate, print a summary",
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
        fmt::print("== 1/3 synthesise ({} preset)\n", a->preset);
        const synth::SynthOptions o = SynthOptionsFromArgs(a->preset, a->frames, a->views, a->width,
                                                           a->height, 0, a->seed, "", "default");
        PrintSynthSummary(synth::WriteSyntheticCapture(o, capture, /*progress=*/true),
                          capture.string());

        fmt::print(
            "\n== 2/3 check: ground truth against itself (perfect on every direct comparison;\n"
            "   S_e warps key-frame masks by flow, which cannot restore disoccluded pixels,\n"
            "   so even the true flow leaves a small S_e)\n");
        const eval::EvalReport self = eval::EvaluateCapture({capture, capture / "gt", false});
        fmt::print("{}", self.FormatTable());
        WriteJsonFileAtomic(out / "eval_gt_self.json", self.ToJson());

        fmt::print("\n== 3/3 evaluate the initial (detector-like) masks against ground truth\n");
        const eval::EvalReport initial = eval::EvaluateCapture({capture, {}, true});
        fmt::print("{}", initial.FormatTable());
        WriteJsonFileAtomic(out / "eval_initial.json", initial.ToJson());
        fmt::print("\nwrote {}\n", out.string());
        return 0;
      }};
}

}  // namespace u4d::apps
