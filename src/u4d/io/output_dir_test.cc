#include "u4d/io/output_dir.h"

#include <gtest/gtest.h>

#include "u4d/util/testing.h"

namespace u4d {
namespace {

using test_util::ExpectErrorMentions;

OutputDirOptions RunLike(const fs::path& capture) {
  OutputDirOptions o;
  o.command = "u4d run";
  o.inputs = {capture};
  o.markers = {"run.json"};
  return o;
}

TEST(OutputDir, NewAndEmptyFoldersAreAccepted) {
  const fs::path root = test_util::FreshTestDir("output_dir", "new");
  const OutputDirOptions o = RunLike(root / "capture");
  EXPECT_EQ(CheckOutputDir(root / "a" / "b", o), OutputDirState::kCreated);
  EXPECT_TRUE(fs::is_directory(root / "a" / "b"));
  EXPECT_EQ(CheckOutputDir(root / "a" / "b", o), OutputDirState::kEmpty);
  EXPECT_TRUE(fs::is_empty(root / "a" / "b"));  // the write probe is removed
}

TEST(OutputDir, TheInputOrAFolderInsideItIsRefused) {
  const fs::path root = test_util::FreshTestDir("output_dir", "input");
  fs::create_directories(root / "capture" / "images");
  const OutputDirOptions o = RunLike(root / "capture");
  ExpectErrorMentions([&] { CheckOutputDir(root / "capture", o); },
                      {"u4d run --output", "capture", "is the input"});
  ExpectErrorMentions([&] { CheckOutputDir(root / "capture/", o); }, {"is the input"});
  ExpectErrorMentions([&] { CheckOutputDir(root / "x" / ".." / "capture" / "scene", o); },
                      {"inside it"});
  // A sibling whose name starts with the capture's is not inside it.
  EXPECT_EQ(CheckOutputDir(root / "capture2", o), OutputDirState::kCreated);
  EXPECT_TRUE(IsSameOrInside(root / "capture" / "a", root / "capture"));
  EXPECT_FALSE(IsSameOrInside(root / "capture2", root / "capture"));
  EXPECT_FALSE(IsSameOrInside(root, root / "capture"));
}

TEST(OutputDir, AnInputRootMayHoldTheOutputButNotBeIt) {
  const fs::path root = test_util::FreshTestDir("output_dir", "input_root");
  fs::create_directories(root / "capture");
  OutputDirOptions o;
  o.command = "u4d run";
  o.input_roots = {root / "capture"};
  ExpectErrorMentions([&] { CheckOutputDir(root / "capture" / ".", o); },
                      {"u4d run --output", "is the input"});
  EXPECT_EQ(CheckOutputDir(root / "capture" / "scene", o), OutputDirState::kCreated);
}

TEST(OutputDir, ANonEmptyFolderNeedsAMarkerOrForce) {
  const fs::path root = test_util::FreshTestDir("output_dir", "nonempty");
  OutputDirOptions o = RunLike(root / "capture");
  o.force_flag = "--force";
  WriteTextFileAtomic(root / "out" / "notes.txt", "mine");
  ExpectErrorMentions([&] { CheckOutputDir(root / "out", o); },
                      {"u4d run --output", "out", "not empty", "no run.json", "--force"});
  WriteTextFileAtomic(root / "out" / "run.json", "{}");
  EXPECT_EQ(CheckOutputDir(root / "out", o), OutputDirState::kPreviousOutput);
  fs::remove(root / "out" / "run.json");
  o.force = true;
  EXPECT_EQ(CheckOutputDir(root / "out", o), OutputDirState::kForced);
  EXPECT_TRUE(fs::exists(root / "out" / "notes.txt"));  // never deletes
}

TEST(OutputDir, AFileOrAnUncreatableFolderIsAnErrorNamingThePath) {
  const fs::path root = test_util::FreshTestDir("output_dir", "file");
  WriteTextFileAtomic(root / "blocker", "x");
  const OutputDirOptions o = RunLike(root / "capture");
  ExpectErrorMentions([&] { CheckOutputDir(root / "blocker", o); },
                      {"blocker", "is not a directory"});
  ExpectErrorMentions([&] { CheckOutputDir(root / "blocker" / "scene", o); },
                      {"blocker/scene", "cannot"});
}

}  // namespace
}  // namespace u4d
