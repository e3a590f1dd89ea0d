// calibration.json (io/capture.h ReadCapture) beside a valid capture.json of
// views cam00 and cam01, the first one a moving camera over 2 frames allowed.
#include "fuzz_input.h"
#include "u4d/io/capture.h"

namespace {

constexpr const char* kManifest = R"({"format": "u4d-capture", "name": "fuzz", "fps": 25,
 "num_frames": 2, "views": [{"name": "cam00", "source": "images", "path": "images/cam00/{:06d}.png"},
                            {"name": "cam01", "source": "images", "path": "images/cam01/{:06d}.png"}]})";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  fuzz::WriteInput("capture.json", kManifest);
  fuzz::WriteInput("calibration.json", data, size);
  fuzz::AcceptErrors([] {
    const Capture cap = ReadCapture(fuzz::ScratchDir());
    for (const CaptureView& v : cap.views) v.CameraAt(1);
  });
  return 0;
}
