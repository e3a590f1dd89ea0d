// The foundation's acceptance check on a generated capture: its ground truth
// evaluated against itself is perfect, and its degraded initial masks score
// clearly below perfect (the margin U4D's core has to recover).
#include <gtest/gtest.h>

#include "u4d/eval/evaluate.h"
#include "u4d/synth/generate.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

class SynthEvalTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    synth::SynthOptions o = synth::SmallHandshakeOptions(4, 320, 180, 4);
    o.write_meshes = true;  // the projection error and Chamfer need them
    dir_ = test_util::RemovedAtExit(synth::WriteCaptureToTempDir("synth_eval_test", o));
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
  ASSERT_TRUE(r.identity.has_value());
  const eval::IdentitySummary id = r.identity->Summarize();
  EXPECT_DOUBLE_EQ(id.mean_ids_per_person, 1.0);
  EXPECT_EQ(id.switches + id.cross_view_disagreements + id.shared_pred_ids, 0);
  EXPECT_EQ(id.no_mesh_frames, 0);
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
