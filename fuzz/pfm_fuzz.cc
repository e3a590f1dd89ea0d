// PFM depth maps (io/image_io.h ReadPfm).
#include "fuzz_input.h"
#include "u4d/io/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const fs::path path = fuzz::WriteInput("map.pfm", data, size);
  fuzz::AcceptErrors([&] { ReadPfm(path); });
  return 0;
}
