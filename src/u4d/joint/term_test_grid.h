// The hand-built 3x3 labelling the energy-term tests share (smoothness_test,
// joint_energy_test), so that each term's expected value is worked out by
// hand on one grid. Include from *_test.cc only.
//
// Pixels p = 3 y + x:   labels   depths (U = 10, τ_d = 4)
//                       1 1 0    2  3 7
//                       1 1 0    4  U 1
//                       0 0 0    5  5 6
#pragma once

#include <vector>

namespace u4d::term_test {

inline const std::vector<int> kLabels = {1, 1, 0, 1, 1, 0, 0, 0, 0};
inline const std::vector<int> kDepths = {2, 3, 7, 4, 10, 1, 5, 5, 6};
inline constexpr int kUnknown = 10;

}  // namespace u4d::term_test
