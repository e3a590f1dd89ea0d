// The solver's block schedule (paper Sec. 2.1: α-expansion over L × D × M).
// The product label space is optimised by alternating α-expansion
// (mrf/expansion.h) over one factor with the others fixed, `rounds` times:
//
//   label block   α ∈ L       (from the second round moving (label, depth) pairs:
//                             label_moves_carry_depth)
//   depth block   α ∈ D ∪ {U} (coarse-to-fine with depth_coarse_step; a band of
//                             depth_refine_band labels from the second round)
//   motion block  α ∈ M       (in the first motion_rounds rounds, and only with a
//                             frame t+1; motion_candidates_per_pixel)
//
// Every block minimises the full JointEnergy restricted to its factor, so the
// energy never increases (each step is recorded in JointViewResult::energy_trace).
#pragma once

#include <vector>

#include "u4d/joint/joint_energy.h"
#include "u4d/joint/joint_view.h"

namespace u4d {

// Per forward pair, the part of JointEnergy::Pair that a block does not change,
// computed once per block: E_r at the current l, m (kMotion: the depth block) or
// E_c + E_s at the current l, d (kLabelDepth: the motion block and the flow fusion).
class PairCache {
 public:
  enum class Part { kMotion, kLabelDepth };
  void Fill(const JointEnergy& energy, const JointLabelling& labelling, Part part);
  double At(int p, int q, int width) const {
    return values_[static_cast<size_t>(p) * 4 + ForwardDirection(p, q, width)];
  }

 private:
  std::vector<double> values_;
};

// Runs the rounds of label, depth and motion blocks from `labelling` (with
// motion_vectors set), appending one energy_trace entry per block and the
// phases "labels", "depth" and "motion" (the last only when has_next) to `result`.
void RunBlockSchedule(const JointEnergy& energy, const JointViewOptions& options, bool has_next,
                      JointLabelling* labelling, JointViewResult* result);

}  // namespace u4d
