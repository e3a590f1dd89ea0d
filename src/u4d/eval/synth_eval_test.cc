// The foundation's acceptance check on a generated capture: its ground truth
// evaluated against itself is perfect, and its degraded initial masks score
// clearly below perfect (the margin U4D's core has to recover).
#include <gtest/gtest.h>

#include "u4d/eval/evaluate.h"
#include "u4d/synth/generate.h"

namespace u4d {
namespace {

class SynthEvalTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("u4d_synth_eval_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    synth::SynthOptions o = synth::SynthPreset("handshake");
    o.num_frames = 4;
    o.rig.num_views = 4;
    o.rig.image_width = 320;
    o.rig.image_height = 180;
    synth::WriteSyntheticCapture(o, dir_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static inline fs::path dir_;
};

TEST_F(SynthEvalTest, GroundTruthAgainstItselfIsPerfect) {
  const eval::EvalReport r = eval::EvaluateCapture({dir_, dir_ / "gt", false});
  ASSERT_TRUE(r.instances && r.depth && r.flow && r.poses && r.meshes && r.projection_error);
  EXPECT_DOUBLE_EQ(r.instances->MeanInstanceIoU(), 1.0);
  EXPECT_DOUBLE_EQ(r.depth->Delta1Pct(), 1.0);
  EXPECT_DOUBLE_EQ(r.flow->Epe(), 0.0);
  EXPECT_DOUBLE_EQ(r.poses->Mpjpe(), 0.0);
  EXPECT_DOUBLE_EQ(r.projection_error->Mean(), 0.0);
}

TEST_F(SynthEvalTest, InitialMasksScoreClearlyBelowPerfect) {
  const eval::EvalReport r = eval::EvaluateCapture({dir_, {}, true});
  ASSERT_TRUE(r.instances.has_value());
  const double iou = r.instances->MeanInstanceIoU();
  // Default degradation: boundary noise, dropped forearms/shins, merges of the
  // two touching people, misses and dropped frames (docs/synthetic.md).
  EXPECT_LT(iou, 0.9);
  EXPECT_GT(iou, 0.4);  // still a detector's output, not noise
}

}  // namespace
}  // namespace u4d
