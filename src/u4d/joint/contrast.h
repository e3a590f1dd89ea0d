// E_c(l), the contrast term of the joint energy (paper Eq. 1, supplementary
// Appendix A): a label change between 8-neighbours p, q costs less across an
// edge of the image's colours or of the initial segmentation,
//
//   λ_c E_c = Σ_(p,q) [l_p ≠ l_q] λ_c (λ_ca c_pq + λ_cl s_pq) / (λ_ca + λ_cl)
//
// with c_pq the colour-contrast weight (label_costs.h ContrastWeights) and s_pq
// the semantic-contrast weight (label_costs.h SemanticContrastWeights), both in
// (0, 1]. 0 when λ_ca + λ_cl = 0.
#pragma once

#include <utility>
#include <vector>

#include "u4d/joint/neighbour_pairs.h"
#include "u4d/joint/parameters.h"

namespace u4d {

// λ_c (λ_ca c_pq + λ_cl s_pq) / (λ_ca + λ_cl) per forward pair; `colour` and
// `semantic` hold c_pq and s_pq in the order of `pairs` (p < q), pairs of a
// grid `width` pixels wide with `num_pixels` pixels. Pairs not listed cost 0.
ForwardPairValues ContrastPairCosts(const std::vector<float>& colour,
                                    const std::vector<float>& semantic,
                                    const std::vector<std::pair<int, int>>& pairs, int width,
                                    int num_pixels, const JointWeights& weights);

// E_c of one pair with labels l_p, l_q, given its weighted cost above.
inline double ContrastCost(int label_p, int label_q, float pair_cost) {
  return label_p != label_q ? pair_cost : 0.0;
}

}  // namespace u4d
