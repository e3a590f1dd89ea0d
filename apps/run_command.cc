// `u4d run <capture> -o <scene>`: the whole pipeline (u4d/pipeline/pipeline.h)
// with a progress bar per stage and a time and memory summary at the end.
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/io/layout.h"
#include "u4d/io/output_dir.h"
#include "u4d/pipeline/pipeline.h"
#include "u4d/pipeline/run_flags.h"
#include "u4d/util/file.h"

namespace u4d::apps {
namespace {

struct RunArgs {
  std::string capture;
  std::string out;
  RunOverrides overrides;  // --config, --set and the named flags, applied in that order
};

int Run(RunArgs& a) {
  RunOptions o;
  a.overrides.ApplyTo(&o);
  o.Check();  // before anything is written
  OutputDirOptions out_dir;
  out_dir.command = "u4d run";
  out_dir.input_roots = {a.capture};
  out_dir.markers = {layout::SceneRunLog().string(), layout::SceneParams().string()};
  CheckOutputDir(a.out, out_dir);
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

// The named flags (RunOptionFlags), each checked on parsing by RunOptions::Check().
void AddNamedFlags(CLI::App& app, RunOverrides* overrides) {
  for (const OptionFlag& f : RunOptionFlags()) {
    if (!f.value.empty()) {
      app.add_flag_callback(
          f.flag, [overrides, f] { overrides->named_flags.emplace_back(f, f.value); },
          OptionFlagHelp(f));
      continue;
    }
    const CLI::Validator valid(
        [f](std::string& text) -> std::string {
          try {
            CheckOptionFlagValue(f, text);
          } catch (const Error& e) {
            return e.what();
          }
          return "";
        },
        "", "");
    app.add_option_function<std::string>(
           f.flag,
           [overrides, f](const std::string& text) {
             overrides->named_flags.emplace_back(f, text);
           },
           OptionFlagHelp(f))
        ->type_name(OptionFlagType(f))
        ->check(valid);
  }
}

}  // namespace

Command MakeRunCommand() {
  auto a = std::make_shared<RunArgs>();
  return {"run", "run the whole pipeline on a capture and write the 4D scene",
          [=](CLI::App& app) {
            app.add_option("capture", a->capture, "capture directory (capture.json)")->required();
            app.add_option("-o,--output", a->out, "scene directory to write")->required();
            app.add_option("--config", a->overrides.config,
                           "JSON file overriding any option: the keys of params.json, nested "
                           "(`u4d options` lists them); applied before --set and the flags below");
            app.add_option("--set", a->overrides.assignments,
                           "KEY=VALUE: one option by its dotted key, e.g. joint.rounds=3 "
                           "(repeatable; `u4d options` lists the keys)")
                ->allow_extra_args(false);  // one KEY=VALUE per --set
            AddNamedFlags(app, &a->overrides);
          },
          [=] { return Run(*a); }};
}

}  // namespace u4d::apps
