// The 8-connected neighbour pairs of a view's pixel grid, as the pairwise terms
// (E_s, E_c, E_r) store them: each pair once, as p < q, under the direction of
// q - p. Pixel index p = y * width + x.
#pragma once

#include <array>
#include <vector>

namespace u4d {

// Index of the forward neighbour direction q - p (p < q, 8-connected):
// (1,0) -> 0, (-1,1) -> 1, (0,1) -> 2, (1,1) -> 3.
inline int ForwardDirection(int p, int q, int width) {
  const int d = q - p;
  if (d == 1) return 0;
  if (d == width - 1) return 1;
  if (d == width) return 2;
  return 3;
}

// A value per forward pair: values[ForwardDirection(p, q, width)][p].
struct ForwardPairValues {
  std::array<std::vector<float>, 4> values;
  void Assign(int num_pixels, float value) {
    for (std::vector<float>& v : values) v.assign(num_pixels, value);
  }
  float& At(int p, int q, int width) { return values[ForwardDirection(p, q, width)][p]; }
  float At(int p, int q, int width) const { return values[ForwardDirection(p, q, width)][p]; }
};

}  // namespace u4d
