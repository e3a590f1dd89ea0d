// Middlebury .flo flow maps (io/image_io.h ReadFlo).
#include "fuzz_input.h"
#include "u4d/io/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const fs::path path = fuzz::WriteInput("map.flo", data, size);
  fuzz::AcceptErrors([&] { ReadFlo(path); });
  return 0;
}
