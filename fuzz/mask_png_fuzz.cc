// A mask's PNG (io/instance_mask.h ReadInstanceMask) beside a JSON sidecar
// naming ids 1 and 2. (PNG decoding itself is OpenCV's and libpng's.)
#include "fuzz_input.h"
#include "u4d/io/instance_mask.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const fs::path json =
      fuzz::WriteInput("mask.json", R"({"instances": [{"id": 1, "class": "person", "score": 0.9},
                                     {"id": 2, "class": "person", "score": 0.8}]})");
  const fs::path png = fuzz::WriteInput("mask.png", data, size);
  fuzz::AcceptErrors([&] { ReadInstanceMask(png, json); });
  return 0;
}
