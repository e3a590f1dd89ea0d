#include "u4d/joint/joint_view.h"

#include <opencv2/imgproc.hpp>

#include "u4d/joint/background_flow.h"
#include "u4d/joint/block_schedule.h"
#include "u4d/joint/energy_setup.h"
#include "u4d/joint/flow_fusion.h"
#include "u4d/joint/joint_energy.h"
#include "u4d/joint/phase_clock.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

namespace u4d {
namespace {

cv::Mat Grey(const cv::Mat& bgr) {
  cv::Mat g;
  cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY);
  return g;
}

// The outputs: labels, sub-sample depth on object pixels, sub-pixel flow (0
// outside the region of interest, where the background flow follows, and on
// the last frame).
void WriteOutputs(const JointEnergy& energy, const JointLabelling& labelling, bool has_next,
                  JointViewResult* result) {
  const int n = energy.num_pixels;
  result->labels = cv::Mat(energy.height, energy.width, CV_16U);
  std::vector<int> depth_labels(n);
  for (int p = 0; p < n; ++p) {
    result->labels.ptr<uint16_t>()[p] = static_cast<uint16_t>(labelling.labels[p]);
    depth_labels[p] = (labelling.labels[p] == 0 || labelling.depths[p] == energy.unknown)
                          ? -1
                          : labelling.depths[p];
  }
  result->depth = RefineDepthLabels(energy.depth, depth_labels);
  result->flow = cv::Mat::zeros(energy.height, energy.width, CV_32FC2);
  if (has_next)
    for (int p = 0; p < n; ++p)
      if (energy.grid.IsActive(p))
        result->flow.ptr<cv::Vec2f>()[p] =
            cv::Vec2f(labelling.motion_vectors[p].x(), labelling.motion_vectors[p].y());
}

}  // namespace

void JointViewOptions::Check() const {
  weights.Check();
  labels.Check();
  depth.Check();
  motion_labels.Check();
  flow.Check();
  pose.Check();
  U4D_CHECK(rounds >= 1 && rounds <= 100, "JointViewOptions.rounds must be in [1, 100], got {}",
            rounds);
  U4D_CHECK(sweeps_per_block >= 1, "JointViewOptions.sweeps_per_block must be >= 1");
  U4D_CHECK(motion_rounds >= 1, "JointViewOptions.motion_rounds must be >= 1, got {}",
            motion_rounds);
  U4D_CHECK(depth_truncation > 0, "JointViewOptions.depth_truncation must be > 0");
  U4D_CHECK(depth_coarse_step >= 0, "JointViewOptions.depth_coarse_step must be >= 0, got {}",
            depth_coarse_step);
  U4D_CHECK(depth_refine_band >= 0, "JointViewOptions.depth_refine_band must be >= 0, got {}",
            depth_refine_band);
  U4D_CHECK(motion_truncation_px > 0, "JointViewOptions.motion_truncation_px must be > 0");
  U4D_CHECK(motion_candidates_per_pixel >= 0,
            "JointViewOptions.motion_candidates_per_pixel must be >= 0, got {}",
            motion_candidates_per_pixel);
  U4D_CHECK(roi_margin_px >= 0, "JointViewOptions.roi_margin_px must be >= 0");
  U4D_CHECK(appearance_refits >= 0, "JointViewOptions.appearance_refits must be >= 0, got {}",
            appearance_refits);
  fusion.Check();
  background_flow.Check();
}

JointViewResult SolveJointView(const JointViewInput& in, const JointViewOptions& options) {
  options.Check();
  CheckJointViewInput(in);
  Timer timer;
  JointViewResult result;
  PhaseClock clock(&result.phases);
  const bool has_next = !in.images_t1.empty();

  // The energy's terms (energy_setup.h), in the order they read each other.
  const cv::Mat roi = RegionOfInterest(in, options.roi_margin_px);
  JointEnergy energy = MakeJointEnergy(in, options, roi);
  LabelTermVolumes volumes = SetUpLabelUnaries(in, options, roi, &energy);
  clock.End("label unaries");
  SetUpContrast(in, options, volumes, &energy);
  if (RefitAppearance(in, options, &volumes, &energy)) clock.End("appearance refits");
  SetUpMotionRegWeights(in, options, volumes, &energy);
  clock.End("pairwise weights");
  SetUpDepthTerms(in, options, roi, &energy);
  clock.End("depth volume");
  cv::Mat plane_sweep_depth;
  const FlowCostInput flow_input = SetUpFlowTerms(in, options, roi, &energy, &plane_sweep_depth);
  clock.End("flow volume");
  JointLabelling labelling = InitialLabelling(in, energy);
  clock.End("initial labelling");

  result.roi = roi;
  result.plane_sweep_depth = plane_sweep_depth;
  result.num_depth_labels = energy.unknown + 1;
  result.num_motion_labels = energy.motion.NumLabels();
  result.energy_trace.push_back({"init", energy.EnergyOf(labelling), timer.Seconds()});

  // The minimisation: the label / depth / motion blocks, then the flow fusion.
  RunBlockSchedule(energy, options, has_next, &labelling, &result);
  clock.Restart();
  if (has_next && options.fusion.enabled && options.terms.flow)
    FuseFlow(energy, flow_input, Grey(in.images_t[in.ref_view]), Grey(in.images_t1[in.ref_view]),
             options, &labelling, &clock, &result);

  WriteOutputs(energy, labelling, has_next, &result);
  if (has_next && options.background_flow.enabled) {
    const int v = in.ref_view;
    BackgroundFlow(in.cameras_t[v], in.cameras_t1[v], Grey(in.images_t[v]), Grey(in.images_t1[v]),
                   options.background_flow)
        .copyTo(result.flow, roi == 0);
    clock.End("background flow");
  }
  result.seconds = timer.Seconds();
  return result;
}

}  // namespace u4d
