// The shared real data the `u4d` command falls back on (util/data_dir.h).
#pragma once

#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/file.h"

namespace u4d::apps {

inline fs::path DefaultMocapClip() {
  const fs::path clip = DataDir() / "mocap_cmu131" / "scaled_131_02.bvh";
  U4D_CHECK(fs::exists(clip),
            "motion capture clip not found: {} (set U4D_DATA_DIR or pass --mocap)", clip.string());
  return clip;
}

// The captured mesh sequences of the realistic synthetic presets.
inline fs::path DefaultCapturedMeshes() {
  const fs::path dir = DataDir() / "captured_meshes";
  U4D_CHECK(fs::is_directory(dir),
            "captured mesh sequences not found: {} (set U4D_DATA_DIR or pass --captured-meshes)",
            dir.string());
  return dir;
}

}  // namespace u4d::apps
