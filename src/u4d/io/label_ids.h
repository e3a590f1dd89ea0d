// The ids a label image holds (io/instance_mask.h: CV_16U, 0 = background).
#pragma once

#include <cstdint>
#include <set>

#include <opencv2/core.hpp>

namespace u4d {

// The nonzero ids of a CV_16UC1 label image, ascending; none for an empty one.
inline std::set<int> IdsIn(const cv::Mat& labels) {
  std::set<int> ids;
  for (int y = 0; y < labels.rows; ++y) {
    const uint16_t* row = labels.ptr<uint16_t>(y);
    for (int x = 0; x < labels.cols; ++x)
      if (row[x] != 0) ids.insert(row[x]);
  }
  return ids;
}

}  // namespace u4d
