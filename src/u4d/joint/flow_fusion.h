// The flow fusion stage (after the block schedule): the motion becomes
// continuous. Fusion moves (mrf::FusionMove, Lempitsky et al. 2010) of the
// current field with dense proposals, under the full JointEnergy with l and d
// fixed: per round the discrete solution refined by parabola fits (first round,
// FlowFusionOptions::refined), the state-independent proposals
// (FlowFusionProposals, joint_view.h) and the current field smoothed. E_f of a
// sub-pixel motion is FlowFieldCosts (flow_cost.h); its e_F^S is that of the
// nearest integer offset in M (forbidden when that offset is not in M), so
// integer motions cost what their labels cost and the energy is one function.
// Each fusion is accepted only when it lowers the energy.
#pragma once

#include <opencv2/core.hpp>

#include "u4d/joint/flow_cost.h"
#include "u4d/joint/joint_energy.h"
#include "u4d/joint/joint_view.h"
#include "u4d/joint/phase_clock.h"

namespace u4d {

// Fuses the proposals into labelling->motion_vectors and flow_costs (labels,
// depths and motions unchanged). `flow_input` is the E_f input of the volume
// (for FlowFieldCosts), `grey_t`, `grey_t1` the reference view's grey frames.
// Records the phases "fusion proposals" and "fusion moves" on `clock` and
// appends the "fusion" step to result->energy_trace.
void FuseFlow(const JointEnergy& energy, const FlowCostInput& flow_input, const cv::Mat& grey_t,
              const cv::Mat& grey_t1, const JointViewOptions& options, JointLabelling* labelling,
              PhaseClock* clock, JointViewResult* result);

}  // namespace u4d
