// The fields of the options structs of features, sparse points and tracks, each declared once
// (name, help; the default is the struct's initialiser): params.json,
// `u4d run --config` / `--set` and docs/options.md come from these
// (util/options.h). Check() stays with each struct.
#pragma once

#include "u4d/features/keypoints.h"
#include "u4d/features/multiview_matching.h"
#include "u4d/features/object_regions.h"
#include "u4d/features/sparse_points.h"
#include "u4d/features/temporal_tracks.h"
#include "u4d/util/options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, SparseFrameOptions* o);
void DeclareOptions(OptionRegistry& r, SparseOptions* o);
void DeclareOptions(OptionRegistry& r, KeypointOptions* o);
void DeclareOptions(OptionRegistry& r, MatchingOptions* o);
void DeclareOptions(OptionRegistry& r, ObjectRegionOptions* o);
void DeclareOptions(OptionRegistry& r, SilhouettePointOptions* o);
void DeclareOptions(OptionRegistry& r, TemporalTrackOptions* o);

}  // namespace u4d
