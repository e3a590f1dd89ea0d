// Where data lives outside the code:
//  - the data the project ships (data/ in the repository, share/u4d when
//    installed): ShippedDataFile(), used by `u4d`, the tests and the benches
//    (the CMU motion clips of the synthetic presets);
//  - the shared real data the tests and benches read when it is present:
//    DataDir(), $U4D_DATA_DIR if set, else the ../shared/data beside the
//    source checkout this binary was built from (the build defines
//    U4D_SHARED_DATA_DIR for the tests, the benches and `u4d`). Tests and
//    benches skip what needs it when it is absent; no algorithm library
//    reads it.
#pragma once

#include <cstdlib>
#include <string>
#include <system_error>
#include <vector>

#include "u4d/util/check.h"
#include "u4d/util/file.h"

#ifndef U4D_SHARED_DATA_DIR
#define U4D_SHARED_DATA_DIR ""
#endif
#ifndef U4D_SOURCE_DIR
#define U4D_SOURCE_DIR ""
#endif

namespace u4d {

inline fs::path DataDir() {
  const char* env = std::getenv("U4D_DATA_DIR");
  return env != nullptr && *env != '\0' ? fs::path(env) : fs::path(U4D_SHARED_DATA_DIR);
}

// The places a shipped data file `relative` (e.g. "mocap/scaled_131_02.bvh")
// is looked for, in order: <dir of the running binary>/../share/u4d/<relative>
// (an installed `u4d`), then <source checkout>/data/<relative> (a binary run
// from its build tree; the build defines U4D_SOURCE_DIR).
inline std::vector<fs::path> ShippedDataCandidates(const fs::path& relative) {
  std::vector<fs::path> candidates;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec && !exe.empty())
    candidates.push_back(
        (exe.parent_path() / ".." / "share" / "u4d" / relative).lexically_normal());
  if (*U4D_SOURCE_DIR != '\0') candidates.push_back(fs::path(U4D_SOURCE_DIR) / "data" / relative);
  return candidates;
}

// The first of ShippedDataCandidates(relative) that exists; throws u4d::Error
// naming every path tried when none does.
inline fs::path ShippedDataFile(const fs::path& relative) {
  std::string tried;
  for (const fs::path& p : ShippedDataCandidates(relative)) {
    if (fs::exists(p)) return p;
    tried += (tried.empty() ? "" : ", ") + p.string();
  }
  ThrowError(
      fmt::format("shipped data file {} not found (tried: {}); reinstall u4d or run it "
                  "from its build tree beside the source checkout",
                  relative.string(), tried.empty() ? "nothing" : tried));
}

}  // namespace u4d
