// The importers' JSON calibrations (io/import_calibration.h) on the same
// bytes: Panoptic camera_parameters.json and 4D Association calibration.json.
#include "fuzz_input.h"
#include "u4d/io/import_calibration.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const fs::path path = fuzz::WriteInput("calibration.json", data, size);
  fuzz::AcceptErrors([&] { ReadPanopticCalibration(path); });
  fuzz::AcceptErrors([&] { ReadFourdaCalibration(path); });
  return 0;
}
