// The native capture: what U4D reads as input. The layout on disk is
// specified in docs/formats.md; this header is its in-memory form.
//
//   <capture>/capture.json       manifest (name, scene type, fps, frames, views, classes)
//   <capture>/calibration.json   one camera per view; per frame for moving cameras
//   <capture>/images/<view>/<frame:06d>.{png,jpg}   or   a video file per view
//   <capture>/masks/...          optional initial instance masks     (io/layout.h)
//   <capture>/poses2d/...        optional 2D keypoints
//   <capture>/poses3d/...        optional 3D poses
//   <capture>/gt/...             optional ground truth
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "u4d/geometry/camera.h"
#include "u4d/util/file.h"

namespace u4d {

enum class SceneType { kIndoor, kOutdoor };
std::string ToString(SceneType type);
SceneType SceneTypeFromString(const std::string& s, const std::string& context);

// Where a view's frames come from.
struct FrameSource {
  enum class Kind { kImages, kVideo };
  Kind kind = Kind::kImages;
  // kImages: a pattern relative to the capture root with one "{}"-style
  // field for the frame index, e.g. "images/cam00/{:06d}.png".
  // kVideo: a video file relative to the capture root.
  std::string path;
  // kImages only: explicit file names (relative to the root), one per frame,
  // used when the files are not numbered 0..N-1 (e.g. imported datasets).
  std::vector<std::string> files;
  // Index in the source of the capture's frame 0 (video frame or pattern index).
  int first_index = 0;
};

struct CaptureView {
  std::string name;
  // One camera for a static view; one per frame for a moving camera.
  std::vector<Camera> cameras;
  FrameSource source;

  bool IsMoving() const { return cameras.size() > 1; }
  const Camera& CameraAt(int frame) const;
};

struct Capture {
  fs::path root;  // directory holding capture.json (set by ReadCapture)
  std::string name;
  SceneType scene = SceneType::kIndoor;
  double fps = 25.0;
  int num_frames = 0;
  std::vector<CaptureView> views;
  // Class names; a class id k >= 1 in masks refers to classes[k-1].
  std::vector<std::string> classes = {"person"};
  // The frame number in the source of each capture frame (strictly
  // increasing), as importers find it in the file names; empty when the
  // frames are consecutive. Gaps mark cuts in time (ContinuesFrom).
  std::vector<int64_t> source_frames;

  int NumViews() const { return static_cast<int>(views.size()); }
  int ViewIndex(const std::string& view_name) const;  // throws when unknown
  // Absolute path of the image of `view` at `frame` (kImages sources only).
  fs::path ImagePath(int view, int frame) const;

  // Throws u4d::Error when the capture is inconsistent: no views, duplicate
  // names, a camera that fails Camera::Check, a moving view whose camera count
  // differs from num_frames, a non-positive fps or frame count, source_frames
  // neither empty nor num_frames increasing non-negative numbers.
  void Check(const std::string& context) const;
};

// Whether `frame` continues `frame - 1` in time: false for frame 0 and where
// the source frames of the two lie more than `max_gap_s` seconds apart (at
// capture.fps), e.g. the instants of a capture assembled from a long
// recording. Nothing temporal (flow, tracks, key-frame segments, object
// links) crosses such a cut. Throws when `frame` is out of range.
bool ContinuesFrom(const Capture& capture, int frame, double max_gap_s);

// Reads capture.json and calibration.json. Frame files are checked lazily by
// the frame reader, not here, so a missing frame names itself when read.
Capture ReadCapture(const fs::path& dir);

// Writes capture.json and calibration.json into `dir` (atomically).
void WriteCapture(const Capture& capture, const fs::path& dir);

// Calibration alone, as in calibration.json: {"cameras": [...]} in view order.
nlohmann::json CalibrationToJson(const Capture& capture);
// Parses one camera record ({"width","height","K","dist","R","t"}).
Camera CameraFromJson(const nlohmann::json& j, const std::string& context);
nlohmann::json CameraToJson(const Camera& camera);

}  // namespace u4d
