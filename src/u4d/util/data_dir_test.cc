// Where the shipped data is found: beside an installed binary, else in the
// source tree's data/ (a test binary runs from the build tree, so the latter).
#include "u4d/util/data_dir.h"

#include <gtest/gtest.h>

#include "u4d/util/testing.h"

namespace u4d {
namespace {

TEST(DataDir, ShippedClipIsFoundInTheSourceTree) {
  const fs::path expected = fs::path(U4D_SOURCE_DIR) / "data" / "mocap" / "scaled_131_02.bvh";
  EXPECT_EQ(ShippedDataFile(fs::path("mocap") / "scaled_131_02.bvh"), expected);
}

TEST(DataDir, CandidatesAreTheInstalledShareThenTheSourceTree) {
  const std::vector<fs::path> c = ShippedDataCandidates("mocap/x.bvh");
  ASSERT_EQ(c.size(), 2u);
  const fs::path exe_dir = fs::read_symlink("/proc/self/exe").parent_path();
  EXPECT_EQ(c[0], (exe_dir.parent_path() / "share" / "u4d" / "mocap" / "x.bvh").lexically_normal());
  EXPECT_EQ(c[1], fs::path(U4D_SOURCE_DIR) / "data" / "mocap" / "x.bvh");
}

TEST(DataDir, MissingShippedFileNamesEveryPathTried) {
  std::vector<std::string> parts = {"mocap/absent.bvh"};
  for (const fs::path& p : ShippedDataCandidates("mocap/absent.bvh")) parts.push_back(p.string());
  test_util::ExpectErrorMentions([] { ShippedDataFile("mocap/absent.bvh"); }, parts);
}

}  // namespace
}  // namespace u4d
