// The chroma key (chroma_key.h): on constructed images whose backdrop,
// shadow and spill pixels are known, and on a synthetic keyed stage
// (synth's UseKeyedStage: green screen, spill on the people, soft floor
// shadows) against its ground-truth people, without masks.
#include <cstdio>

#include <gtest/gtest.h>

#include "u4d/init/chroma_key.h"
#include "u4d/init/init.h"
#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/import_calibration.h"
#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

using test_util::ExpectErrorMentions;

const cv::Vec3b kScreen(65, 177, 81);  // BGR of a lit green screen

cv::Vec3b Scaled(const cv::Vec3b& c, double s) {
  return {cv::saturate_cast<uint8_t>(c[0] * s), cv::saturate_cast<uint8_t>(c[1] * s),
          cv::saturate_cast<uint8_t>(c[2] * s)};
}

// `c` moved towards the screen colour (at c's brightness) by `s`: spill.
cv::Vec3b Spilled(const cv::Vec3b& c, double s) {
  const double sum = static_cast<double>(c[0]) + c[1] + c[2];
  const double key_sum = static_cast<double>(kScreen[0]) + kScreen[1] + kScreen[2];
  cv::Vec3b out;
  for (int k = 0; k < 3; ++k)
    out[k] = cv::saturate_cast<uint8_t>(c[k] + s * (kScreen[k] * sum / key_sum - c[k]));
  return out;
}

// A 200x160 screen with, in its middle, patches whose class is known: a
// shadow on the screen (backdrop) and people's colours with spill
// (foreground).
struct Patch {
  const char* what;
  cv::Vec3b colour;
  bool backdrop;
};

TEST(ChromaKey, ShadowsAreBackdropSpillIsForeground) {
  const std::vector<Patch> patches = {
      {"soft shadow (x0.6)", Scaled(kScreen, 0.6), true},
      {"deep shadow (x0.3)", Scaled(kScreen, 0.3), true},
      {"brighter screen (x1.3)", Scaled(kScreen, 1.3), true},
      {"grey shirt, spill 0.3", Spilled({128, 128, 128}, 0.3), false},
      {"white shirt, spill 0.3", Spilled({235, 235, 235}, 0.3), false},
      {"skin, spill 0.3", Spilled({140, 170, 220}, 0.3), false},
      {"red top, spill 0.3", Spilled({40, 40, 200}, 0.3), false},
      {"blue jeans, spill 0.3", Spilled({130, 80, 50}, 0.3), false},
      {"dark hair, spill 0.3", Spilled({20, 25, 30}, 0.3), false},
      {"black", {3, 4, 3}, false},
  };
  cv::Mat image(160, 200 + 20 * static_cast<int>(patches.size()), CV_8UC3, kScreen);
  for (size_t i = 0; i < patches.size(); ++i)
    image(cv::Rect(100 + 20 * static_cast<int>(i), 60, 20, 40)).setTo(patches[i].colour);
  const ChromaKey key = ChooseChromaKey({image}, ChromaKeyOptions(), "test");
  ASSERT_TRUE(key.keyed);
  EXPECT_NEAR(key.border_share, 1.0, 1e-9);
  EXPECT_LT((key.chroma - Chroma(kScreen)).norm(), 1e-12);  // the screen's own colour
  const cv::Mat fg = ChromaKeyMask(image, key);
  for (size_t i = 0; i < patches.size(); ++i) {
    const cv::Mat patch = fg(cv::Rect(100 + 20 * static_cast<int>(i), 60, 20, 40));
    EXPECT_EQ(cv::countNonZero(patch), patches[i].backdrop ? 0 : 20 * 40) << patches[i].what;
  }
  EXPECT_EQ(cv::countNonZero(fg(cv::Rect(0, 0, 100, 160))), 0);
}

TEST(ChromaKey, GivenColoursAndBadInput) {
  cv::Mat image(120, 160, CV_8UC3, cv::Scalar(200, 90, 40));  // a blue screen
  image(cv::Rect(60, 40, 30, 50)).setTo(cv::Scalar(60, 60, 200));
  ChromaKeyOptions blue;
  blue.colour = "blue";
  blue.mode = ChromaKeyOptions::Mode::kOn;
  const ChromaKey key = ChooseChromaKey({image}, blue, "v");
  ASSERT_TRUE(key.keyed);
  EXPECT_EQ(cv::countNonZero(ChromaKeyMask(image, key)), 30 * 50);
  // A green key on a blue screen finds no backdrop: mode on fails, naming the view.
  ChromaKeyOptions green = blue;
  green.colour = "#20B040";
  ExpectErrorMentions([&] { ChooseChromaKey({image}, green, "cam3"); },
                      {"cam3", "no saturated pixel", "#20B040"});
  green.mode = ChromaKeyOptions::Mode::kAuto;
  EXPECT_FALSE(ChooseChromaKey({image}, green, "cam3").keyed);
  ChromaKeyOptions bad;
  bad.colour = "greenish";
  ExpectErrorMentions([&] { bad.Check(); }, {"colour", "greenish"});
  bad = ChromaKeyOptions();
  bad.hue_tolerance_deg = 120;
  ExpectErrorMentions([&] { bad.Check(); }, {"hue_tolerance_deg"});
  ExpectErrorMentions([&] { ChromaKeyModeFromString("maybe"); }, {"off, auto or on", "maybe"});
  ExpectErrorMentions([&] { FindChromaKey({cv::Mat(4, 4, CV_8UC1)}, ChromaKeyOptions()); },
                      {"BGR"});
}

// Foreground IoU of the whole chain (keyed views, cross-view check, people
// on the ground plane) against the ground-truth union of people, pooled over
// every view and frame.
struct KeyedResult {
  double iou_key = 0;    // ChromaKeyMask alone (cleaned as step 2)
  double iou_chain = 0;  // UnsupervisedInstanceMasks
  int keyed_views = 0;
};

KeyedResult RunKeyed(const Capture& capture) {
  FrameReader reader(capture);
  const int nv = capture.NumViews();
  std::vector<Camera> cameras;
  std::vector<ChromaKey> keys;
  KeyedResult r;
  for (int v = 0; v < nv; ++v) {
    cameras.push_back(capture.views[v].CameraAt(0));
    std::vector<cv::Mat> frames;
    for (int t = 0; t < capture.num_frames; ++t) frames.push_back(reader.Read(v, t));
    keys.push_back(ChooseChromaKey(frames, ChromaKeyOptions(), capture.views[v].name));
    r.keyed_views += keys.back().keyed;
  }
  double i[2] = {0, 0}, u[2] = {0, 0};
  const std::vector<BackgroundModel> no_backgrounds(nv);
  for (int t = 0; t < capture.num_frames; ++t) {
    std::vector<cv::Mat> images;
    for (int v = 0; v < nv; ++v) images.push_back(reader.Read(v, t));
    const std::vector<cv::Mat> ids =
        UnsupervisedInstanceMasks(cameras, images, no_backgrounds, InitOptions(), keys);
    for (int v = 0; v < nv; ++v) {
      const cv::Mat gt =
          ReadInstanceMask(capture.root / layout::GtInstances(capture.views[v].name, t),
                           capture.root / layout::GtInstancesInfo(capture.views[v].name, t))
              .ids > 0;
      const cv::Mat key = keys[v].keyed ? ChromaKeyMask(images[v], keys[v]) > 0
                                        : cv::Mat(gt.size(), CV_8UC1, cv::Scalar(0));
      const cv::Mat chain = ids[v] > 0;
      i[0] += cv::countNonZero(gt & key);
      u[0] += cv::countNonZero(gt | key);
      i[1] += cv::countNonZero(gt & chain);
      u[1] += cv::countNonZero(gt | chain);
    }
  }
  r.iou_key = i[0] / u[0];
  r.iou_chain = i[1] / u[1];
  return r;
}

// The goal: a green-screen stage (spill, soft floor shadows) gives a
// foreground IoU >= 0.95 against ground truth without masks. The camera is
// the realistic preset's (sensor noise 2.5 grey levels, exposure differing
// by up to 8% between cameras, motion blur over half the frame interval),
// the people walk towards each other (frames 6-9 of the handshake at 25 fps).
TEST(ChromaKey, KeyedSyntheticStageWithoutMasks) {
  synth::SynthOptions o = synth::SmallHandshakeOptions(6, 320, 240, 4);
  o.start_frame = 6;
  o.render.noise_sigma = 2.5f;
  o.render.gain_jitter = 0.08f;
  o.effects.motion_blur_shutter = 0.5;
  synth::UseKeyedStage(&o);
  const Capture capture =
      ReadCapture(test_util::RemovedAtExit(synth::WriteCaptureToTempDir("chroma_key_test", o)));
  const KeyedResult r = RunKeyed(capture);
  std::printf("keyed stage: %d of %d views keyed; foreground IoU key alone %.4f, chain %.4f\n",
              r.keyed_views, capture.NumViews(), r.iou_key, r.iou_chain);
  EXPECT_EQ(r.keyed_views, capture.NumViews());
  EXPECT_GE(r.iou_chain, 0.95);
}

// The automatic choice leaves an ordinary stage (the synthetic room and the
// outdoor scene: textured walls and floor) unkeyed.
TEST(ChromaKey, AutoLeavesOrdinaryStagesUnkeyed) {
  for (const bool indoor : {true, false}) {
    synth::SynthOptions o = synth::SmallHandshakeOptions(4, 320, 240, 2);
    o.environment.indoor = indoor;
    const Capture capture = ReadCapture(test_util::RemovedAtExit(
        synth::WriteCaptureToTempDir(indoor ? "chroma_room" : "chroma_outdoor", o)));
    FrameReader reader(capture);
    for (int v = 0; v < capture.NumViews(); ++v) {
      const ChromaKey key = ChooseChromaKey({reader.Read(v, 0)}, ChromaKeyOptions(), "v");
      std::printf("%s view %d: border share of its best hue %.2f\n", indoor ? "room" : "outdoor", v,
                  key.border_share);
      EXPECT_FALSE(key.keyed) << (indoor ? "room" : "outdoor") << " view " << v;
    }
  }
}

// Real captures that are not keyed stay unkeyed: the Panoptic dome (grey
// walls, lamps) and the Pose2Sim room.
TEST(ChromaKey, AutoLeavesRealCapturesUnkeyed) {
  const fs::path panoptic = DataDir() / "panoptic_demo";
  const fs::path pose2sim = DataDir() / "pose2sim_single";
  U4D_SKIP_WITHOUT_SHARED_DATA(panoptic);
  U4D_SKIP_WITHOUT_SHARED_DATA(pose2sim);
  for (const fs::path& source : {panoptic, pose2sim}) {
    const Capture capture = source == panoptic ? ImportPanoptic(source) : ImportQualisys(source);
    FrameReader reader(capture);
    for (int v = 0; v < capture.NumViews(); ++v) {
      std::vector<cv::Mat> frames;
      for (int t = 0; t < std::min(capture.num_frames, 5); ++t) frames.push_back(reader.Read(v, t));
      const ChromaKey key = ChooseChromaKey(frames, ChromaKeyOptions(), capture.views[v].name);
      std::printf("%s %s: border share of its best hue %.2f (hue %.0f deg)\n",
                  source.filename().c_str(), capture.views[v].name.c_str(), key.border_share,
                  key.HueDegrees());
      EXPECT_FALSE(key.keyed) << source << " " << capture.views[v].name;
    }
  }
}

}  // namespace
}  // namespace u4d
