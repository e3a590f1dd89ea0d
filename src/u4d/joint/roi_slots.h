// Compact storage of per-pixel cost volumes over a region of interest.
//
// The joint solve only looks at the pixels of the objects' regions (about a
// seventh of a 480x270 view with two people), so the depth and motion cost
// volumes store one column of costs per ROI pixel instead of per image pixel:
// memory, the page faults of allocating it and the loops that fill it then
// scale with the region, not the image.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace u4d {

struct RoiSlots {
  int width = 0, height = 0;
  // Per pixel (row-major, width * height): its slot, consecutive in row-major
  // order over the ROI's pixels; -1 = outside the ROI (not stored).
  std::vector<int> slot;
  int count = 0;  // number of slots (ROI pixels)
  // The bounding box of the ROI (empty when the ROI is).
  cv::Rect box;
};

// Slots for the nonzero pixels of `roi` (CV_8UC1, width x height), or for every
// pixel when `roi` is empty. Throws u4d::Error on a roi of another type or
// size, or a non-positive size.
RoiSlots MakeRoiSlots(const cv::Mat& roi, int width, int height);

}  // namespace u4d
