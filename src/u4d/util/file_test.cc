#include "u4d/util/file.h"
#include "u4d/util/testing.h"

#include <fstream>

#include <gtest/gtest.h>

namespace u4d {
namespace {

fs::path TempDir() {
  static const fs::path dir = test_util::FreshTestDir("file_test", "files");
  return dir;
}

TEST(File, MissingFileNamesThePath) {
  try {
    ReadJsonFile("/nonexistent/u4d/thing.json");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/u4d/thing.json"), std::string::npos);
  }
}

TEST(File, CorruptJsonNamesTheFile) {
  const fs::path path = TempDir() / "bad.json";
  WriteTextFileAtomic(path, "{\"a\": [1, 2");
  try {
    ReadJsonFile(path);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("invalid JSON"), std::string::npos);
  }
}

TEST(File, FailedAtomicWriteKeepsOldContent) {
  const fs::path path = TempDir() / "keep.txt";
  WriteTextFileAtomic(path, "old");
  EXPECT_THROW(WriteAtomically(path, [](const fs::path&) { ThrowError("writer failed"); }), Error);
  EXPECT_EQ(ReadTextFile(path), "old");
  // No temporary file left behind.
  int count = 0;
  for (const auto& entry : fs::directory_iterator(path.parent_path())) {
    (void)entry;
    ++count;
  }
  EXPECT_GE(count, 1);
  for (const auto& entry : fs::directory_iterator(path.parent_path())) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos);
  }
}

TEST(File, JsonGetReportsMissingAndWrongType) {
  nlohmann::json j = {{"a", 1}};
  EXPECT_EQ(JsonGet<int>(j, "a", "ctx"), 1);
  EXPECT_THROW(JsonGet<int>(j, "b", "ctx"), Error);
  EXPECT_THROW(JsonGet<std::string>(j, "a", "ctx"), Error);
}

}  // namespace
}  // namespace u4d

namespace u4d {
namespace {

// The names WriteAtomically gives its temporary files, and no others.
TEST(File, AtomicWriteTemporariesAreRecognised) {
  fs::path seen;
  WriteAtomically(TempDir() / "000001.png", [&](const fs::path& tmp) {
    seen = tmp;
    std::ofstream(tmp) << "x";
  });
  EXPECT_TRUE(IsAtomicWriteTemporary(seen)) << seen;
  EXPECT_TRUE(IsAtomicWriteTemporary("scene.tmp-42.json"));
  EXPECT_TRUE(IsAtomicWriteTemporary("segment.tmp-7"));
  for (const char* name :
       {"000001.png", "a.tmp-.png", "a.tmp-x.png", "a.tmp-12x.png", "tmp-12.png"})
    EXPECT_FALSE(IsAtomicWriteTemporary(name)) << name;
}

TEST(File, ParseIndexNameAcceptsOnlyDecimalIndices) {
  EXPECT_EQ(ParseIndexName("7"), 7);
  EXPECT_EQ(ParseIndexName("000042"), 42);
  EXPECT_EQ(ParseIndexName("123456789"), 123456789);
  for (const char* stray : {"", "abc", "-1", "7.tmp", "1e3", " 7", "99999999999"})
    EXPECT_EQ(ParseIndexName(stray), std::nullopt) << stray;
}

TEST(File, WriteIntoAnUnwritablePlaceNamesThePath) {
  // A regular file where a parent directory should be.
  const fs::path dir = test_util::FreshTestDir("file_test", "unwritable");
  WriteTextFileAtomic(dir / "blocker", "x");
  try {
    WriteTextFileAtomic(dir / "blocker" / "sub" / "a.txt", "y");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create directory"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("blocker/sub"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace u4d
