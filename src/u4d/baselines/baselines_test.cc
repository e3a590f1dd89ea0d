// The baselines (flow_baselines.h, grabcut_baseline.h) against the GT of a
// synthetic handshake capture.
#include <cstdio>
#include <set>

#include <gtest/gtest.h>

#include "u4d/baselines/flow_baselines.h"
#include "u4d/baselines/grabcut_baseline.h"
#include "u4d/eval/dense_metrics.h"
#include "u4d/eval/segmentation_metrics.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/util/testing.h"

namespace u4d::baselines {
namespace {

class BaselinesTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Script frames 128-130: the people walk apart (up to ~4 px/frame); the
    // default window is centred on the handshake, where they barely move.
    synth::SynthOptions o = synth::SmallHandshakeOptions(3, 320, 180, 3);
    o.start_frame = 128;
    dir_ = test_util::RemovedAtExit(synth::WriteCaptureToTempDir("eval_baselines_test", o));
    capture_ = ReadCapture(dir_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static inline fs::path dir_;
  static inline Capture capture_;
};

// Every baseline must explain part of the motion of the people: its EPE on
// GT-valid person pixels is below that of the zero flow (summed over views
// and frame pairs). No tighter bound: the baselines are what E_f is compared
// with, their accuracy is reported, not required.
TEST_F(BaselinesTest, FlowBeatsZeroFlowOnPeople) {
  for (FlowBaseline b : AllFlowBaselines()) {
    eval::FlowMetrics m, zero;
    for (int v = 0; v < capture_.NumViews(); ++v)
      for (int t = 0; t + 1 < capture_.num_frames; ++t) {
        const std::string& name = capture_.views[v].name;
        const cv::Mat a = ReadColorImage(capture_.ImagePath(v, t));
        const cv::Mat c = ReadColorImage(capture_.ImagePath(v, t + 1));
        const cv::Mat flow = BaselineFlow(b, a, c);
        ASSERT_EQ(flow.type(), CV_32FC2);
        ASSERT_EQ(flow.size(), a.size());
        const cv::Mat gt = ReadFlo(dir_ / layout::GtFlow(name, t));
        const cv::Mat valid = ReadMaskImage(dir_ / layout::GtFlowValid(name, t));
        const cv::Mat person = ReadLabelImage(dir_ / layout::GtInstances(name, t)) != 0;
        m.Add(eval::EvaluateFlow(flow, gt, valid, person, "baseline"));
        zero.Add(eval::EvaluateFlow(cv::Mat(gt.size(), CV_32FC2, cv::Scalar(0, 0)), gt, valid,
                                    person, "zero"));
      }
    std::printf("%-10s EPE on people %.3f px (zero flow %.3f px, %ld pixels)\n",
                ToString(b).c_str(), m.Epe(), zero.Epe(), static_cast<long>(m.evaluated));
    EXPECT_LT(m.Epe(), zero.Epe()) << ToString(b);
  }
}

TEST(FlowBaselineNames, RoundTripAndUnknown) {
  for (FlowBaseline b : AllFlowBaselines()) EXPECT_EQ(FlowBaselineFromString(ToString(b)), b);
  test_util::ExpectErrorMentions([] { FlowBaselineFromString("raft"); }, {"raft", "deepflow"});
}

TEST(FlowBaselineInputs, BadImagesThrow) {
  const cv::Mat a(20, 30, CV_8UC3, cv::Scalar(0)), b(20, 31, CV_8UC3, cv::Scalar(0));
  test_util::ExpectErrorMentions([&] { BaselineFlow(FlowBaseline::kDis, a, b); },
                                 {"30x20", "31x20"});
  test_util::ExpectErrorMentions([&] { BaselineFlow(FlowBaseline::kDis, cv::Mat(), a); },
                                 {"image_t", "empty"});
  test_util::ExpectErrorMentions(
      [&] { BaselineFlow(FlowBaseline::kDis, cv::Mat(20, 30, CV_32FC1), a); }, {"8-bit"});
}

// GrabCut on the degraded initial masks: the mean instance IoU against the GT
// before and after is printed (the comparison the issue asks for); asserted is
// only the contract: CV_16U, same size, every id from the input set.
TEST_F(BaselinesTest, GrabCutRefinesInitialMasks) {
  eval::InstanceSegAccumulator before, after;
  for (int v = 0; v < capture_.NumViews(); ++v)
    for (int t = 0; t < capture_.num_frames; ++t) {
      const std::string& name = capture_.views[v].name;
      const fs::path png = dir_ / layout::Mask(name, t);
      if (!fs::exists(png)) continue;
      const InstanceMask initial = ReadInstanceMask(png, dir_ / layout::MaskInfo(name, t));
      const InstanceMask gt = ReadInstanceMask(dir_ / layout::GtInstances(name, t),
                                               dir_ / layout::GtInstancesInfo(name, t));
      const cv::Mat image = ReadColorImage(capture_.ImagePath(v, t));
      InstanceMask refined = initial;
      refined.ids = GrabCutInstances(image, initial.ids);
      ASSERT_EQ(refined.ids.type(), CV_16UC1);
      ASSERT_EQ(refined.ids.size(), image.size());
      std::set<int> in_ids, out_ids;
      for (int y = 0; y < image.rows; ++y)
        for (int x = 0; x < image.cols; ++x) {
          in_ids.insert(initial.ids.at<uint16_t>(y, x));
          out_ids.insert(refined.ids.at<uint16_t>(y, x));
        }
      for (int id : out_ids) EXPECT_TRUE(in_ids.count(id)) << "id " << id << " not in the input";
      before.Add(eval::EvaluateInstances(initial, gt, eval::InstanceSegOptions{}, png.string()));
      after.Add(eval::EvaluateInstances(refined, gt, eval::InstanceSegOptions{}, png.string()));
    }
  ASSERT_GT(before.num_gt, 0);
  std::printf("GrabCut: mean instance IoU %.3f -> %.3f over %d GT instances (%d images)\n",
              before.MeanInstanceIoU(), after.MeanInstanceIoU(), before.num_gt, before.num_images);
  // The degraded masks have noisy boundaries and cut limbs while the people
  // stand out in colour from the room: GrabCut seeded with them should move
  // towards the truth, or it is no baseline worth comparing against.
  EXPECT_GT(after.MeanInstanceIoU(), before.MeanInstanceIoU());
}

TEST(GrabCutInputs, BadInputsThrow) {
  const cv::Mat image(20, 30, CV_8UC3, cv::Scalar(0));
  test_util::ExpectErrorMentions(
      [&] { GrabCutInstances(image, cv::Mat(20, 30, CV_8UC1, cv::Scalar(0))); }, {"CV_16UC1"});
  test_util::ExpectErrorMentions(
      [&] { GrabCutInstances(image, cv::Mat(21, 30, CV_16UC1, cv::Scalar(0))); }, {"30x20"});
  GrabCutOptions o;
  o.iterations = 0;
  test_util::ExpectErrorMentions(
      [&] { GrabCutInstances(image, cv::Mat(20, 30, CV_16UC1, cv::Scalar(0)), o); },
      {"iterations"});
  // No instance: nothing to refine.
  EXPECT_EQ(cv::countNonZero(GrabCutInstances(image, cv::Mat(20, 30, CV_16UC1, cv::Scalar(0)))), 0);
}

}  // namespace
}  // namespace u4d::baselines
