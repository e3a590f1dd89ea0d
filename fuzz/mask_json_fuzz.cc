// A mask's JSON sidecar (io/instance_mask.h ReadInstanceMask) beside a valid
// 16-bit PNG holding ids 0, 1 and 2.
#include <opencv2/core.hpp>

#include "fuzz_input.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  static const fs::path png = [] {
    cv::Mat ids = cv::Mat::zeros(6, 8, CV_16UC1);
    ids(cv::Rect(1, 1, 3, 3)).setTo(1);
    ids(cv::Rect(4, 2, 3, 3)).setTo(2);
    const fs::path path = fuzz::ScratchDir() / "mask.png";
    WriteImage(path, ids);
    return path;
  }();
  const fs::path json = fuzz::WriteInput("mask.json", data, size);
  fuzz::AcceptErrors([&] { ReadInstanceMask(png, json); });
  return 0;
}
