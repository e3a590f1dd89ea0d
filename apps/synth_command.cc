// `u4d synth`: writes a synthetic capture with full ground truth.
#include <memory>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "apps/data_dir.h"
#include "u4d/io/output_dir.h"
#include "u4d/synth/generate.h"

namespace u4d::apps {

namespace {

struct SynthArgs {
  std::string preset = "handshake";
  std::string out;
  int frames = 0;
  int views = 0;
  int width = 0;
  int height = 0;
  int people = 0;
  uint64_t seed = 1;
  std::string mocap;
  std::string degrade = "preset";
  std::string captured_meshes;
  bool no_meshes = false;
  int clean_plate = 0;
  bool still = false;
  bool keyed = false;
  bool force = false;
  int start_frame = -1;
  std::vector<std::string> props;
};

}  // namespace

// Refuses a non-empty output folder unless --force; with --force a previous
// capture there (capture.json) is removed first, so no stale views or frames
// of it remain in the new one.
void PrepareSynthOutput(const fs::path& out, bool force) {
  OutputDirOptions options;
  options.command = "u4d synth";
  options.force = force;
  options.force_flag = "--force";
  const OutputDirState state = CheckOutputDir(out, options);
  if (state != OutputDirState::kForced || !fs::exists(out / "capture.json")) return;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(out, ec)) {
    fs::remove_all(entry.path(), ec);
    U4D_CHECK(!ec, "u4d synth --output {}: cannot remove {}: {}", out.string(),
              entry.path().string(), ec.message());
  }
}

void PrintSynthSummary(const synth::SynthSummary& s, const std::string& dir) {
  fmt::print(
      "wrote {}: {} views x {} frames, {} people{} in {:.1f} s ({:.2f} frames/s; rendering "
      "and GT flow {:.1f} s)\n",
      dir, s.num_views, s.num_frames, s.num_people,
      s.num_objects > 0 ? fmt::format(" and {} objects", s.num_objects) : "", s.seconds,
      s.num_frames / s.seconds, s.render_seconds);
  fmt::print(
      "initial inputs: {} dropped view-frames, {} merged instances, {} false positives, "
      "{} dropped limbs, {} left/right-swapped 2D poses\n",
      s.dropped_masks, s.merged_instances, s.false_positives, s.dropped_limbs, s.swapped_poses);
}

synth::SynthOptions SynthOptionsFromArgs(const std::string& preset, int frames, int views,
                                         int width, int height, int people, uint64_t seed,
                                         const std::string& mocap,
                                         const std::string& captured_meshes,
                                         const std::string& degrade) {
  synth::SynthOptions o = synth::SynthPreset(preset);
  o.seed = seed;
  o.environment.seed = static_cast<uint32_t>(seed * 7919u + 17u);
  o.render.noise_seed = static_cast<uint32_t>(seed);
  if (frames > 0) o.num_frames = frames;
  if (views > 0) o.rig.num_views = views;
  if (width > 0) o.rig.image_width = width;
  if (height > 0) o.rig.image_height = height;
  if (people > 0) o.num_people = people;
  if (preset == "meetup") o.mocap_bvh = mocap.empty() ? DefaultMocapClip() : fs::path(mocap);
  if (!o.captured.empty())
    o.captured_meshes =
        captured_meshes.empty() ? DefaultCapturedMeshes() : fs::path(captured_meshes);
  if (degrade == "none") {
    o.masks = synth::MaskDegradeOptions::None();
    o.keypoints = synth::KeypointDegradeOptions::None();
  } else if (degrade == "mild") {
    o.masks = synth::MaskDegradeOptions::Mild();
    o.keypoints = synth::KeypointDegradeOptions::Mild();
  } else if (degrade == "harsh") {
    o.masks = synth::MaskDegradeOptions::Harsh();
    o.keypoints = synth::KeypointDegradeOptions::Harsh();
  } else if (degrade == "realistic") {
    o.masks = synth::MaskDegradeOptions::Realistic();
  } else if (degrade == "default") {
    o.masks = synth::MaskDegradeOptions::Default();
    o.keypoints = synth::KeypointDegradeOptions::Default();
  } else {
    U4D_CHECK(degrade == "preset",
              "--degrade must be preset, none, mild, default, realistic or harsh, got '{}'",
              degrade);
  }
  return o;
}

Command MakeSynthCommand() {
  auto a = std::make_shared<SynthArgs>();
  return {"synth", "write a synthetic capture with full ground truth",
          [=](CLI::App& app) {
            std::string presets;
            for (const std::string& n : synth::SynthPresetNames())
              presets += (presets.empty() ? "" : " | ") + n;
            app.add_option("--preset", a->preset, presets)->capture_default_str();
            app.add_option("-o,--output", a->out, "capture directory to write")->required();
            app.add_option("--frames", a->frames, "number of frames (default: the preset's)")
                ->check(CLI::Range(1, 100000));
            app.add_option("--views", a->views, "number of cameras (default 8)")
                ->check(CLI::Range(1, 1000));
            app.add_option("--width", a->width, "image width (default 960)")
                ->check(CLI::Range(16, 16384));
            app.add_option("--height", a->height, "image height (default 540)")
                ->check(CLI::Range(16, 16384));
            app.add_option("--people", a->people, "meetup: number of people (>= 3)")
                ->check(CLI::Range(1, 100));
            app.add_option("--seed", a->seed, "random seed")->capture_default_str();
            app.add_option("--mocap", a->mocap,
                           "meetup: BVH clip (default: the CMU 131 walk shipped in data/mocap)");
            app.add_option("--degrade", a->degrade,
                           "initial-input errors: preset (the preset's own) | none | mild | "
                           "default | realistic | harsh")
                ->capture_default_str();
            app.add_option("--captured-meshes", a->captured_meshes,
                           "realistic presets: the captured mesh sequences (default: "
                           "captured_meshes in the data dir)");
            app.add_flag("--no-meshes", a->no_meshes, "skip the per-frame GT meshes");
            app.add_option("--clean-plate", a->clean_plate,
                           "frames of the empty stage to write as clean plates (background/)")
                ->check(CLI::NonNegativeNumber);
            app.add_flag("--still", a->still, "the people stand still (the first frame's pose)");
            app.add_flag("--keyed", a->keyed,
                         "a green-screen stage: keyed backdrop, spill on the people, floor "
                         "shadows");
            app.add_flag("--force", a->force,
                         "write into a non-empty folder (a previous capture there is replaced)");
            app.add_option("--start-frame", a->start_frame,
                           "first script frame of the capture (-1: the window centred on the "
                           "first handshake)")
                ->capture_default_str();
            app.add_option("--props", a->props,
                           "objects the procedural people hold, the i-th by person i's left "
                           "hand: box | ball (default: the preset's; synth/props.h)")
                ->delimiter(',');
          },
          [=] {
            PrepareSynthOutput(a->out, a->force);
            synth::SynthOptions o =
                SynthOptionsFromArgs(a->preset, a->frames, a->views, a->width, a->height, a->people,
                                     a->seed, a->mocap, a->captured_meshes, a->degrade);
            o.write_meshes = !a->no_meshes;
            o.clean_plate_frames = a->clean_plate;
            o.still_people = a->still;
            if (a->keyed) UseKeyedStage(&o);
            o.start_frame = a->start_frame;
            if (!a->props.empty()) o.props = synth::PropsFromNames(a->props);
            PrintSynthSummary(synth::WriteSyntheticCapture(o, a->out, /*progress=*/true), a->out);
            return 0;
          }};
}

}  // namespace u4d::apps
