#include "u4d/io/clean_plate.h"

#include <gtest/gtest.h>

#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

cv::Mat Flat(int value, int width = 8, int height = 6) {
  return cv::Mat(height, width, CV_8UC3, cv::Scalar(value, value, value));
}

TEST(CleanPlateTest, ReadsOnePictureOrTheFramesOfAFolderInNameOrder) {
  const fs::path root = test_util::FreshTestDir("clean_plate_test", "layouts");
  EXPECT_TRUE(ReadCleanPlate(root, "cam0", 8, 6).empty());  // no plate: none

  WriteImage(root / layout::CleanPlateDir() / "cam0.png", Flat(40));
  const std::vector<cv::Mat> one = ReadCleanPlate(root, "cam0", 8, 6);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].at<cv::Vec3b>(2, 3), cv::Vec3b(40, 40, 40));

  const fs::path dir = root / layout::CleanPlateDir() / "cam1";
  WriteImage(dir / "b.png", Flat(20));
  WriteImage(dir / "a.png", Flat(10));
  WriteTextFileAtomic(dir / "notes.txt", "not a picture: ignored");
  const std::vector<cv::Mat> frames = ReadCleanPlate(root, "cam1", 8, 6);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].at<cv::Vec3b>(0, 0)[0], 10);
  EXPECT_EQ(frames[1].at<cv::Vec3b>(0, 0)[0], 20);
}

TEST(CleanPlateTest, AWrongSizeOrAnEmptyFolderIsAnErrorNamingTheFile) {
  const fs::path root = test_util::FreshTestDir("clean_plate_test", "errors");
  WriteImage(root / layout::CleanPlateDir() / "cam0.png", Flat(40, 9, 6));
  test_util::ExpectErrorMentions([&] { ReadCleanPlate(root, "cam0", 8, 6); },
                                 {"cam0.png", "9x6", "8x6"});
  fs::create_directories(root / layout::CleanPlateDir() / "cam1");
  test_util::ExpectErrorMentions([&] { ReadCleanPlate(root, "cam1", 8, 6); },
                                 {"cam1", "no .png or .jpg"});
}

}  // namespace
}  // namespace u4d
