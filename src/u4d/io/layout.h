// Relative paths of everything in a capture and in a 4D scene, in one place.
// docs/formats.md documents the same layout for people; keep them in step.
// Frames are numbered from 0 and written with six digits.
#pragma once

#include <string>

#include "u4d/util/file.h"

namespace u4d::layout {

std::string FrameName(int frame);  // "000042"

// Capture inputs (relative to the capture root).
fs::path Image(const std::string& view, int frame);     // images/<view>/<frame>.png
fs::path Mask(const std::string& view, int frame);      // masks/<view>/<frame>.png
fs::path MaskInfo(const std::string& view, int frame);  // masks/<view>/<frame>.json
fs::path Poses2d(const std::string& view, int frame);   // poses2d/<view>/<frame>.json
fs::path Poses3d(int frame);                            // poses3d/<frame>.json

// Ground truth (relative to the capture root).
fs::path GtInstances(const std::string& view, int frame);      // gt/instances/<view>/<frame>.png
fs::path GtInstancesInfo(const std::string& view, int frame);  // gt/instances/<view>/<frame>.json
fs::path GtDepth(const std::string& view, int frame);          // gt/depth/<view>/<frame>.pfm
fs::path GtFlow(const std::string& view, int frame);           // gt/flow/<view>/<frame>.flo
fs::path GtFlowValid(const std::string& view, int frame);      // gt/flow_valid/<view>/<frame>.png
fs::path GtVisibility(const std::string& view, int frame);     // gt/visibility/<view>/<frame>.json
fs::path GtJoints3d(int frame);                                // gt/joints3d/<frame>.json
fs::path GtMesh(int object_id, int frame);                     // gt/meshes/<id>/<frame>.ply

}  // namespace u4d::layout
