// End-to-end checks of a written synthetic capture: it reads back as a
// capture, and its ground truth agrees with itself geometrically across views
// and through time (the GT is exact, so these checks are tight).
#include "u4d/synth/generate.h"

#include <gtest/gtest.h>

#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/poses.h"
#include "u4d/util/testing.h"

namespace u4d::synth {
namespace {

class GenerateTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SynthOptions o = SmallHandshakeOptions(4, 240, 136, 3);
    o.write_meshes = true;
    dir_ = test_util::RemovedAtExit(WriteCaptureToTempDir("generate_test", o, &summary_));
  }
  static inline fs::path dir_;
  static inline SynthSummary summary_;
};

TEST_F(GenerateTest, ReadsBackAsACapture) {
  const Capture c = ReadCapture(dir_);
  EXPECT_EQ(c.NumViews(), 4);
  EXPECT_EQ(c.num_frames, 3);
  FrameReader reader(c);
  for (int v = 0; v < c.NumViews(); ++v) EXPECT_EQ(reader.Read(v, 2).cols, 240);
  EXPECT_EQ(ReadPoses3d(dir_ / layout::GtJoints3d(1)).size(), 2u);
  EXPECT_TRUE(fs::exists(dir_ / layout::GtMesh(2, 2)));
  EXPECT_FALSE(fs::exists(dir_ / layout::GtFlow("cam00", 2)));  // no flow out of the last frame
}

// A person pixel of view a, lifted with GT depth and seen by view b where b's
// GT depth agrees (so it is visible there), must carry the same instance id.
TEST_F(GenerateTest, InstancesAndDepthAgreeAcrossViews) {
  const Capture c = ReadCapture(dir_);
  int checked = 0, agree = 0;
  for (int a = 0; a < c.NumViews(); ++a) {
    const int b = (a + 1) % c.NumViews();
    const Camera& ca = c.views[a].cameras[0];
    const Camera& cb = c.views[b].cameras[0];
    const cv::Mat ids_a = ReadLabelImage(dir_ / layout::GtInstances(c.views[a].name, 1));
    const cv::Mat ids_b = ReadLabelImage(dir_ / layout::GtInstances(c.views[b].name, 1));
    const cv::Mat depth_a = ReadPfm(dir_ / layout::GtDepth(c.views[a].name, 1));
    const cv::Mat depth_b = ReadPfm(dir_ / layout::GtDepth(c.views[b].name, 1));
    for (int y = 0; y < ids_a.rows; y += 2) {
      for (int x = 0; x < ids_a.cols; x += 2) {
        const int id = ids_a.at<uint16_t>(y, x);
        if (id == 0) continue;
        const Eigen::Vector3d point = ca.Unproject({x, y}, depth_a.at<float>(y, x));
        const Eigen::Vector2d pb = cb.Project(point);
        const int xb = static_cast<int>(std::lround(pb.x())),
                  yb = static_cast<int>(std::lround(pb.y()));
        if (xb < 0 || yb < 0 || xb >= ids_b.cols || yb >= ids_b.rows) continue;
        if (std::abs(depth_b.at<float>(yb, xb) - cb.Depth(point)) > 0.01) continue;  // occluded
        ++checked;
        agree += ids_b.at<uint16_t>(yb, xb) == id ? 1 : 0;
      }
    }
  }
  ASSERT_GT(checked, 500);
  // Disagreements only where rounding to the nearest pixel crosses a boundary.
  EXPECT_GT(static_cast<double>(agree) / checked, 0.97);
}

// Following valid GT flow from t lands on the same person at t+1.
TEST_F(GenerateTest, FlowCarriesInstancesForward) {
  const Capture c = ReadCapture(dir_);
  int checked = 0, agree = 0;
  for (const CaptureView& v : c.views) {
    const cv::Mat ids0 = ReadLabelImage(dir_ / layout::GtInstances(v.name, 0));
    const cv::Mat ids1 = ReadLabelImage(dir_ / layout::GtInstances(v.name, 1));
    const cv::Mat flow = ReadFlo(dir_ / layout::GtFlow(v.name, 0));
    const cv::Mat valid = ReadMaskImage(dir_ / layout::GtFlowValid(v.name, 0));
    for (int y = 0; y < ids0.rows; ++y) {
      for (int x = 0; x < ids0.cols; ++x) {
        const int id = ids0.at<uint16_t>(y, x);
        if (id == 0 || !valid.at<uint8_t>(y, x)) continue;
        const cv::Vec2f f = flow.at<cv::Vec2f>(y, x);
        const int x1 = static_cast<int>(std::lround(x + f[0]));
        const int y1 = static_cast<int>(std::lround(y + f[1]));
        ASSERT_TRUE(x1 >= 0 && y1 >= 0 && x1 < ids1.cols && y1 < ids1.rows);
        ++checked;
        agree += ids1.at<uint16_t>(y1, x1) == id ? 1 : 0;
      }
    }
  }
  ASSERT_GT(checked, 500);
  EXPECT_GT(static_cast<double>(agree) / checked, 0.97);
}

// The initial masks are degraded copies: present for most view-frames, not identical to GT.
TEST_F(GenerateTest, InitialMasksAreDegraded) {
  const Capture c = ReadCapture(dir_);
  int present = 0, differing = 0;
  for (const CaptureView& v : c.views) {
    for (int f = 0; f < c.num_frames; ++f) {
      if (!fs::exists(dir_ / layout::Mask(v.name, f))) continue;
      ++present;
      const InstanceMask m =
          ReadInstanceMask(dir_ / layout::Mask(v.name, f), dir_ / layout::MaskInfo(v.name, f));
      const cv::Mat gt = ReadLabelImage(dir_ / layout::GtInstances(v.name, f));
      differing += cv::countNonZero((m.ids > 0) != (gt > 0)) > 0 ? 1 : 0;
    }
  }
  EXPECT_GE(present, 8);
  EXPECT_GE(differing, present / 2);
  EXPECT_EQ(present + summary_.dropped_masks, 12);
}

TEST(Generate, BadOptionsAreRejected) {
  EXPECT_THROW(SynthPreset("nonsense"), Error);
  SynthOptions o = SynthPreset("meetup");
  o.mocap_bvh.clear();
  EXPECT_THROW(o.Check(), Error);
  o = SynthPreset("handshake");
  o.num_frames = 1;
  EXPECT_THROW(o.Check(), Error);
}

}  // namespace
}  // namespace u4d::synth
