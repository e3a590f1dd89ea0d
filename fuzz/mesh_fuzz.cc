// Mesh files (io/mesh_sequence.h ReadMeshFile): the same bytes as PLY (ASCII
// or binary) and as OBJ.
#include "fuzz_input.h"
#include "u4d/io/mesh_sequence.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace u4d;
  const fs::path ply = fuzz::WriteInput("mesh.ply", data, size);
  fuzz::AcceptErrors([&] { ReadMeshFile(ply); });
  const fs::path obj = fuzz::WriteInput("mesh.obj", data, size);
  fuzz::AcceptErrors([&] { ReadMeshFile(obj); });
  return 0;
}
