// The importers' text files on the same bytes: a Qualisys .qca.txt, a
// Middlebury *_par.txt (io/import_calibration.h), and 4D Association's gt.txt
// and detection files (io/import_fourda.h).
#include "fuzz_input.h"
#include "u4d/io/import_calibration.h"
#include "u4d/io/import_fourda.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const fs::path path = fuzz::WriteInput("import.txt", data, size);
  fuzz::AcceptErrors([&] { ReadQualisysCalibration(path); });
  fuzz::AcceptErrors([&] { ReadMiddleburyCalibration(path, 640, 480); });
  fuzz::AcceptErrors([&] { ReadFourdaGroundTruth(path); });
  fuzz::AcceptErrors([&] { ReadFourdaDetections(path); });
  return 0;
}
