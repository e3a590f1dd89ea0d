// Reads the colour frames of a capture, from image files or video files.
// Video is decoded sequentially and kept open per view, so reading frames in
// order is cheap; seeking backwards reopens the file.
#pragma once

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/io/capture.h"

namespace cv {
class VideoCapture;
}

namespace u4d {

class FrameReader {
 public:
  explicit FrameReader(Capture capture);  // keeps its own copy
  ~FrameReader();

  // The BGR image of `view` at `frame`. Throws u4d::Error naming the file on
  // a missing or corrupt frame, or when its size differs from the camera's.
  // Calls for different views may run concurrently (each view has its own
  // decoder); calls for the same view may not.
  cv::Mat Read(int view, int frame);

 private:
  struct VideoState;
  Capture capture_;
  std::vector<std::unique_ptr<VideoState>> videos_;  // per view, opened on first use
};

}  // namespace u4d
