#include "fuzz_input.h"

#include <fstream>

#include <unistd.h>

namespace u4d::fuzz {

fs::path ScratchDir() {
  const fs::path dir = fs::temp_directory_path() / ("u4d_fuzz_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

fs::path WriteInput(const std::string& name, const uint8_t* data, size_t size) {
  const fs::path path = ScratchDir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  U4D_ASSERT(out.good());
  return path;
}

fs::path WriteInput(const std::string& name, const std::string& text) {
  return WriteInput(name, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

}  // namespace u4d::fuzz
