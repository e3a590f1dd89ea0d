#include "u4d/joint/roi_slots.h"

#include <algorithm>

#include "u4d/util/check.h"

namespace u4d {

RoiSlots MakeRoiSlots(const cv::Mat& roi, int width, int height) {
  U4D_CHECK(width > 0 && height > 0, "MakeRoiSlots: size must be positive, got {}x{}", width,
            height);
  U4D_CHECK(roi.empty() || (roi.type() == CV_8UC1 && roi.cols == width && roi.rows == height),
            "MakeRoiSlots: roi must be empty or CV_8U {}x{}, got type {} {}x{}", width, height,
            roi.type(), roi.cols, roi.rows);
  RoiSlots s;
  s.width = width;
  s.height = height;
  s.slot.assign(static_cast<size_t>(width) * height, -1);
  int x0 = width, y0 = height, x1 = -1, y1 = -1;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      if (!roi.empty() && roi.at<uint8_t>(y, x) == 0) continue;
      s.slot[static_cast<size_t>(y) * width + x] = s.count++;
      x0 = std::min(x0, x), x1 = std::max(x1, x);
      y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  if (s.count > 0) s.box = cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
  return s;
}

}  // namespace u4d
