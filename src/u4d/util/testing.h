// Helpers shared by the GoogleTest suites. Include from *_test.cc only.
#pragma once

#include <set>
#include <string>
#include <system_error>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/file.h"

namespace u4d::test_util {

// The temporary folders of this test process, removed when it exits unless
// a test failed (they are then kept for a look at what it wrote).
class TempDirs {
 public:
  static void Register(const fs::path& dir) { Instance().dirs_.insert(dir); }

 private:
  static TempDirs& Instance() {
    static TempDirs dirs;
    return dirs;
  }
  ~TempDirs() {
    if (!::testing::UnitTest::GetInstance()->Passed()) return;
    std::error_code ignored;  // a folder already gone is fine
    for (const fs::path& dir : dirs_) fs::remove_all(dir, ignored);
  }
  std::set<fs::path> dirs_;
};

// `dir` (a folder this test process made, e.g. by synth::WriteCaptureToTempDir),
// removed when the process exits as the folders of FreshTestDir are.
inline fs::path RemovedAtExit(const fs::path& dir) {
  TempDirs::Register(dir);
  return dir;
}

// An empty directory <tmp>/u4d_<suite>_<pid>/<name>: one per process, since
// ctest runs the tests of a suite in separate processes, in parallel.
// <tmp>/u4d_<suite>_<pid> goes when the process exits (TempDirs).
inline fs::path FreshTestDir(const std::string& suite, const std::string& name) {
  const fs::path root =
      fs::temp_directory_path() / ("u4d_" + suite + "_" + std::to_string(::getpid()));
  TempDirs::Register(root);
  const fs::path dir = root / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Expects `f` to throw u4d::Error whose message contains every one of `parts`.
template <typename F>
void ExpectErrorMentions(F&& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no u4d::Error thrown";
  } catch (const Error& e) {
    for (const std::string& p : parts)
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos)
          << "message '" << e.what() << "' does not mention '" << p << "'";
  }
}

}  // namespace u4d::test_util

// U4D_SKIP_WITHOUT_SHARED_DATA(data_path): skips the current test (in a TEST
// body or SetUp()) with a message naming `data_path` when that real
// data (under DataDir(): ../shared/data beside the checkout, or
// $U4D_DATA_DIR) is absent. The data shipped in data/ needs no skip.
#define U4D_SKIP_WITHOUT_SHARED_DATA(data_path)                                        \
  do {                                                                                 \
    const ::u4d::fs::path u4d_shared_path_ = (data_path);                              \
    if (!::u4d::fs::exists(u4d_shared_path_))                                          \
      GTEST_SKIP() << "shared real data absent: " << u4d_shared_path_.string()         \
                   << " (put ../shared/data beside the checkout or set U4D_DATA_DIR)"; \
  } while (0)
