// scene.json of a 4D scene (io/scene_index.h ReadSceneIndex), which
// `u4d view` and `u4d eval` read from folders they are given.
#include "fuzz_input.h"
#include "u4d/io/scene_index.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  fuzz::WriteInput("scene.json", data, size);
  fuzz::AcceptErrors([] { ReadSceneIndex(fuzz::ScratchDir()); });
  return 0;
}
