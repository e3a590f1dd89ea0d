#include "u4d/eval/dense_metrics.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

TEST(Depth, HandImage) {
  // (0,0): 1.005 vs 1 -> rel 0.005, err 0.005; (1,0): 2.2 vs 2 -> rel 0.1,
  // err 0.2; (0,1): no prediction; (1,1): no GT.
  const cv::Mat gt = (cv::Mat_<float>(2, 2) << 1.0f, 2.0f, 4.0f, 0.0f);
  const cv::Mat pred = (cv::Mat_<float>(2, 2) << 1.005f, 2.2f, 0.0f, 5.0f);
  const DepthMetrics m = EvaluateDepth(pred, gt, {}, "test");
  EXPECT_EQ(m.gt_valid, 3);
  EXPECT_EQ(m.evaluated, 2);
  EXPECT_NEAR(m.AbsRel(), (0.005 + 0.1) / 2, 1e-6);
  EXPECT_NEAR(m.Rmse(), std::sqrt((0.005 * 0.005 + 0.2 * 0.2) / 2), 1e-6);
  EXPECT_DOUBLE_EQ(m.Delta1Pct(), 0.5);
  EXPECT_DOUBLE_EQ(m.Delta5Pct(), 0.5);
  EXPECT_NEAR(m.Completeness(), 2.0 / 3.0, 1e-12);
  // Masked to pixel (1,0) only.
  const cv::Mat mask = (cv::Mat_<uint8_t>(2, 2) << 0, 255, 0, 0);
  const DepthMetrics k = EvaluateDepth(pred, gt, mask, "test");
  EXPECT_EQ(k.evaluated, 1);
  EXPECT_NEAR(k.AbsRel(), 0.1, 1e-6);
  EXPECT_DOUBLE_EQ(k.Delta5Pct(), 0.0);
  // Pooling is pixel-weighted: sums, not a mean of means.
  DepthMetrics pooled = m;
  pooled.Add(k);
  EXPECT_NEAR(pooled.AbsRel(), (0.005 + 0.1 + 0.1) / 3, 1e-6);
  // No prediction at all: completeness 0, errors undefined.
  const DepthMetrics none = EvaluateDepth({}, gt, {}, "test");
  EXPECT_EQ(none.Completeness(), 0.0);
  EXPECT_TRUE(std::isnan(none.AbsRel()));
}

TEST(Depth, BadInputsThrowNamingTheFile) {
  cv::Mat gt = (cv::Mat_<float>(1, 2) << 1.0f, 2.0f);
  cv::Mat pred = (cv::Mat_<float>(1, 2) << std::numeric_limits<float>::quiet_NaN(), 2.0f);
  try {
    EvaluateDepth(pred, gt, {}, "pred/depth/cam0/000000.pfm");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("pred/depth/cam0/000000.pfm"), std::string::npos);
  }
  EXPECT_THROW(EvaluateDepth(cv::Mat::ones(2, 2, CV_32FC1), gt, {}, "x"), Error);
  EXPECT_THROW(EvaluateDepth({}, -gt, {}, "x"), Error);
}

TEST(Flow, HandEpe) {
  // EPE 5 (3-4-5 triangle) and 0.5.
  cv::Mat gt(1, 2, CV_32FC2, cv::Scalar(0, 0));
  gt.at<cv::Vec2f>(0, 1) = {1, 0};
  cv::Mat pred(1, 2, CV_32FC2);
  pred.at<cv::Vec2f>(0, 0) = {3, 4};
  pred.at<cv::Vec2f>(0, 1) = {1.5f, 0};
  const FlowMetrics m = EvaluateFlow(pred, gt, {}, {}, "test");
  EXPECT_NEAR(m.Epe(), 2.75, 1e-6);
  EXPECT_DOUBLE_EQ(m.Within1Px(), 0.5);
  EXPECT_DOUBLE_EQ(m.Within3Px(), 0.5);
  EXPECT_DOUBLE_EQ(m.Beyond10Px(), 0.0);  // 5 px is not a gross error
  EXPECT_DOUBLE_EQ(m.Completeness(), 1.0);
  cv::Mat far = pred.clone();
  far.at<cv::Vec2f>(0, 0) = {6, 8.5f};  // EPE 10.41
  EXPECT_DOUBLE_EQ(EvaluateFlow(far, gt, {}, {}, "test").Beyond10Px(), 0.5);
  const cv::Mat valid = (cv::Mat_<uint8_t>(1, 2) << 0, 255);
  EXPECT_NEAR(EvaluateFlow(pred, gt, valid, {}, "test").Epe(), 0.5, 1e-6);
  const cv::Mat mask = (cv::Mat_<uint8_t>(1, 2) << 255, 0);
  EXPECT_NEAR(EvaluateFlow(pred, gt, {}, mask, "test").Epe(), 5.0, 1e-6);
  pred.at<cv::Vec2f>(0, 0) = {std::numeric_limits<float>::quiet_NaN(), 0};
  const FlowMetrics half = EvaluateFlow(pred, gt, {}, {}, "test");
  EXPECT_DOUBLE_EQ(half.Completeness(), 0.5);
  EXPECT_NEAR(half.Epe(), 0.5, 1e-6);
  EXPECT_THROW(EvaluateFlow(cv::Mat(2, 2, CV_32FC2), gt, {}, {}, "x"), Error);
}

TEST(Flow, MotionScaleTellsAShrunkFlowFromANoisyOne) {
  // Truth: a 10 px motion to the right on 4 pixels, a 0.5 px one (too short
  // to have a direction that counts) on a fifth.
  cv::Mat gt(1, 5, CV_32FC2, cv::Scalar(10, 0));
  gt.at<cv::Vec2f>(0, 4) = {0.5f, 0};
  // The motion shrunk by a fifth: EPE 2 on the moving pixels.
  cv::Mat shrunk = gt * 0.8;
  shrunk.at<cv::Vec2f>(0, 4) = {-3, 0};  // whatever the short one does, it does not count
  EXPECT_NEAR(EvaluateFlow(shrunk, gt, {}, {}, "test").MotionScale(), 0.8, 1e-9);
  // The same EPE across the motion, half up and half down: no bias.
  cv::Mat noisy = gt.clone();
  for (int x = 0; x < 4; ++x) noisy.at<cv::Vec2f>(0, x)[1] = x % 2 ? 2.f : -2.f;
  const FlowMetrics m = EvaluateFlow(noisy, gt, {}, {}, "test");
  EXPECT_NEAR(m.MotionScale(), 1.0, 1e-9);
  EXPECT_NEAR(m.Epe(), 1.6, 1e-6);  // 4 x 2 px over 5 pixels
  // Pooled over images by their true lengths: 0.8 x 40 + 1.0 x 40 over 80.
  FlowMetrics both = EvaluateFlow(shrunk, gt, {}, {}, "test");
  both.Add(m);
  EXPECT_NEAR(both.MotionScale(), 0.9, 1e-9);
  // A still scene has no motion to scale.
  const cv::Mat still(1, 2, CV_32FC2, cv::Scalar(0, 0));
  EXPECT_TRUE(std::isnan(EvaluateFlow(still, still, {}, {}, "test").MotionScale()));
}

}  // namespace
}  // namespace u4d::eval
