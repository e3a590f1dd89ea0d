// Two error channels (see docs/conventions.md):
//  - bad input and broken contracts throw u4d::Error with a message that names
//    the file or argument, what was expected and what was found;
//  - internal invariants use U4D_ASSERT, which aborts with the location.
#pragma once

#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace u4d {

// The one exception type for bad input. Callers catch it at the CLI boundary
// and print what(); nothing below the CLI swallows it.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

[[noreturn]] void ThrowError(const std::string& message);
[[noreturn]] void AssertFailed(const char* expr, const char* file, int line);

}  // namespace u4d

// U4D_CHECK(cond, "format {}", args...): throws u4d::Error when cond is false.
#define U4D_CHECK(cond, ...)                                  \
  do {                                                        \
    if (!(cond)) ::u4d::ThrowError(fmt::format(__VA_ARGS__)); \
  } while (0)

// U4D_ASSERT(cond): an internal invariant; a failure is a bug in U4D.
#define U4D_ASSERT(cond)                                         \
  do {                                                           \
    if (!(cond)) ::u4d::AssertFailed(#cond, __FILE__, __LINE__); \
  } while (0)
