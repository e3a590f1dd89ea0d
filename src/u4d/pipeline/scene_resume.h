// Whether `u4d run` resumes in a scene directory or recomputes it
// (pipeline.h "Resume"), and the clean start of a run that recomputes.
//
// A scene records what it was computed from: params.json (every option, the
// capture's path and the sources used) and inputs.json (the capture's
// fingerprint, io/input_fingerprint.h). A run resumes only when both equal
// its own; when the same capture's files or the options changed, every stage
// depends on them (all stages read the calibration and the masks), so the
// run recomputes the whole scene; a directory holding another capture's run
// is refused. Never a mix of two runs' results in one scene.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "u4d/io/input_fingerprint.h"
#include "u4d/util/file.h"

namespace u4d {

// What changed since the run in `scene_dir`: "" when it holds no earlier run
// (no params.json) or one with the same result-changing options
// (RunOptions::ResumeKey of `params`) and the same inputs, so that the run
// resumes; else a description naming the first option that differs, or the
// capture's files that changed (the first few of them), and the run must
// recompute everything (RemoveSceneOutputs). Throws u4d::Error when the
// directory holds the run of another capture (another path), naming both.
std::string ResumeChange(const fs::path& scene_dir, const nlohmann::json& params,
                         const InputFingerprint& inputs);

// Removes the temporary files of writes that a killed run left in
// `scene_dir` (util/file.h IsAtomicWriteTemporary), before a run resumes there.
void RemoveInterruptedWrites(const fs::path& scene_dir);

// Removes what an earlier run wrote in `scene_dir` (the files and folders
// io/layout.h names for a scene), so that a run that recomputes everything
// leaves no file of the earlier one (e.g. the meshes of an object that is
// gone). Does nothing unless the directory holds params.json or run.json;
// other files there are kept.
void RemoveSceneOutputs(const fs::path& scene_dir);

}  // namespace u4d
