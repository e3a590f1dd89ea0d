#include "u4d/fusion/flow_consensus.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "u4d/fusion/fusion_test_util.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

using fusion_test::FrameMaps;

class FlowConsensusTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const Capture capture = ReadCapture(fusion_test::WriteSmallCapture("flow_consensus_test"));
    maps_ = new FrameMaps(fusion_test::ReadGtFrame(capture, 0));
  }
  static void TearDownTestSuite() { delete maps_; }

  // The GT views of frame 0 with `flows` (a static rig: the same camera at t and t+1).
  static std::vector<FlowConsensusView> Views(const std::vector<cv::Mat>& flows) {
    std::vector<FlowConsensusView> views;
    for (size_t v = 0; v < flows.size(); ++v)
      views.push_back(
          {maps_->cameras[v], maps_->cameras[v], maps_->ids[v], maps_->depths[v], flows[v]});
    return views;
  }

  // Mean end-point error against the GT flow over view v's pixels of `id` (0: all objects).
  static double Epe(const cv::Mat& flow, int v, int id = 0) {
    double sum = 0;
    long n = 0;
    for (int y = 0; y < flow.rows; ++y)
      for (int x = 0; x < flow.cols; ++x) {
        const int l = maps_->ids[v].at<uint16_t>(y, x);
        if (l == 0 || (id != 0 && l != id) || !(maps_->depths[v].at<float>(y, x) > 0)) continue;
        sum += cv::norm(flow.at<cv::Vec2f>(y, x) - maps_->flows[v].at<cv::Vec2f>(y, x));
        ++n;
      }
    return n ? sum / n : 0;
  }

  static double MedianError(const cv::Mat& flow, int v, int id) {
    std::vector<double> e;
    for (int y = 0; y < flow.rows; ++y)
      for (int x = 0; x < flow.cols; ++x)
        if (maps_->ids[v].at<uint16_t>(y, x) == id && maps_->depths[v].at<float>(y, x) > 0)
          e.push_back(cv::norm(flow.at<cv::Vec2f>(y, x) - maps_->flows[v].at<cv::Vec2f>(y, x)));
    std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
    return e[e.size() / 2];
  }

  static FrameMaps* maps_;
};

FrameMaps* FlowConsensusTest::maps_ = nullptr;

TEST_F(FlowConsensusTest, TheTrueFlowsStayTrue) {
  const std::vector<cv::Mat> out = FlowConsensus(Views(maps_->flows), {});
  for (size_t v = 0; v < out.size(); ++v) EXPECT_LT(Epe(out[v], static_cast<int>(v)), 0.05) << v;
}

TEST_F(FlowConsensusTest, TheOtherViewsOutvoteOneViewsWrongMotion) {
  // View 0 gives the person of id 1, who moves by a pixel or two, a motion of
  // 6 px (a match on the wrong object); every view's flow has its own noise.
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0, 0.5f);
  std::vector<cv::Mat> flows;
  for (const cv::Mat& gt : maps_->flows) {
    cv::Mat f = gt.clone();
    for (auto it = f.begin<cv::Vec2f>(); it != f.end<cv::Vec2f>(); ++it)
      *it += cv::Vec2f(noise(rng), noise(rng));
    flows.push_back(f);
  }
  flows[0].setTo(cv::Scalar(6, 0), maps_->ids[0] == 1);
  const double before = Epe(flows[0], 0, 1);
  ASSERT_GT(before, 5.0);
  const std::vector<cv::Mat> out = FlowConsensus(Views(flows), {});
  // Where at least two other views see the point they outvote it: most of
  // the person is corrected (points seen by one other view only cannot be).
  EXPECT_LT(MedianError(out[0], 0, 1), 1.0);
  EXPECT_LT(Epe(out[0], 0, 1), 0.5 * before);
  // The noise the views do not share averages out.
  for (size_t v = 1; v < out.size(); ++v)
    EXPECT_LT(Epe(out[v], static_cast<int>(v)), Epe(flows[v], static_cast<int>(v))) << v;
  // Background pixels keep their flow.
  const cv::Mat background = maps_->ids[0] == 0;
  EXPECT_EQ(cv::norm(out[0], flows[0], cv::NORM_INF, background), 0);
}

TEST_F(FlowConsensusTest, AViewAloneKeepsItsFlow) {
  std::vector<cv::Mat> flows = maps_->flows;
  for (size_t v = 1; v < flows.size(); ++v) flows[v] = cv::Mat();
  cv::Mat wrong = maps_->flows[0] + cv::Scalar(3, 3);
  flows[0] = wrong;
  const std::vector<cv::Mat> out = FlowConsensus(Views(flows), {});
  EXPECT_EQ(cv::norm(out[0], wrong, cv::NORM_INF), 0);
  for (size_t v = 1; v < out.size(); ++v) EXPECT_TRUE(out[v].empty());
}

TEST_F(FlowConsensusTest, BadInputThrows) {
  std::vector<FlowConsensusView> views = Views(maps_->flows);
  views[2].depth = cv::Mat::zeros(10, 10, CV_32F);
  EXPECT_THROW(FlowConsensus(views, {}), Error);
  FlowConsensusOptions o;
  o.min_views = 1;
  EXPECT_THROW(FlowConsensus(Views(maps_->flows), o), Error);
}

}  // namespace
}  // namespace u4d
