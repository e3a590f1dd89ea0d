#include "u4d/io/layout.h"

#include <fmt/format.h>

namespace u4d::layout {

std::string FrameName(int frame) { return fmt::format("{:06d}", frame); }

fs::path Image(const std::string& view, int frame) {
  return fs::path("images") / view / (FrameName(frame) + ".png");
}
fs::path Mask(const std::string& view, int frame) {
  return fs::path("masks") / view / (FrameName(frame) + ".png");
}
fs::path MaskInfo(const std::string& view, int frame) {
  return fs::path("masks") / view / (FrameName(frame) + ".json");
}
fs::path Poses2d(const std::string& view, int frame) {
  return fs::path("poses2d") / view / (FrameName(frame) + ".json");
}
fs::path Poses3d(int frame) { return fs::path("poses3d") / (FrameName(frame) + ".json"); }
fs::path CleanPlateDir() { return "background"; }

fs::path GtInstances(const std::string& view, int frame) {
  return fs::path("gt/instances") / view / (FrameName(frame) + ".png");
}
fs::path GtInstancesInfo(const std::string& view, int frame) {
  return fs::path("gt/instances") / view / (FrameName(frame) + ".json");
}
fs::path GtDepth(const std::string& view, int frame) {
  return fs::path("gt/depth") / view / (FrameName(frame) + ".pfm");
}
fs::path GtFlow(const std::string& view, int frame) {
  return fs::path("gt/flow") / view / (FrameName(frame) + ".flo");
}
fs::path GtFlowValid(const std::string& view, int frame) {
  return fs::path("gt/flow_valid") / view / (FrameName(frame) + ".png");
}
fs::path GtVisibility(const std::string& view, int frame) {
  return fs::path("gt/visibility") / view / (FrameName(frame) + ".json");
}
fs::path GtJoints3d(int frame) { return fs::path("gt/joints3d") / (FrameName(frame) + ".json"); }
fs::path GtContacts() { return "gt/contacts.json"; }

fs::path GtMesh(int object_id, int frame) {
  return fs::path("gt/meshes") / fmt::format("{:02d}", object_id) / (FrameName(frame) + ".ply");
}

fs::path SceneIndex() { return "scene.json"; }
fs::path SceneCalibration() { return "calibration.json"; }
fs::path SceneParams() { return "params.json"; }
fs::path SceneInputs() { return "inputs.json"; }
fs::path SceneKeyframes() { return "keyframes.json"; }
fs::path SceneEval() { return "eval.json"; }
fs::path SceneConsistency() { return "consistency.json"; }
fs::path SceneInstances(const std::string& view, int frame) {
  return fs::path("instances") / view / (FrameName(frame) + ".png");
}
fs::path SceneInstancesInfo(const std::string& view, int frame) {
  return fs::path("instances") / view / (FrameName(frame) + ".json");
}
fs::path SceneDepth(const std::string& view, int frame) {
  return fs::path("depth") / view / (FrameName(frame) + ".pfm");
}
fs::path SceneFlow(const std::string& view, int frame) {
  return fs::path("flow") / view / (FrameName(frame) + ".flo");
}
fs::path ScenePicture(const std::string& kind, const std::string& view, int frame) {
  return fs::path("pictures") / kind / view / (FrameName(frame) + ".png");
}
fs::path ScenePoses3d(int frame) { return fs::path("poses3d") / (FrameName(frame) + ".json"); }
fs::path SceneTracks(const std::string& view) { return fs::path("tracks") / (view + ".json"); }
fs::path SceneMesh(int object_id, int frame) {
  return fs::path("meshes") / fmt::format("{:02d}", object_id) / (FrameName(frame) + ".ply");
}
fs::path SceneSegmentDir(int segment) {
  return fs::path("segments") / fmt::format("{:02d}", segment);
}

fs::path SceneInitialMask(const std::string& view, int frame) {
  return fs::path("initial/masks") / view / (FrameName(frame) + ".png");
}
fs::path SceneInitialObjects(int frame) {
  return fs::path("initial/objects") / (FrameName(frame) + ".json");
}
fs::path SceneRunLog() { return "run.json"; }

}  // namespace u4d::layout
