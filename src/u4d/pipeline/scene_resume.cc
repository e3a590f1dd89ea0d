#include "u4d/pipeline/scene_resume.h"

#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "u4d/io/layout.h"
#include "u4d/pipeline/run_options.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

// The first difference between the options (and sources) of the earlier
// run's params.json and `params`, as "op /path", or "" when they are the same.
std::string OptionsChange(const nlohmann::json& earlier, const nlohmann::json& params) {
  const nlohmann::json before = RunOptions::ResumeKey(earlier);
  const nlohmann::json now = RunOptions::ResumeKey(params);
  if (before == now) return "";
  const nlohmann::json diff = nlohmann::json::diff(before, now);
  return fmt::format("other options ({} {})", diff.at(0).value("op", ""),
                     diff.at(0).value("path", ""));
}

// The capture's files that changed since the run in `scene_dir` (the first
// few), or "" when none did.
std::string InputsChange(const fs::path& scene_dir, const InputFingerprint& inputs) {
  const fs::path path = scene_dir / layout::SceneInputs();
  if (!fs::exists(path))
    return fmt::format("no {} (written by an earlier version)", layout::SceneInputs().string());
  const std::vector<std::string> changed =
      ChangedInputs(FingerprintFromJson(ReadJsonFile(path), path.string()), inputs);
  if (changed.empty()) return "";
  constexpr size_t kListed = 5;
  std::vector<std::string> listed(changed.begin(),
                                  changed.begin() + std::min(changed.size(), kListed));
  const std::string more =
      changed.size() > kListed ? fmt::format(" and {} more", changed.size() - kListed) : "";
  return fmt::format("other inputs ({}{} changed)", fmt::join(listed, ", "), more);
}

}  // namespace

std::string ResumeChange(const fs::path& scene_dir, const nlohmann::json& params,
                         const InputFingerprint& inputs) {
  if (!fs::exists(scene_dir / layout::SceneParams())) return "";
  const nlohmann::json earlier = ReadJsonFile(scene_dir / layout::SceneParams());
  const std::string before = earlier.value("capture", std::string());
  const std::string now = params.value("capture", std::string());
  U4D_CHECK(before == now,
            "{} holds the run of another capture ({}, not {}); write to a new directory, or run "
            "with --no-resume to replace that run",
            scene_dir.string(), before, now);
  std::string change = OptionsChange(earlier, params);
  if (change.empty()) change = InputsChange(scene_dir, inputs);
  return change;
}

void RemoveInterruptedWrites(const fs::path& scene_dir) {
  std::error_code ec;
  if (!fs::is_directory(scene_dir, ec)) return;
  std::vector<fs::path> stale;
  for (auto it = fs::recursive_directory_iterator(scene_dir, ec); !ec && it != fs::end(it);
       it.increment(ec))
    if (it->is_regular_file(ec) && IsAtomicWriteTemporary(it->path())) stale.push_back(it->path());
  U4D_CHECK(!ec, "{}: cannot list its files ({})", scene_dir.string(), ec.message());
  for (const fs::path& path : stale) {
    fs::remove(path, ec);
    U4D_CHECK(!ec, "{}: cannot remove this file of an interrupted run ({})", path.string(),
              ec.message());
  }
}

void RemoveSceneOutputs(const fs::path& scene_dir) {
  if (!fs::exists(scene_dir / layout::SceneParams()) &&
      !fs::exists(scene_dir / layout::SceneRunLog()))
    return;
  // The first component of every path io/layout.h names in a scene; the
  // files that mark a run go last, so that an interrupted removal leaves a
  // folder still recognised as a run's.
  const std::vector<fs::path> paths = {layout::SceneIndex(),
                                       layout::SceneCalibration(),
                                       layout::SceneKeyframes(),
                                       layout::SceneEval(),
                                       layout::SceneConsistency(),
                                       layout::SceneInstances("v", 0),
                                       layout::SceneDepth("v", 0),
                                       layout::SceneFlow("v", 0),
                                       layout::ScenePicture("image", "v", 0),
                                       layout::ScenePoses3d(0),
                                       layout::SceneTracks("v"),
                                       layout::SceneMesh(1, 0),
                                       layout::SceneSegmentDir(0),
                                       layout::SceneInitialMask("v", 0),
                                       layout::SceneInputs(),
                                       layout::SceneRunLog(),
                                       layout::SceneParams()};
  for (const fs::path& path : paths) {
    const fs::path top = scene_dir / *path.begin();
    std::error_code ec;
    fs::remove_all(top, ec);
    U4D_CHECK(!ec, "{}: cannot remove the earlier run's output ({})", top.string(), ec.message());
  }
}

}  // namespace u4d
