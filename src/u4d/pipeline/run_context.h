// What the stages of `u4d run` (pipeline.cc, early_stages.h) share: the
// capture, the options, the frames run, the inputs used and the run log.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/pipeline/run_log.h"
#include "u4d/pipeline/run_options.h"

namespace u4d {

// Everything the stages share. Frames run are [f0, f1); per-frame vectors
// are indexed by k = frame - f0.
struct RunContext {
  const Capture& cap;
  fs::path out;
  const RunOptions& o;
  int f0 = 0, f1 = 0;
  std::vector<std::string> names;
  MaskSource masks = MaskSource::kGiven;
  PoseSource poses = PoseSource::kNone;
  RunLog log;
  FrameReader reader;
  std::map<int, std::string> classes;  // object id -> class (object_classes.h)

  int NumFrames() const { return f1 - f0; }
  int NumViews() const { return cap.NumViews(); }
  std::vector<Camera> Cameras(int frame) const {
    std::vector<Camera> cams;
    for (const CaptureView& v : cap.views) cams.push_back(v.CameraAt(frame));
    return cams;
  }
  // Frame `frame` continues frame - 1 in time (no cut, io/capture.h).
  bool Continues(int frame) const { return ContinuesFrom(cap, frame, o.max_frame_gap_s); }
  // The run's frames [f0, f1) split at the cuts, and into pieces of at most
  // `max_frames`: [first, last) per piece.
  std::vector<std::pair<int, int>> Shots(int max_frames = std::numeric_limits<int>::max()) const {
    std::vector<std::pair<int, int>> shots;
    for (int f = f0; f < f1; ++f) {
      if (f == f0 || !Continues(f) || f - shots.back().first == max_frames)
        shots.emplace_back(f, f);
      shots.back().second = f + 1;
    }
    return shots;
  }
};

// Frame f of every view, read in parallel.
std::vector<cv::Mat> ReadViews(RunContext& c, int f);

}  // namespace u4d
