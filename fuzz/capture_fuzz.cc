// capture.json (io/capture.h ReadCapture) beside a valid calibration.json of
// views cam00 and cam01; an accepted capture must also name its frames.
#include <algorithm>

#include "fuzz_input.h"
#include "u4d/io/capture.h"

namespace {

constexpr const char* kCalibration = R"({"cameras": [
 {"view": "cam00", "width": 16, "height": 12, "K": [[20, 0, 8], [0, 20, 6], [0, 0, 1]],
  "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 3]},
 {"view": "cam01", "width": 16, "height": 12, "K": [[20, 0, 8], [0, 20, 6], [0, 0, 1]],
  "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0.5, 0, 3]}]})";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  fuzz::WriteInput("calibration.json", kCalibration);
  fuzz::WriteInput("capture.json", data, size);
  fuzz::AcceptErrors([] {
    const Capture cap = ReadCapture(fuzz::ScratchDir());
    for (int v = 0; v < cap.NumViews(); ++v)
      if (cap.views[v].source.kind == FrameSource::Kind::kImages)
        for (int f = 0; f < std::min(cap.num_frames, 3); ++f) cap.ImagePath(v, f);
  });
  return 0;
}
