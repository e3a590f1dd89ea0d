// The synthetic worlds the benches run on, by preset name: the presets the
// method was developed on and the realistic ones it was not tuned on
// (captured performers, docs/synthetic.md), so that a change that helps one
// world and hurts the other is seen in the same run.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "u4d/synth/generate.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/file.h"

namespace u4d::bench {

using ::u4d::DataDir;

// Whether `preset` can be synthesised here (the realistic presets need the
// captured meshes of the shared data; the meetup's CMU clip is shipped).
inline bool WorldAvailable(const std::string& preset) {
  if (preset.rfind("realistic", 0) == 0) return fs::is_directory(DataDir() / "captured_meshes");
  return true;
}

// The worlds of `presets` that can be synthesised here, in order; prints
// "<preset>: skipped (no shared data at ...)" for each of the others.
inline std::vector<std::string> AvailableWorlds(const std::vector<std::string>& presets) {
  std::vector<std::string> available;
  for (const std::string& preset : presets) {
    if (WorldAvailable(preset))
      available.push_back(preset);
    else
      std::printf("%s: skipped (no shared data at %s)\n", preset.c_str(),
                  DataDir().string().c_str());
  }
  return available;
}

// The preset at a bench's size, without GT meshes (set write_meshes for them).
inline synth::SynthOptions World(const std::string& preset, int views, int width, int height,
                                 int frames) {
  synth::SynthOptions o = preset == "handshake"
                              ? synth::SmallHandshakeOptions(views, width, height, frames)
                              : synth::SynthPreset(preset);
  o.rig.num_views = views;
  o.rig.image_width = width;
  o.rig.image_height = height;
  o.num_frames = frames;
  o.write_meshes = false;
  if (preset == "meetup") o.mocap_bvh = ShippedDataFile(fs::path("mocap") / "scaled_131_02.bvh");
  if (!o.captured.empty()) o.captured_meshes = DataDir() / "captured_meshes";
  return o;
}

}  // namespace u4d::bench
