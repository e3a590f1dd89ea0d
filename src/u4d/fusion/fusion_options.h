// The fields of the options structs of fusion, scene flow, the flow consensus and glTF
// (depth_fusion.h, scene_flow.h, flow_consensus.h, gltf.h), each declared once (name, help; the
// default is the struct's initialiser): params.json, `u4d run --config` / `--set` and
// docs/options.md come from these (util/options.h). Check() stays with each struct.
#pragma once

#include "u4d/fusion/depth_fusion.h"
#include "u4d/fusion/flow_consensus.h"
#include "u4d/fusion/gltf.h"
#include "u4d/fusion/scene_flow.h"
#include "u4d/util/options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, FusionOptions* o);
void DeclareOptions(OptionRegistry& r, TrackOptions* o);
void DeclareOptions(OptionRegistry& r, FlowConsensusOptions* o);
void DeclareOptions(OptionRegistry& r, GltfOptions* o);

}  // namespace u4d
