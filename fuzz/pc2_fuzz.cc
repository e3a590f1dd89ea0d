// PC2 point caches (io/mesh_sequence.h ReadPointCache) for a valid template
// OBJ of one triangle.
#include "fuzz_input.h"
#include "u4d/io/mesh_sequence.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const fs::path obj = fuzz::WriteInput("template.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const fs::path pc2 = fuzz::WriteInput("cache.pc2", data, size);
  fuzz::AcceptErrors([&] { ReadPointCache(obj, pc2); });
  return 0;
}
