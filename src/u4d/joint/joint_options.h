// The fields of the options structs of the joint optimisation (joint_view.h, frame_setup.h,
// parameters.h), each declared once (name, help; the default is the struct's initialiser):
// params.json, `u4d run --config` / `--set` and docs/options.md come from these (util/options.h).
// Check() stays with each struct.
#pragma once

#include "u4d/joint/background_flow.h"
#include "u4d/joint/depth_cost.h"
#include "u4d/joint/flow_cost.h"
#include "u4d/joint/frame_setup.h"
#include "u4d/joint/hull_support.h"
#include "u4d/joint/joint_view.h"
#include "u4d/joint/label_costs.h"
#include "u4d/joint/motion_labels.h"
#include "u4d/joint/parameters.h"
#include "u4d/joint/pose_prior.h"
#include "u4d/util/options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, FrameSetupOptions* o);
void DeclareOptions(OptionRegistry& r, HullSupportOptions* o);
void DeclareOptions(OptionRegistry& r, PosePriorOptions* o);
void DeclareOptions(OptionRegistry& r, FlowFusionOptions* o);
void DeclareOptions(OptionRegistry& r, BackgroundFlowOptions* o);
void DeclareOptions(OptionRegistry& r, JointViewOptions* o);
void DeclareOptions(OptionRegistry& r, JointWeights* o);
void DeclareOptions(OptionRegistry& r, JointTerms* o);
void DeclareOptions(OptionRegistry& r, LabelCostOptions* o);
void DeclareOptions(OptionRegistry& r, DepthCostOptions* o);
void DeclareOptions(OptionRegistry& r, MotionLabelOptions* o);
void DeclareOptions(OptionRegistry& r, FlowCostOptions* o);

}  // namespace u4d
