// The 2D and 3D pose readers (io/poses.h) on the same bytes: the capture's
// own poses2d/ and poses3d/ files, OpenPose JSON and COCO keypoints.
#include "fuzz_input.h"
#include "u4d/io/poses.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const fs::path path = fuzz::WriteInput("poses.json", data, size);
  fuzz::AcceptErrors([&] { ReadPoses2d(path); });
  fuzz::AcceptErrors([&] { ReadPoses3d(path); });
  fuzz::AcceptErrors([&] { ReadOpenPoseJson(path); });
  fuzz::AcceptErrors([&] { ReadCocoKeypoints(path, "000000000785.jpg"); });
  return 0;
}
