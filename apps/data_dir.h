// Where the shared real data lives: $U4D_DATA_DIR if set, else the
// ../shared/data beside the source checkout this binary was built from.
#pragma once

#include <cstdlib>

#include "u4d/util/check.h"
#include "u4d/util/file.h"

#ifndef U4D_SHARED_DATA_DIR
#define U4D_SHARED_DATA_DIR ""
#endif

namespace u4d::apps {

inline fs::path DataDir() {
  const char* env = std::getenv("U4D_DATA_DIR");
  return env != nullptr && *env != '\0' ? fs::path(env) : fs::path(U4D_SHARED_DATA_DIR);
}

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
