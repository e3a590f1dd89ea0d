// The capture's fingerprint (input_fingerprint.h): a change to what a run
// reads is seen and named, a change elsewhere (ground truth) is not.
#include "u4d/io/input_fingerprint.h"

#include <gtest/gtest.h>

#include "u4d/io/layout.h"
#include "u4d/io/tiny_capture_test_util.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

Capture TwoViewCapture(const fs::path& root) {
  Capture c = test_util::TinyTwoViewCapture();
  c.root = root;
  WriteCapture(c, root);
  for (int v = 0; v < 2; ++v)
    for (int f = 0; f < 2; ++f) WriteTextFileAtomic(c.ImagePath(v, f), "pixels");
  WriteTextFileAtomic(root / layout::MaskInfo("cam0", 0), "{\"instances\": []}");
  return c;
}

// The reference values of 64-bit FNV-1a (the hash's published test vectors).
TEST(InputFingerprintTest, HashesContentWithFnv1a) {
  const fs::path dir = test_util::FreshTestDir("input_fingerprint", "hash");
  WriteTextFileAtomic(dir / "empty", "");
  WriteTextFileAtomic(dir / "a", "a");
  EXPECT_EQ(HashFileContent(dir / "empty"), "c:cbf29ce484222325");
  EXPECT_EQ(HashFileContent(dir / "a"), "c:af63dc4c8601ec8c");
  test_util::ExpectErrorMentions([&] { HashFileContent(dir / "missing"); }, {"missing"});
}

TEST(InputFingerprintTest, NamesTheInputsThatChanged) {
  const fs::path root = test_util::FreshTestDir("input_fingerprint", "capture");
  Capture cap = TwoViewCapture(root);
  const InputFingerprint before = FingerprintCapture(cap);
  EXPECT_TRUE(before.files.count("capture.json"));
  EXPECT_TRUE(before.files.count("calibration.json"));
  EXPECT_TRUE(before.files.count("masks/cam0/000000.json"));
  EXPECT_EQ(before.files.at("images/cam1/000001.png").rfind("m:6:", 0), 0u);
  EXPECT_TRUE(ChangedInputs(before, FingerprintCapture(cap)).empty());

  // Ground truth is no input.
  WriteTextFileAtomic(root / layout::GtJoints3d(0), "[]");
  EXPECT_TRUE(ChangedInputs(before, FingerprintCapture(cap)).empty());

  // One camera moved, a mask edited, one added, a frame rewritten.
  cap.views[1].cameras[0].cam_from_world.translation.x() += 1;
  WriteCapture(cap, root);
  WriteTextFileAtomic(root / layout::MaskInfo("cam0", 0), "{\"instances\": [ ]}");
  WriteTextFileAtomic(root / layout::Poses2d("cam1", 1), "[]");
  WriteTextFileAtomic(cap.ImagePath(0, 1), "other pixels");
  EXPECT_EQ(ChangedInputs(before, FingerprintCapture(cap)),
            (std::vector<std::string>{"calibration.json", "images/cam0/000001.png",
                                      "masks/cam0/000000.json", "poses2d/cam1/000001.json"}));

  // A removed frame is "absent", and so differs.
  const InputFingerprint full = FingerprintCapture(cap);
  fs::remove(cap.ImagePath(1, 0));
  const InputFingerprint missing = FingerprintCapture(cap);
  EXPECT_EQ(missing.files.at("images/cam1/000000.png"), "absent");
  EXPECT_EQ(ChangedInputs(full, missing), (std::vector<std::string>{"images/cam1/000000.png"}));
}

TEST(InputFingerprintTest, RoundTripsThroughJsonAndRejectsOtherFiles) {
  InputFingerprint fp;
  fp.files = {{"calibration.json", "c:0123456789abcdef"}, {"images/a/000000.png", "m:5:17"}};
  EXPECT_TRUE(ChangedInputs(fp, FingerprintFromJson(FingerprintToJson(fp), "inputs.json")).empty());
  test_util::ExpectErrorMentions(
      [] { FingerprintFromJson(nlohmann::json::array(), "inputs.json"); }, {"inputs.json"});
  test_util::ExpectErrorMentions(
      [] {
        FingerprintFromJson({{"format", "u4d-inputs"}, {"files", {{"a", 7}}}}, "inputs.json");
      },
      {"inputs.json", "'a'"});
}

}  // namespace
}  // namespace u4d
