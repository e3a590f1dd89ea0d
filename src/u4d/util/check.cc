#include "u4d/util/check.h"

#include <cstdio>
#include <cstdlib>

namespace u4d {

void ThrowError(const std::string& message) { throw Error(message); }

void AssertFailed(const char* expr, const char* file, int line) {
  std::fprintf(stderr, "U4D internal error: assertion '%s' failed at %s:%d\n", expr, file, line);
  std::abort();
}

}  // namespace u4d
