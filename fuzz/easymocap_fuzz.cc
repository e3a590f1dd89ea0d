// EasyMocap calibrations (io/import_calibration.h ReadEasyMocapCalibration):
// the bytes as intri.yml beside a valid extri.yml of cameras 01 and 02, then
// as extri.yml beside a valid intri.yml. (YAML parsing is OpenCV's.)
#include "fuzz_input.h"
#include "u4d/io/import_calibration.h"

namespace {

constexpr const char* kIntri = R"(%YAML:1.0
---
names: ["01", "02"]
K_01: !!opencv-matrix
  rows: 3
  cols: 3
  dt: d
  data: [20., 0., 8., 0., 20., 6., 0., 0., 1.]
dist_01: !!opencv-matrix
  rows: 1
  cols: 5
  dt: d
  data: [0., 0., 0., 0., 0.]
H_01: 12
W_01: 16
K_02: !!opencv-matrix
  rows: 3
  cols: 3
  dt: d
  data: [20., 0., 8., 0., 20., 6., 0., 0., 1.]
dist_02: !!opencv-matrix
  rows: 1
  cols: 5
  dt: d
  data: [0., 0., 0., 0., 0.]
H_02: 12
W_02: 16
)";

constexpr const char* kExtri = R"(%YAML:1.0
---
names: ["01", "02"]
R_01: !!opencv-matrix
  rows: 3
  cols: 1
  dt: d
  data: [0., 0., 0.]
T_01: !!opencv-matrix
  rows: 3
  cols: 1
  dt: d
  data: [0., 0., 3.]
R_02: !!opencv-matrix
  rows: 3
  cols: 1
  dt: d
  data: [0., 0.1, 0.]
T_02: !!opencv-matrix
  rows: 3
  cols: 1
  dt: d
  data: [0.5, 0., 3.]
)";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const fs::path intri = fuzz::WriteInput("intri.yml", data, size);
  const fs::path extri = fuzz::WriteInput("extri.yml", kExtri);
  fuzz::AcceptErrors([&] { ReadEasyMocapCalibration(intri, extri); });
  const fs::path intri_ok = fuzz::WriteInput("intri_ok.yml", kIntri);
  const fs::path extri_fuzzed = fuzz::WriteInput("extri_fuzzed.yml", data, size);
  fuzz::AcceptErrors([&] { ReadEasyMocapCalibration(intri_ok, extri_fuzzed); });
  return 0;
}
