#include "u4d/joint/flow_fusion.h"

#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "u4d/baselines/dense_flow.h"
#include "u4d/joint/block_schedule.h"
#include "u4d/joint/motion_labels.h"
#include "u4d/mrf/expansion.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

namespace u4d {
namespace {

// Fusion of the current motion (binary label 0) with a proposal (label 1):
// the full energy as a function of the per-pixel choice, l and d fixed.
// `cache` holds PairCache::Part::kLabelDepth at the current l and d.
struct FusionBlock : mrf::GridEnergy {
  const JointEnergy& energy;
  const JointLabelling& state;
  const PairCache& cache;
  const std::vector<Eigen::Vector2f>& proposal;  // proposal motion
  const std::vector<float>& proposal_cost;       // its raw E_f cost
  FusionBlock(const JointEnergy& e, const JointLabelling& labelling, const PairCache& c,
              const std::vector<Eigen::Vector2f>& m, const std::vector<float>& f)
      : energy(e), state(labelling), cache(c), proposal(m), proposal_cost(f) {}
  const Eigen::Vector2f& Motion(int p, int k) const {
    return k == 0 ? state.motion_vectors[p] : proposal[p];
  }
  double Unary(int p, int k) const override {
    return energy.MotionUnary(p, Motion(p, k), k == 0 ? state.flow_costs[p] : proposal_cost[p],
                              state.labels[p], state.depths[p]);
  }
  double Pairwise(int p, int q, int kp, int kq) const override {
    return cache.At(p, q, energy.width) +
           energy.PairMotion(p, q, state.labels[p], state.labels[q], Motion(p, kp), Motion(q, kq));
  }
};

cv::Mat MotionField(const JointEnergy& energy, const JointLabelling& labelling) {
  cv::Mat f(energy.height, energy.width, CV_32FC2);
  for (int p = 0; p < energy.num_pixels; ++p)
    f.ptr<cv::Vec2f>()[p] =
        cv::Vec2f(labelling.motion_vectors[p].x(), labelling.motion_vectors[p].y());
  return f;
}

// One fusion move of the current motion with `proposal_field` (CV_32FC2).
void Fuse(const JointEnergy& energy, const PairCache& cache, const MotionLabelGrid& index,
          const FlowCostInput& flow_input, const JointViewOptions& options,
          const cv::Mat& proposal_field, JointLabelling* labelling) {
  const int n = energy.num_pixels;
  std::vector<Eigen::Vector2f> proposal_motion(n);
  std::vector<float> proposal_flow_cost(n);
  cv::Mat field = proposal_field.clone();  // a non-finite proposal keeps the current motion
  for (int p = 0; p < n; ++p) {
    cv::Vec2f& f = field.ptr<cv::Vec2f>()[p];
    if (!std::isfinite(f[0]) || !std::isfinite(f[1]))
      f = cv::Vec2f(labelling->motion_vectors[p].x(), labelling->motion_vectors[p].y());
  }
  const cv::Mat costs = FlowFieldCosts(flow_input, field, options.flow);
  for (int p = 0; p < n; ++p) {
    const cv::Vec2f f = field.ptr<cv::Vec2f>()[p];
    proposal_motion[p] = Eigen::Vector2f(f[0], f[1]);
    if (!energy.grid.IsActive(p) || !proposal_motion[p].allFinite()) {
      proposal_motion[p] = labelling->motion_vectors[p];
      proposal_flow_cost[p] = labelling->flow_costs[p];
      continue;
    }
    // e_F^S of a sub-pixel motion: that of its nearest integer offset in M,
    // or allowed near the pixel's dense match.
    const int k = index.Nearest(proposal_motion[p]);
    const bool forbidden = ForbiddenMotion(energy.motion, flow_input, options.flow,
                                           options.motion_labels.window, p, k, proposal_motion[p]);
    proposal_flow_cost[p] = costs.ptr<float>()[p] + (forbidden ? kForbiddenMotion : 0.f);
  }
  std::vector<int> choice(n, 0);
  const std::vector<int> proposal(n, 1);
  mrf::FusionMove(energy.grid,
                  FusionBlock(energy, *labelling, cache, proposal_motion, proposal_flow_cost),
                  proposal, &choice, options.algorithm);
  for (int p = 0; p < n; ++p)
    if (choice[p] == 1) {
      labelling->motion_vectors[p] = proposal_motion[p];
      labelling->flow_costs[p] = proposal_flow_cost[p];
    }
}

}  // namespace

void FuseFlow(const JointEnergy& energy, const FlowCostInput& flow_input, const cv::Mat& grey_t,
              const cv::Mat& grey_t1, const JointViewOptions& options, JointLabelling* labelling,
              PhaseClock* clock, JointViewResult* result) {
  Timer timer;
  PairCache cache;
  cache.Fill(energy, *labelling, PairCache::Part::kLabelDepth);
  const MotionLabelGrid index(energy.motion.motions);
  // Proposals that do not depend on the state.
  const std::vector<cv::Mat> external =
      FlowFusionProposals(grey_t, grey_t1, options.fusion, flow_input.dense_matches);
  clock->End("fusion proposals");
  for (int round = 0; round < options.fusion.rounds; ++round) {
    if (round == 0 && options.fusion.refined) {
      std::vector<int> labels(labelling->motions);
      for (int p = 0; p < energy.num_pixels; ++p)
        if (!energy.grid.IsActive(p)) labels[p] = -1;
      Fuse(energy, cache, index, flow_input, options, RefineFlowLabels(energy.motion, labels),
           labelling);
    }
    for (const cv::Mat& f : external) Fuse(energy, cache, index, flow_input, options, f, labelling);
    if (options.fusion.smoothed) {
      cv::Mat smooth;
      cv::GaussianBlur(MotionField(energy, *labelling), smooth, cv::Size(5, 5), 1.0);
      Fuse(energy, cache, index, flow_input, options, smooth, labelling);
    }
  }
  result->energy_trace.push_back({"fusion", energy.EnergyOf(*labelling), timer.Seconds()});
  clock->End("fusion moves");
}

void FlowFusionOptions::Check() const {
  U4D_CHECK(rounds >= 1, "FlowFusionOptions.rounds must be >= 1, got {}", rounds);
}

std::vector<cv::Mat> FlowFusionProposals(const cv::Mat& grey_t, const cv::Mat& grey_t1,
                                         const FlowFusionOptions& options,
                                         const cv::Mat& fine_dis) {
  U4D_CHECK(grey_t.type() == CV_8UC1 && grey_t1.type() == CV_8UC1 &&
                grey_t.size() == grey_t1.size() && !grey_t.empty(),
            "FlowFusionProposals: need two 8-bit grey images of one size (got {}x{} type {} and "
            "{}x{} type {})",
            grey_t.cols, grey_t.rows, grey_t.type(), grey_t1.cols, grey_t1.rows, grey_t1.type());
  std::vector<cv::Mat> proposals;
  using baselines::DenseFlow;
  using baselines::DenseFlowMethod;
  if (options.deepflow) proposals.push_back(DenseFlow(DenseFlowMethod::kDeepFlow, grey_t, grey_t1));
  if (options.dis_fine) {
    U4D_CHECK(fine_dis.empty() || (fine_dis.type() == CV_32FC2 && fine_dis.size() == grey_t.size()),
              "FlowFusionProposals: the given fine DIS flow must be CV_32FC2 of the images' size");
    proposals.push_back(fine_dis.empty() ? DenseFlow(DenseFlowMethod::kDisFine, grey_t, grey_t1)
                                         : fine_dis);
  }
  if (options.dis) proposals.push_back(DenseFlow(DenseFlowMethod::kDisMedium, grey_t, grey_t1));
  if (proposals.size() == 2) proposals.push_back(0.5 * (proposals[0] + proposals[1]));
  return proposals;
}

}  // namespace u4d
