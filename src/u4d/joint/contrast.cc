#include "u4d/joint/contrast.h"

namespace u4d {

ForwardPairValues ContrastPairCosts(const std::vector<float>& colour,
                                    const std::vector<float>& semantic,
                                    const std::vector<std::pair<int, int>>& pairs, int width,
                                    int num_pixels, const JointWeights& weights) {
  ForwardPairValues costs;
  costs.Assign(num_pixels, 0.f);
  const double cw = weights.contrast_colour + weights.contrast_label;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const auto [p, q] = pairs[i];
    const double e =
        cw > 0 ? (weights.contrast_colour * colour[i] + weights.contrast_label * semantic[i]) / cw
               : 0.0;
    costs.At(p, q, width) = static_cast<float>(weights.contrast * e);
  }
  return costs;
}

}  // namespace u4d
