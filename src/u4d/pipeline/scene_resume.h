// Whether `u4d run` may resume in a scene directory (pipeline.h "Resume"),
// and the clean start of a run that recomputes everything.
//
// A scene records what it was computed from: params.json (every option, the
// capture's path and the sources used) and inputs.json (the capture's
// fingerprint, io/input_fingerprint.h). A run resumes only when both equal
// its own; anything else would mix two runs' results in one scene.
#pragma once

#include <nlohmann/json.hpp>

#include "u4d/io/input_fingerprint.h"
#include "u4d/util/file.h"

namespace u4d {

// Returns when `scene_dir` holds no earlier run (no params.json) or one with
// the same result-changing options (RunOptions::ResumeKey of `params`) and
// the same inputs. Otherwise throws u4d::Error naming the first option that
// differs, or the capture's files that changed (the first few of them), and
// suggesting a new directory or --no-resume.
void CheckResumable(const fs::path& scene_dir, const nlohmann::json& params,
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
