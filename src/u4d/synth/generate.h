// Writes a synthetic capture with complete ground truth (docs/synthetic.md,
// layout in docs/formats.md): people from people.h, static scene from
// environment.h, a camera rig from rig.h, rendered by render.h, with the
// degraded detector inputs of degrade.h as the capture's initial masks and
// 2D keypoints.
//
// Streaming: only frames t and t+1 are in memory at any time, so the length
// of the sequence does not change the memory used. Deterministic in `seed`.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "u4d/synth/captured.h"
#include "u4d/synth/degrade.h"
#include "u4d/synth/environment.h"
#include "u4d/synth/image_effects.h"
#include "u4d/synth/props.h"
#include "u4d/synth/render.h"
#include "u4d/synth/rig.h"
#include "u4d/util/file.h"

namespace u4d::synth {

struct SynthOptions {
  std::string preset = "handshake";  // one of SynthPresetNames()
  std::string name;                  // capture name; empty = the preset's name
  int num_frames = 50;               // frames to write
  // The people's script lasts at least script_seconds (the handshake needs
  // >= 4 s, the meetup >= 5 s); the capture is the window of num_frames
  // starting at script frame start_frame. start_frame < 0 centres the window
  // on the first handshake (or starts at 0 when there is none).
  double script_seconds = 6.0;
  int start_frame = -1;
  double fps = 25.0;         // frames per second
  int num_people = 3;        // meetup only: people in the scene (>= 3)
  uint64_t seed = 1;         // seeds people, textures, noise and degradation
  fs::path mocap_bvh;        // meetup: CMU clip driving one person (required there)
  bool write_meshes = true;  // write gt/meshes/<id>/<frame>.ply
  // Frames of the empty stage written as each view's clean plate
  // (background/<view>/<frame>.png, io/clean_plate.h), with their own sensor
  // noise; 0 = none. Static rigs only.
  int clean_plate_frames = 0;
  // Every frame shows the people as in the window's first frame: people who
  // stand entirely still (a background from the capture's frames holds them).
  bool still_people = false;
  int png_compression = 1;         // 0-9; low is fast, high is small
  RigOptions rig;                  // cameras (num_views, resolution, moving)
  EnvironmentOptions environment;  // floor and background
  RenderOptions render;            // lighting and sensor noise
  FlowOptions flow;                // visibility tolerance of the GT flow
  MaskDegradeOptions masks = MaskDegradeOptions::Default();              // initial masks
  KeypointDegradeOptions keypoints = KeypointDegradeOptions::Default();  // 2D keypoints
  ImageEffectsOptions effects;  // motion blur and floor shadows (off by default)

  // Captured performers (captured.h), people after the procedural ones (their
  // instance ids follow). A relative source is read from captured_meshes.
  std::vector<CapturedPerformerOptions> captured;
  fs::path captured_meshes;  // the shared captured_meshes folder (realistic presets)
  // With two or more captured performers, the second is moved along the line
  // from the first's position to its own so that their closest approach over
  // the capture is this many metres: they touch at least once. < 0 keeps the
  // positions.
  double captured_touch_gap = -1;
  // Rigid objects the procedural people hold (props.h), objects after the
  // people (their instance ids follow), each of its own class.
  std::vector<PropOptions> props;

  void Check() const;  // throws u4d::Error on bad values or an unknown preset
};

// The defaults of a named preset:
//   handshake         2 people approach, shake hands, step apart; 8 static views, indoor
//   meetup            3+ people meet (one driven by real CMU mocap); 8 static views, outdoor
//   moving-cameras    the handshake seen by 8 cameras that orbit and bob
//   realistic         2 captured performers (a dance, a jump) who touch; a real
//                     detector's failures (MaskDegradeOptions::Realistic), sensor
//                     noise, exposure differing between cameras, motion blur,
//                     floor shadows; 8 static views, indoor (needs captured_meshes)
//   realistic-moving  the same seen by 8 cameras that orbit and bob
//   objects           the handshake, one person carrying a box in the left
//                     hand, the other bouncing a ball with the left hand;
//                     the detector merges each object with its holder at
//                     times (classes "person", "box", "ball")
// Throws u4d::Error for an unknown name, listing the known ones.
SynthOptions SynthPreset(const std::string& preset);
const std::vector<std::string>& SynthPresetNames();

struct SynthSummary {
  int num_frames = 0;
  int num_views = 0;
  int num_people = 0;
  int num_objects = 0;        // props
  double seconds = 0;         // wall time of the whole generation
  double render_seconds = 0;  // of which rendering and GT flow
  int dropped_masks = 0;      // view-frames with no initial mask
  int merged_instances = 0;   // touching people merged into one instance
  int false_positives = 0;    // spurious detections added
  int dropped_limbs = 0;      // thin limbs cut from masks
  int swapped_poses = 0;      // 2D poses with left/right swapped
};

// Writes the capture into `dir` (created; existing files are overwritten).
// Shows a progress bar when `progress` is set and stderr is a terminal.
SynthSummary WriteSyntheticCapture(const SynthOptions& options, const fs::path& dir,
                                   bool progress = false);

// Makes `o`'s stage a keyed one (a green screen): EnvironmentOptions::keyed,
// spill of the backdrop's colour on the people (ImageEffectsOptions spill,
// strength 0.3) and soft floor shadows (strength at least 0.45).
void UseKeyedStage(SynthOptions* o);

// For tests and benchmarks: the handshake preset at a small size, without
// GT meshes (set write_meshes to get them).
SynthOptions SmallHandshakeOptions(int num_views, int width, int height, int num_frames);
// The same for the realistic preset (its views; the captured performances
// read from `captured_meshes`).
SynthOptions SmallRealisticOptions(const fs::path& captured_meshes, int width, int height,
                                   int num_frames);

// Writes `options` into a fresh directory <tmp>/u4d_<name>_<pid> (one per
// process, since ctest runs the tests of a suite in separate processes, in
// parallel) and returns it; `summary` receives the writer's summary if given.
fs::path WriteCaptureToTempDir(const std::string& name, const SynthOptions& options,
                               SynthSummary* summary = nullptr);

}  // namespace u4d::synth
