// BVH motion capture (synth/bvh.h ParseBvh).
#include <string>

#include "fuzz_input.h"
#include "u4d/synth/bvh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::AcceptErrors([&] { synth::ParseBvh(text, "fuzz.bvh"); });
  return 0;
}
