#include "u4d/io/image_io.h"

#include <fstream>
#include <set>

#include <gtest/gtest.h>

#include "u4d/io/label_ids.h"
#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

fs::path TempDir() {
  static const fs::path dir = test_util::FreshTestDir("image_io_test", "files");
  return dir;
}

void ExpectErrorMentions(const std::function<void()>& f, const std::string& needle) {
  test_util::ExpectErrorMentions(f, {needle});
}

// The ids of a label image: each nonzero value once, ascending, the largest
// 16-bit id included; none in an empty or all-background image.
TEST(LabelIds, ListTheNonzeroIdsOnce) {
  cv::Mat labels = cv::Mat::zeros(4, 5, CV_16U);
  labels.at<uint16_t>(0, 4) = 7;
  labels.at<uint16_t>(3, 0) = 2;
  labels.at<uint16_t>(2, 2) = 7;
  labels.at<uint16_t>(1, 1) = 65535;
  EXPECT_EQ(IdsIn(labels), (std::set<int>{2, 7, 65535}));
  EXPECT_TRUE(IdsIn(cv::Mat::zeros(3, 3, CV_16U)).empty());
  EXPECT_TRUE(IdsIn(cv::Mat()).empty());
}

TEST(ImageIo, FloRoundTripAndRealSintel) {
  cv::Mat flow(7, 5, CV_32FC2);
  cv::randu(flow, -10, 10);
  const fs::path path = TempDir() / "a.flo";
  WriteFlo(path, flow);
  cv::Mat back = ReadFlo(path);
  EXPECT_EQ(cv::norm(flow, back, cv::NORM_INF), 0.0);

  // Real MPI-Sintel ground truth: 1024x436, plausible magnitudes.
  const fs::path sintel = DataDir() / "sintel_flow/clean/easy/gt/frame_0002.flo";
  U4D_SKIP_WITHOUT_SHARED_DATA(sintel);
  cv::Mat gt = ReadFlo(sintel);
  EXPECT_EQ(gt.cols, 1024);
  EXPECT_EQ(gt.rows, 436);
  double lo = 0, hi = 0;
  cv::minMaxLoc(gt.reshape(1), &lo, &hi);
  EXPECT_GT(hi - lo, 1.0);
  EXPECT_LT(std::max(std::abs(lo), std::abs(hi)), 1000.0);
}

TEST(ImageIo, OnlyKnownFormatsReachTheDecoders) {
  const fs::path dir = TempDir();
  cv::Mat ids(3, 4, CV_16UC1, cv::Scalar(7));
  WriteImage(dir / "ids.png", ids);
  EXPECT_EQ(SniffImageFormat(dir / "ids.png"), ImageFormat::kPng);
  EXPECT_EQ(cv::norm(ReadLabelImage(dir / "ids.png"), ids, cv::NORM_INF), 0.0);
  // Instance ids and masks are PNG only; a JPEG named .png is refused by its bytes.
  WriteImage(dir / "frame.jpg", cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3)));
  fs::copy_file(dir / "frame.jpg", dir / "jpeg.png", fs::copy_options::overwrite_existing);
  EXPECT_EQ(SniffImageFormat(dir / "jpeg.png"), ImageFormat::kJpeg);
  EXPECT_EQ(ReadColorImage(dir / "jpeg.png").size(), cv::Size(8, 8));
  test_util::ExpectErrorMentions([&] { ReadLabelImage(dir / "jpeg.png"); },
                                 {"jpeg.png", "found JPEG", "expected PNG"});
  test_util::ExpectErrorMentions([&] { ReadMaskImage(dir / "jpeg.png"); }, {"expected PNG"});
  // A JPEG 2000 file (a format OpenCV could decode) never reaches its decoder.
  {
    std::ofstream out(dir / "j2k.png", std::ios::binary);
    out << std::string("\x00\x00\x00\x0cjP  \r\n\x87\n", 12) << std::string(64, '\0');
  }
  EXPECT_EQ(SniffImageFormat(dir / "j2k.png"), ImageFormat::kUnknown);
  test_util::ExpectErrorMentions([&] { ReadColorImage(dir / "j2k.png"); }, {"j2k.png", "unknown"});
}

TEST(ImageIo, AHugePngHeaderIsRefusedBeforeDecoding) {
  const fs::path dir = TempDir();
  WriteImage(dir / "small.png", cv::Mat(2, 2, CV_16UC1, cv::Scalar(1)));
  std::string bytes;
  {
    std::ifstream in(dir / "small.png", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  // IHDR width and height (big-endian at bytes 16 and 20): 60000 x 60000.
  for (int at : {16, 20}) bytes.replace(at, 4, std::string("\x00\x00\xea\x60", 4));
  { std::ofstream(dir / "huge.png", std::ios::binary) << bytes; }
  test_util::ExpectErrorMentions([&] { ReadLabelImage(dir / "huge.png"); },
                                 {"huge.png", "60000x60000"});
}

TEST(ImageIo, PfmRoundTrip) {
  cv::Mat depth(6, 9, CV_32FC1);
  cv::randu(depth, 0.5, 8.0);
  depth.at<float>(2, 3) = 0.0f;
  const fs::path path = TempDir() / "d.pfm";
  WritePfm(path, depth);
  EXPECT_EQ(cv::norm(depth, ReadPfm(path), cv::NORM_INF), 0.0);
}

TEST(ImageIo, BadFilesGiveClearErrors) {
  const fs::path dir = TempDir();
  ExpectErrorMentions([&] { ReadColorImage(dir / "missing.png"); }, "missing.png");
  { std::ofstream(dir / "corrupt.png") << "not a png at all"; }
  ExpectErrorMentions([&] { ReadColorImage(dir / "corrupt.png"); }, "corrupt");
  { std::ofstream(dir / "bad.flo") << "PIEH"; }
  ExpectErrorMentions([&] { ReadFlo(dir / "bad.flo"); }, "bad.flo");
  // A truncated .flo: valid header, too little data.
  {
    std::ofstream out(dir / "short.flo", std::ios::binary);
    const float magic = 202021.25f;
    const int32_t w = 100, h = 100;
    out.write(reinterpret_cast<const char*>(&magic), 4);
    out.write(reinterpret_cast<const char*>(&w), 4);
    out.write(reinterpret_cast<const char*>(&h), 4);
    out << "xxxx";
  }
  ExpectErrorMentions([&] { ReadFlo(dir / "short.flo"); }, "truncated");
  ExpectErrorMentions([&] { CheckImageSize(cv::Mat(4, 5, CV_8UC1), 6, 4, "img.png"); },
                      "expected size 6x4, found 5x4");
}

// A header announcing 99999x99999 over a few bytes of data is refused from
// the file size, before the 40-80 GB image would be allocated.
TEST(ImageIo, HugeHeadersOverShortDataAreRefusedBeforeAllocating) {
  const fs::path dir = TempDir();
  {
    std::ofstream out(dir / "huge.flo", std::ios::binary);
    const float magic = 202021.25f;
    const int32_t w = 99999, h = 99999;
    out.write(reinterpret_cast<const char*>(&magic), 4);
    out.write(reinterpret_cast<const char*>(&w), 4);
    out.write(reinterpret_cast<const char*>(&h), 4);
    out << "xxxxxxxx";
  }
  test_util::ExpectErrorMentions(
      [&] { ReadFlo(dir / "huge.flo"); },
      {"huge.flo", "truncated", "99999x99999", "79998400008 bytes", "but 8 bytes follow"});
  { std::ofstream(dir / "huge.pfm", std::ios::binary) << "PF\n99999 99999\n-1\nxxxx"; }
  test_util::ExpectErrorMentions([&] { ReadPfm(dir / "huge.pfm"); },
                                 {"huge.pfm", "truncated", "99999x99999x3", "but 4 bytes follow"});
  // Exactly one float short of a 2x2 single-channel map.
  { std::ofstream(dir / "short.pfm", std::ios::binary) << "Pf\n2 2\n-1\n" << std::string(12, 'a'); }
  test_util::ExpectErrorMentions([&] { ReadPfm(dir / "short.pfm"); },
                                 {"short.pfm", "(16 bytes)", "but 12 bytes follow"});
}

}  // namespace
}  // namespace u4d
