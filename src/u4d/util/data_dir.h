// Where the shared real data lives: $U4D_DATA_DIR if set, else the
// ../shared/data beside the source checkout this binary was built from (the
// build defines U4D_SHARED_DATA_DIR for the tests, the benches and `u4d`).
// Tests and benches skip what needs it when it is absent; no algorithm
// library reads it.
#pragma once

#include <cstdlib>

#include "u4d/util/file.h"

#ifndef U4D_SHARED_DATA_DIR
#define U4D_SHARED_DATA_DIR ""
#endif

namespace u4d {

inline fs::path DataDir() {
  const char* env = std::getenv("U4D_DATA_DIR");
  return env != nullptr && *env != '\0' ? fs::path(env) : fs::path(U4D_SHARED_DATA_DIR);
}

}  // namespace u4d
