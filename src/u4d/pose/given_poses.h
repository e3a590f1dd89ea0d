// Given 3D poses (paper Section 2.1.1 allows skeletons from an external
// source instead of the multi-view estimate): a pass-through reader of the
// capture's poses3d/<frame>.json files (io/poses.h format, H36M-17, metres).
#pragma once

#include <vector>

#include "u4d/io/poses.h"
#include "u4d/util/file.h"

namespace u4d {

// Reads poses3d/<frame>.json (io/layout.h) for frames 0..num_frames-1 of the
// capture at `capture_root`; the ids in the files are kept. A missing frame
// file throws u4d::Error naming it, unless `allow_missing`, when the frame
// has no people. Throws on num_frames < 0.
std::vector<std::vector<Pose3d>> ReadGivenPoses3d(const fs::path& capture_root, int num_frames,
                                                  bool allow_missing = false);

}  // namespace u4d
