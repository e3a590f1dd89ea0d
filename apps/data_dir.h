// The data the `u4d` command falls back on (util/data_dir.h): the CMU clip it
// ships, and the shared real data of the realistic presets.
#pragma once

#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/file.h"

namespace u4d::apps {

// The meetup preset's CMU clip, shipped with u4d (data/mocap).
inline fs::path DefaultMocapClip() {
  return ShippedDataFile(fs::path("mocap") / "scaled_131_02.bvh");
}

// The captured mesh sequences of the realistic synthetic presets: real data
// that is not shipped (../shared/data/captured_meshes or $U4D_DATA_DIR).
inline fs::path DefaultCapturedMeshes() {
  const fs::path dir = DataDir() / "captured_meshes";
  U4D_CHECK(fs::is_directory(dir),
            "the realistic presets need captured mesh sequences, not shipped with u4d: folder {} "
            "not found (pass --captured-meshes <dir> or set U4D_DATA_DIR to a folder holding "
            "captured_meshes)",
            dir.string());
  return dir;
}

}  // namespace u4d::apps
