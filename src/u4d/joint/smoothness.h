// E_s(l, d), the depth smoothness of the joint energy (paper Eq. 1, supplementary
// Appendix A), over depth labels: 0 .. U−1 are depths in steps of inverse depth,
// U (`unknown`) is the unknown depth.
//
//   spatial, per 8-neighbour pair (p, q) of the region of interest:
//     [l_p = l_q] λ_s λ_s^s ρ_d(d_p, d_q)
//   temporal, per pixel p with a depth at t−1 (d^{t−1}_p, carried to t by its flow):
//     λ_s λ_s^t ρ_d(d_p, d^{t−1}_p)
//   ρ_d(a, b) = min(|a − b|, τ_d) / τ_d for two depths; 1 between U and a depth; 0 for U, U.
//
// The temporal part is OFF in the pipeline: it needs JointViewInput::previous_depth (the
// previous frame's depth carried to t by its flow) and no caller sets it (pipeline/ and
// joint/frame_setup.cc leave it empty), so the solver never adds it. It is kept, and
// tested (smoothness_test.cc), as the paper's formula; wiring it needs the previous
// frame's solved depth warped by the solved flow, which is pipeline work.
#pragma once

#include <algorithm>
#include <cstdlib>

namespace u4d {

struct SmoothnessTerm {
  double spatial_weight = 0;   // λ_s λ_s^s
  double temporal_weight = 0;  // λ_s λ_s^t
  double truncation = 4;       // τ_d, depth label steps
  int unknown = 0;             // the label U

  // ρ_d(a, b) above, in [0, 1].
  double Distance(int a, int b) const {
    if (a == unknown || b == unknown) return a == b ? 0.0 : 1.0;
    return std::min<double>(std::abs(a - b), truncation) / truncation;
  }
  // The spatial part of one pair whose pixels are both in the region of interest.
  double Spatial(int label_p, int label_q, int depth_p, int depth_q) const {
    return label_p == label_q ? spatial_weight * Distance(depth_p, depth_q) : 0.0;
  }
  // The temporal part at one pixel; previous_depth < 0: no depth at t−1, 0.
  double Temporal(int depth, int previous_depth) const {
    return previous_depth >= 0 ? temporal_weight * Distance(depth, previous_depth) : 0.0;
  }
};

}  // namespace u4d
