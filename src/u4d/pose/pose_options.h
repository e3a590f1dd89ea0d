// The fields of the options structs of multi-view 3D pose (multiview_pose.h, pose_tracking.h,
// pose_smoothing.h), each declared once (name, help; the default is the struct's initialiser):
// params.json, `u4d run --config` / `--set` and docs/options.md come from these (util/options.h).
// Check() stays with each struct.
#pragma once

#include "u4d/pose/multiview_pose.h"
#include "u4d/pose/pose_smoothing.h"
#include "u4d/pose/pose_tracking.h"
#include "u4d/util/options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, MultiViewPoseOptions* o);
void DeclareOptions(OptionRegistry& r, PoseTrackerOptions* o);
void DeclareOptions(OptionRegistry& r, PoseSmoothingOptions* o);

}  // namespace u4d
