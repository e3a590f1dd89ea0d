// scene.json: the index of a 4D scene written by `u4d run` (or by
// `u4d scene-from-gt`), read by the web viewer (viewer/) and by tools. It
// lists what the scene holds so that a reader never has to probe the disk:
// frames, views with their image sizes, objects with their display colours,
// key-frames with the frames they stand for, temporal segments with their
// glTF files, which picture kinds exist, and which pipeline stages are done.
// Paths of the files follow io/layout.h; scene.json also carries them as
// templates ("files") so that the viewer does not hard-code the layout.
// docs/formats.md ("The 4D scene") documents the JSON schema.
//
//   {"format": "u4d-scene", "version": 1, "name": "handshake", "fps": 25,
//    "frames": [0, 1, ...],
//    "views": [{"name": "cam00", "width": 960, "height": 540}],
//    "objects": [{"id": 1, "class": "person", "color": [r, g, b]}],
//    "keyframes": [{"frame": 0, "members": [0, 1, 2, ...]}],
//    "segments": [{"index": 0, "keyframe": 0, "first": 0, "last": 9,
//                  "dir": "segments/00", "glb": {"1": "segments/00/1.glb"}}],
//    "pictures": ["image", "instances", "depth", "flow"],
//    "has_meshes": true, "has_poses3d": true, "has_tracks": false,
//    "has_eval": false, "stages_done": ["masks", "depth"],
//    "skeleton": {"name": "h36m17", "bones": [[0, 1], ...]},
//    "files": {"mesh": "meshes/{object}/{frame}.ply", ...}}
//
// Writing is atomic (util/file.h). Reading throws u4d::Error naming the file
// and the field on a missing or ill-typed field, an unknown format, frames
// that are not strictly increasing, duplicate view names or object ids, an
// object id < 1, a colour component outside [0, 255], a key-frame or segment
// frame that is not among the frames, or a segment with first > last.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "u4d/io/poses.h"
#include "u4d/util/file.h"

namespace u4d {

struct SceneViewInfo {
  std::string name;  // the capture's view name
  int width = 0;     // pixels of the camera (the scene's per-view maps have this size)
  int height = 0;
};

struct SceneObjectInfo {
  int id = 0;                              // instance id, >= 1, the same in every view and frame
  std::string class_name = "person";       // JSON field "class"
  std::array<uint8_t, 3> rgb = {0, 0, 0};  // display colour (InstanceColor(id) by default)
};

struct SceneKeyframeInfo {
  int frame = 0;             // the key-frame
  std::vector<int> members;  // frames it stands for (its own one included), increasing
};

struct SceneSegmentInfo {
  int index = 0;     // k of segments/<kk>/
  int keyframe = 0;  // its key-frame (a frame id)
  int first = 0;     // first and last frame covered, inclusive
  int last = 0;
  std::string dir;                 // relative to the scene root, layout::SceneSegmentDir
  std::map<int, std::string> glb;  // object id -> relative path of its .glb
};

struct SceneIndex {
  std::string name;
  double fps = 25.0;
  std::vector<int> frames;  // frame ids, strictly increasing
  std::vector<SceneViewInfo> views;
  std::vector<SceneObjectInfo> objects;
  std::vector<SceneKeyframeInfo> keyframes;
  std::vector<SceneSegmentInfo> segments;
  // Picture kinds present under pictures/<kind>/: "image", "instances",
  // "depth", "flow" (see layout::ScenePicture).
  std::vector<std::string> pictures;
  bool has_meshes = false;               // meshes/<id>/<frame>.ply
  bool has_poses3d = false;              // poses3d/<frame>.json
  bool has_tracks = false;               // tracks/<view>.json
  bool has_eval = false;                 // eval.json
  std::vector<std::string> stages_done;  // pipeline stages finished, in order

  // Throws u4d::Error (prefixed by `context`) on the inconsistencies listed
  // at the top of this file.
  void Check(const std::string& context) const;
};

nlohmann::json SceneIndexToJson(const SceneIndex& index);
SceneIndex SceneIndexFromJson(const nlohmann::json& j, const std::string& context);

// <dir>/scene.json. Write checks first (throws on an inconsistent index).
void WriteSceneIndex(const fs::path& dir, const SceneIndex& index);
SceneIndex ReadSceneIndex(const fs::path& dir);

}  // namespace u4d
