// Shared by the libFuzzer targets of fuzz/ (scripts/fuzz.sh, docs/conventions.md).
// Each target hands the fuzzer's bytes to readers of untrusted files. The
// readers take paths, so the bytes are written to a file first. A reader may
// reject the bytes with u4d::Error, which is its contract; any other
// exception escapes LLVMFuzzerTestOneInput and aborts, which libFuzzer
// reports as a crash, as it does a sanitizer's finding or an allocation
// beyond its -rss_limit_mb.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "u4d/util/check.h"
#include "u4d/util/file.h"

namespace u4d::fuzz {

// A folder of this process's own under the temporary directory.
fs::path ScratchDir();

// Writes `size` bytes to ScratchDir() / name (replacing it) and returns the path.
fs::path WriteInput(const std::string& name, const uint8_t* data, size_t size);
fs::path WriteInput(const std::string& name, const std::string& text);

// Calls `read`, accepting a u4d::Error.
template <typename F>
void AcceptErrors(F&& read) {
  try {
    read();
  } catch (const Error&) {
  }
}

}  // namespace u4d::fuzz
