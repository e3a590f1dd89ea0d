// run.json of a 4D scene: what a run has finished, so that an interrupted run
// resumes without redoing it, and the time and memory each stage took.
//
//   {"format": "u4d-run", "capture": "/path", "masks": "given", "poses": "from2d",
//    "stages_done": ["poses", "initial", ...], "segments_done": [0, 1],
//    "stages": [{"name": "joint", "seconds": 12.5, "peak_rss_mb": 820, "items": 48}],
//    "segment_parts": [{"name": "solve", "seconds": 10.1}, ...],
//    "empty_frames": [3, 4]}
//
// segment_parts splits the "segments" stage's time (summed over its frames)
// into its parts, in the order they first ran: "inputs" (reading the frames
// and setting up each view's problem), "solve" (the joint view solves, all
// views at once), "flow_consensus" (the views' flows combined,
// fusion/flow_consensus.h), "maps" (the per-view label, depth and flow maps
// at camera size, written), "fusion" (one mesh per object), "mesh_depth"
// (the meshes' depth into the maps, pipeline/mesh_depth.h), "scene_flow"
// (tracking the segment's meshes to the next frame) and "animation" (writing
// the segment's glTF). It
// is optional when read (runs written before it have none), as is
// empty_frames: the frames in which the initial stage found no object in any
// view (they stay empty in the scene).
//
// A stage or segment is recorded only after every file it writes exists
// (each file is itself written atomically), so a recorded one is complete.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "u4d/util/file.h"

namespace u4d {

struct StageReport {
  std::string name;
  double seconds = 0;
  int64_t peak_rss_bytes = 0;  // the stage's peak resident memory (util/timer.h)
  int items = 0;               // frames, views or segments processed
};

// Time spent in one part of a stage.
struct PartTime {
  std::string name;
  double seconds = 0;
};

struct RunLog {
  std::string capture;
  std::string masks, poses;  // the sources used (run_options.h names)
  std::vector<std::string> stages_done;
  std::set<int> segments_done;
  std::vector<StageReport> stages;      // this run's stages, in order
  std::vector<PartTime> segment_parts;  // where the "segments" stage's time went
  std::vector<int> empty_frames;        // frames with no object in any view (initial stage)

  bool StageDone(const std::string& name) const;
  void MarkStage(const std::string& name);  // appends once
  // Adds or accumulates (resumed runs add to an existing entry).
  void AddReport(const StageReport& report);
  // Adds `seconds` to segment part `name` (appended the first time).
  void AddSegmentPart(const std::string& name, double seconds);
  // A table: stage, seconds, peak memory, items.
  std::string FormatTable() const;
};

void WriteRunLog(const fs::path& scene_dir, const RunLog& log);
// Throws u4d::Error naming the file when it is not a u4d-run file.
RunLog ReadRunLog(const fs::path& scene_dir);

}  // namespace u4d
