// The inputs that made a libFuzzer target crash (fuzz/regressions/<target>/,
// scripts/fuzz.sh) are read again here, in the ordinary build, by the readers
// that target fuzzes: each must be read or rejected with u4d::Error, never
// end in another exception or a crash. Add a crash input to the folder of
// its target and it is tested here.
#include <functional>
#include <map>

#include <gtest/gtest.h>

#include "u4d/io/image_io.h"
#include "u4d/io/import_calibration.h"
#include "u4d/io/import_fourda.h"
#include "u4d/io/mesh_sequence.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

const fs::path kFuzz = fs::path(U4D_SOURCE_DIR) / "fuzz";

// Calls `read`, accepting a u4d::Error; any other exception fails the test.
void ExpectReadOrError(const fs::path& input, const std::function<void()>& read) {
  try {
    read();
  } catch (const Error&) {
  } catch (const std::exception& e) {
    ADD_FAILURE() << input << ": " << e.what();
  }
}

// Runs `read` on every regression input of `target`; returns how many.
int ForEachRegression(const std::string& target, const std::function<void(const fs::path&)>& read) {
  int n = 0;
  const fs::path dir = kFuzz / "regressions" / target;
  if (!fs::is_directory(dir)) return 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    read(e.path());
    ++n;
  }
  return n;
}

TEST(FuzzRegressions, ImportText) {
  const int n = ForEachRegression("import_text", [](const fs::path& p) {
    ExpectReadOrError(p, [&] { ReadQualisysCalibration(p); });
    ExpectReadOrError(p, [&] { ReadMiddleburyCalibration(p, 640, 480); });
    ExpectReadOrError(p, [&] { ReadFourdaGroundTruth(p); });
    ExpectReadOrError(p, [&] { ReadFourdaDetections(p); });
  });
  EXPECT_GE(n, 1);
}

// As fuzz/mask_png_fuzz.cc: the input as a mask's PNG of instance ids.
TEST(FuzzRegressions, MaskPng) {
  const int n = ForEachRegression("mask_png", [](const fs::path& p) {
    ExpectReadOrError(p, [&] { ReadLabelImage(p); });
    ExpectReadOrError(p, [&] { ReadMaskImage(p); });
  });
  EXPECT_GE(n, 1);
}

// As fuzz/mesh_fuzz.cc: the input as a PLY and as an OBJ mesh file. (The
// PLY element without properties that claims 10^12 entries looped in the
// fuzzer's build; an optimised build drops the empty loop, so here it is a
// read-or-error check only.)
TEST(FuzzRegressions, Mesh) {
  const int n = ForEachRegression("mesh", [](const fs::path& p) {
    const fs::path dir = test_util::FreshTestDir("fuzz_regressions", "mesh");
    for (const char* name : {"input.ply", "input.obj"}) {
      fs::copy_file(p, dir / name);
      ExpectReadOrError(p, [&] { ReadMeshFile(dir / name); });
    }
  });
  EXPECT_GE(n, 1);
}

// As fuzz/easymocap_fuzz.cc: the input as intri.yml beside a valid
// extri.yml, then as extri.yml beside a valid intri.yml.
TEST(FuzzRegressions, EasyMocap) {
  const fs::path intri = kFuzz / "corpus/easymocap/intri.yml";
  const fs::path extri = kFuzz / "corpus/easymocap/extri.yml";
  ASSERT_EQ(ReadEasyMocapCalibration(intri, extri).size(), 2u);
  const int n = ForEachRegression("easymocap", [&](const fs::path& p) {
    const fs::path dir = test_util::FreshTestDir("fuzz_regressions", "easymocap");
    // OpenCV picks the format from the extension.
    fs::copy_file(p, dir / "input.yml");
    ExpectReadOrError(p, [&] { ReadEasyMocapCalibration(dir / "input.yml", extri); });
    ExpectReadOrError(p, [&] { ReadEasyMocapCalibration(intri, dir / "input.yml"); });
  });
  EXPECT_GE(n, 1);
}

}  // namespace
}  // namespace u4d
