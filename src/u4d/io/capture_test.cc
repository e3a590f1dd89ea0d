#include "u4d/io/capture.h"

#include <gtest/gtest.h>

#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/tiny_capture_test_util.h"
#include "u4d/util/check.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

fs::path FreshDir(const std::string& name) { return test_util::FreshTestDir("capture_test", name); }

Capture TwoViewCapture() { return test_util::TinyTwoViewCapture(); }

TEST(Capture, RoundTripAndFrames) {
  const fs::path dir = FreshDir("roundtrip");
  Capture c = TwoViewCapture();
  WriteCapture(c, dir);
  for (int v = 0; v < 2; ++v)
    for (int f = 0; f < 2; ++f)
      WriteImage(dir / layout::Image(c.views[v].name, f), cv::Mat(6, 8, CV_8UC3, cv::Scalar(f)));
  const Capture back = ReadCapture(dir);
  ASSERT_EQ(back.NumViews(), 2);
  EXPECT_EQ(back.num_frames, 2);
  EXPECT_LT((back.views[1].cameras[0].K - c.views[1].cameras[0].K).norm(), 1e-12);
  FrameReader reader(back);
  EXPECT_EQ(reader.Read(1, 1).at<cv::Vec3b>(0, 0)[0], 1);
}

// source_frames round-trips; a gap of more than max_gap_s seconds at the
// capture's fps is a cut; a list of the wrong length or not increasing is
// an error naming the file.
TEST(Capture, SourceFramesMarkCutsInTime) {
  const fs::path dir = FreshDir("source_frames");
  Capture c = TwoViewCapture();
  c.num_frames = 4;
  c.fps = 25;
  c.source_frames = {100, 101, 125, 1000};
  WriteCapture(c, dir);
  const Capture back = ReadCapture(dir);
  EXPECT_EQ(back.source_frames, c.source_frames);
  EXPECT_FALSE(ContinuesFrom(back, 0, 1.0));
  EXPECT_TRUE(ContinuesFrom(back, 1, 1.0));
  EXPECT_TRUE(ContinuesFrom(back, 2, 1.0));  // 24 frames = 0.96 s
  EXPECT_FALSE(ContinuesFrom(back, 2, 0.5));
  EXPECT_FALSE(ContinuesFrom(back, 3, 1.0));  // 35 s
  EXPECT_THROW(ContinuesFrom(back, 4, 1.0), Error);
  c.source_frames.clear();  // consecutive frames
  EXPECT_TRUE(ContinuesFrom(c, 3, 1e-9));

  nlohmann::json manifest = ReadJsonFile(dir / "capture.json");
  for (const nlohmann::json& bad : {nlohmann::json{1, 2, 3}, nlohmann::json{1, 2, 2, 3},
                                    nlohmann::json{-1, 2, 3, 4}, nlohmann::json{1, 2, 3.5, 4}}) {
    manifest["source_frames"] = bad;
    WriteJsonFileAtomic(dir / "capture.json", manifest);
    test_util::ExpectErrorMentions([&] { ReadCapture(dir); },
                                   {(dir / "capture.json").string(), "source_frames"});
  }
}

TEST(Capture, BadInputsNameTheProblem) {
  const fs::path dir = FreshDir("bad");
  Capture c = TwoViewCapture();
  WriteCapture(c, dir);
  // Missing frame file: the error names it.
  FrameReader reader(ReadCapture(dir));
  try {
    reader.Read(0, 1);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("000001.png"), std::string::npos) << e.what();
  }
  // Wrong image size.
  WriteImage(dir / layout::Image("cam0", 0), cv::Mat(5, 8, CV_8UC3));
  EXPECT_THROW(reader.Read(0, 0), Error);

  // NaN in K.
  nlohmann::json calib = ReadJsonFile(dir / "calibration.json");
  calib["cameras"][0]["K"][0][0] = nullptr;
  WriteJsonFileAtomic(dir / "calibration.json", calib);
  EXPECT_THROW(ReadCapture(dir), Error);

  // Wrong matrix size.
  calib = CalibrationToJson(c);
  calib["cameras"][1]["R"] = {1, 0, 0, 0, 1, 0};
  WriteJsonFileAtomic(dir / "calibration.json", calib);
  try {
    ReadCapture(dir);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'R' must have 9 numbers, found 6"), std::string::npos)
        << e.what();
  }

  // Moving camera with a frame-count mismatch.
  c.views[0].cameras.resize(3, c.views[0].cameras[0]);
  EXPECT_THROW(c.Check("test"), Error);
}

// Each malformed manifest or calibration found by the mutation fuzzer is a
// u4d::Error naming the file and the field, not a nlohmann or fmt exception.
TEST(Capture, MalformedJsonIsAnErrorNamingFileAndField) {
  using test_util::ExpectErrorMentions;
  const fs::path dir = FreshDir("malformed");
  const Capture c = TwoViewCapture();
  WriteCapture(c, dir);
  const nlohmann::json manifest = ReadJsonFile(dir / "capture.json");
  const nlohmann::json calib = ReadJsonFile(dir / "calibration.json");
  const auto with_manifest = [&](const nlohmann::json& m) {
    WriteJsonFileAtomic(dir / "capture.json", m);
    WriteJsonFileAtomic(dir / "calibration.json", calib);
  };
  const auto with_calib = [&](const nlohmann::json& k) {
    WriteJsonFileAtomic(dir / "capture.json", manifest);
    WriteJsonFileAtomic(dir / "calibration.json", k);
  };
  const auto read = [&] { ReadCapture(dir); };

  with_manifest(nlohmann::json::array({manifest}));
  ExpectErrorMentions(read, {"capture.json", "expected a JSON object", "array"});
  nlohmann::json m = manifest;
  m["views"][0]["first_index"] = "3";
  with_manifest(m);
  ExpectErrorMentions(read, {"capture.json", "view cam0", "'first_index'", "must be an integer"});
  m = manifest;
  m["views"][1]["path"] = "images/cam1/{:06q}.png";
  with_manifest(m);
  ExpectErrorMentions(read, {"capture.json", "view cam1", "invalid path pattern", "{:06q}"});
  m = manifest;
  m["num_frames"] = 3e9;
  with_manifest(m);
  ExpectErrorMentions(read, {"capture.json", "'num_frames'", "out of range"});
  m["num_frames"] = 2.5;
  with_manifest(m);
  ExpectErrorMentions(read, {"capture.json", "'num_frames'", "must be an integer"});
  m = manifest;
  m["views"] = 7;
  with_manifest(m);
  ExpectErrorMentions(read, {"capture.json", "'views'", "must be an array"});
  with_calib(calib);
  WriteTextFileAtomic(dir / "capture.json", "{\"format\": \"u4d-capture\", \"fps\": 1e999}");
  ExpectErrorMentions(read, {"capture.json", "invalid JSON"});

  nlohmann::json k = calib;
  k["cameras"][0]["view"] = 7;
  with_calib(k);
  ExpectErrorMentions(read, {"calibration.json", "'view'", "must be a string"});
  k = calib;
  k["cameras"][1]["width"] = 99999999;
  with_calib(k);
  ExpectErrorMentions(read, {"calibration.json", "view cam1", "'width'", "[1, 99999]"});
  k = calib;
  k["cameras"] = nlohmann::json::object();
  with_calib(k);
  ExpectErrorMentions(read, {"calibration.json", "'cameras'", "must be an array"});
  k = calib;
  k["cameras"][0]["per_frame"] = "x";
  with_calib(k);
  ExpectErrorMentions(read, {"calibration.json", "view cam0", "'per_frame'", "must be an array"});
}

// A camera in calibration.json for a view that capture.json does not list
// (usually a typo in a view name) is an error naming it, not ignored.
TEST(Capture, ExtraCameraIsAnError) {
  const fs::path dir = FreshDir("extra_camera");
  const Capture c = TwoViewCapture();
  WriteCapture(c, dir);
  nlohmann::json calib = ReadJsonFile(dir / "calibration.json");
  nlohmann::json extra = calib["cameras"][1];
  extra["view"] = "cam9";
  calib["cameras"].push_back(extra);
  WriteJsonFileAtomic(dir / "calibration.json", calib);
  test_util::ExpectErrorMentions([&] { ReadCapture(dir); },
                                 {"calibration.json", "camera for view 'cam9'", "does not list"});
  calib["cameras"][2]["view"] = "cam1";  // a second record for cam1
  WriteJsonFileAtomic(dir / "calibration.json", calib);
  test_util::ExpectErrorMentions([&] { ReadCapture(dir); },
                                 {"calibration.json", "view cam1", "more than one camera record"});
}

// Each pixel of the score image holds its instance's score; the background
// and an id without an entry hold 1.
TEST(InstanceMask, ScoreImageHoldsEachInstancesScore) {
  InstanceMask mask;
  mask.ids = cv::Mat::zeros(2, 4, CV_16U);
  mask.ids.at<uint16_t>(0, 1) = 3;
  mask.ids.at<uint16_t>(1, 2) = 5;
  mask.ids.at<uint16_t>(1, 3) = 9;  // not listed
  mask.instances = {{3, "person", 0.25}, {5, "box", 0.75}};
  const cv::Mat s = ScoreImage(mask);
  ASSERT_EQ(s.type(), CV_32F);
  EXPECT_EQ(s.at<float>(0, 1), 0.25f);
  EXPECT_EQ(s.at<float>(1, 2), 0.75f);
  EXPECT_EQ(s.at<float>(1, 3), 1.f);
  EXPECT_EQ(s.at<float>(0, 0), 1.f);
  EXPECT_TRUE(ScoreImage(InstanceMask{}).empty());
}

TEST(InstanceMask, MalformedJsonIsAnErrorNamingFileAndField) {
  using test_util::ExpectErrorMentions;
  const fs::path dir = FreshDir("mask");
  InstanceMask mask;
  mask.ids = cv::Mat(4, 4, CV_16UC1, cv::Scalar(0));
  mask.ids.at<uint16_t>(1, 1) = 3;
  mask.instances = {{3, "person", 0.5}};
  WriteInstanceMask(dir / "m.png", dir / "m.json", mask);
  EXPECT_EQ(ReadInstanceMask(dir / "m.png", dir / "m.json").instances.at(0).score, 0.5);
  const auto with = [&](const std::string& text) {
    WriteTextFileAtomic(dir / "m.json", text);
    return [&] { ReadInstanceMask(dir / "m.png", dir / "m.json"); };
  };
  ExpectErrorMentions(with(R"({"instances": [{"id": 3, "class": 2}]})"),
                      {"m.json", "'class'", "must be a string"});
  ExpectErrorMentions(with(R"({"instances": [{"id": 3, "score": "high"}]})"),
                      {"m.json", "'score'", "must be a number"});
  ExpectErrorMentions(with(R"({"instances": [{"id": 3, "score": 1e999}]})"),
                      {"m.json", "invalid JSON"});
  ExpectErrorMentions(with(R"({"instances": [{"id": 4294967299}]})"),
                      {"m.json", "'id'", "out of range"});
  ExpectErrorMentions(with(R"({"instances": [7]})"), {"m.json", "expected a JSON object"});
  ExpectErrorMentions(with(R"([1, 2])"), {"m.json", "expected a JSON object"});
  ExpectErrorMentions(with(R"({"instances": {}})"), {"m.json", "'instances'", "must be an array"});
  // The sidecar alone is read with the same checks; the image's ids are
  // checked against it only with the image.
  WriteTextFileAtomic(dir / "m.json", R"({"instances": [{"id": 5, "score": 0.25}]})");
  const std::vector<InstanceInfo> info = ReadInstanceInfo(dir / "m.json");
  ASSERT_EQ(info.size(), 1u);
  EXPECT_EQ(info[0].id, 5);
  EXPECT_EQ(info[0].label, "person");
  EXPECT_EQ(info[0].score, 0.25);
  ExpectErrorMentions([&] { ReadInstanceMask(dir / "m.png", dir / "m.json"); },
                      {"m.json", "id 3", "not listed"});
  WriteTextFileAtomic(dir / "m.json", R"({"instances": [{"id": 5}, {"id": 5}]})");
  ExpectErrorMentions([&] { ReadInstanceInfo(dir / "m.json"); }, {"m.json", "listed twice"});
}

}  // namespace
}  // namespace u4d
