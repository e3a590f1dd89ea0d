#include "u4d/joint/joint_view.h"

#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "u4d/eval/dense_metrics.h"
#include "u4d/eval/segmentation_metrics.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/poses.h"
#include "u4d/joint/frame_setup.h"
#include "u4d/synth/generate.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

InstanceMask AsPersons(const cv::Mat& ids) {
  InstanceMask mask;
  mask.ids = ids;
  double max_id = 0;
  cv::minMaxLoc(ids, nullptr, &max_id);
  for (int id = 1; id <= static_cast<int>(max_id); ++id)
    if (cv::countNonZero(ids == id) > 0) mask.instances.push_back({id, "person", 1.0});
  return mask;
}

// The ground truth of one view and frame.
struct Truth {
  InstanceMask instances;
  cv::Mat depth, flow, flow_valid;
};

Truth ReadTruth(const Capture& capture, int view, int frame) {
  const std::string& name = capture.views[view].name;
  Truth t;
  t.instances = ReadInstanceMask(capture.root / layout::GtInstances(name, frame),
                                 capture.root / layout::GtInstancesInfo(name, frame));
  t.depth = ReadPfm(capture.root / layout::GtDepth(name, frame));
  t.flow = ReadFlo(capture.root / layout::GtFlow(name, frame));
  t.flow_valid = ReadMaskImage(capture.root / layout::GtFlowValid(name, frame));
  return t;
}

// Sparse correspondences standing in for the temporal tracks: GT flow at
// random GT-valid person pixels (the tracks themselves are measured in
// features/temporal_tracks_test.cc, precision 0.98).
std::vector<SparseMotion> SparseFromTruth(const Truth& t, int count, uint64_t seed) {
  std::vector<cv::Point> candidates;
  for (int y = 0; y < t.flow.rows; ++y)
    for (int x = 0; x < t.flow.cols; ++x)
      if (t.instances.ids.at<uint16_t>(y, x) > 0 && t.flow_valid.at<uint8_t>(y, x))
        candidates.push_back({x, y});
  std::mt19937_64 rng(seed);
  std::shuffle(candidates.begin(), candidates.end(), rng);
  std::vector<SparseMotion> sparse;
  for (int i = 0; i < std::min<int>(count, candidates.size()); ++i) {
    const cv::Vec2f f = t.flow.at<cv::Vec2f>(candidates[i]);
    sparse.push_back({Eigen::Vector2d(candidates[i].x, candidates[i].y),
                      Eigen::Vector2d(f[0], f[1]), t.instances.ids.at<uint16_t>(candidates[i])});
  }
  return sparse;
}

class JointViewSynthTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    synth::SynthOptions options = synth::SmallHandshakeOptions(6, 320, 180, 3);
    options.start_frame = 128;  // the people walk apart: there is motion to estimate
    dir_ = new fs::path(synth::WriteCaptureToTempDir("joint_view", options));
  }
  static void TearDownTestSuite() { delete dir_; }
  static fs::path* dir_;
};
fs::path* JointViewSynthTest::dir_ = nullptr;

TEST_F(JointViewSynthTest, EnergyDecreasesAndImprovesLabelsDepthAndFlow) {
  const Capture capture = ReadCapture(*dir_);
  FrameReader reader(capture);
  const int frame = 1;
  // GT 3D poses stand in for the estimated ones (pose/ measures its own
  // accuracy: 27 mm MPJPE on this preset).
  std::vector<std::vector<Pose3d>> poses(capture.num_frames);
  for (int f = 0; f < capture.num_frames; ++f)
    poses[f] = ReadPoses3d(capture.root / layout::GtJoints3d(f));
  JointFrameData data = ReadJointFrameData(capture, &reader, frame, poses);
  std::vector<Truth> truth;
  for (int v = 0; v < capture.NumViews(); ++v) {
    truth.push_back(ReadTruth(capture, v, frame));
    data.sparse[v] = SparseFromTruth(truth.back(), 150, 11 + v);
  }
  double scale = 0;
  const std::vector<JointViewInput> inputs = MakeJointViewInputs(data, {}, &scale);
  ASSERT_EQ(scale, 1.0);  // 320 wide: solved at full resolution

  JointViewOptions options;
  options.weights = PaperWeights(capture.scene, capture.NumViews());
  eval::InstanceSegOptions seg_options;
  double iou_initial = 0, iou_refined = 0;
  int views = 0;
  eval::DepthMetrics depth_refined, depth_wta;
  eval::FlowMetrics flow_refined, flow_zero;
  for (int v = 0; v < 4; ++v) {  // four of the six views keep the test short
    const JointViewInput& in = inputs[v];
    if (in.objects.empty()) continue;
    const JointViewResult r = SolveJointView(in, options);
    // The energy never increases from block to block.
    for (size_t i = 1; i < r.energy_trace.size(); ++i)
      EXPECT_LE(r.energy_trace[i].energy, r.energy_trace[i - 1].energy + 1e-6)
          << "view " << v << " block " << r.energy_trace[i].block;
    const Truth& t = truth[v];
    const auto initial =
        eval::EvaluateInstances(AsPersons(in.initial_labels), t.instances, seg_options, "initial");
    const auto refined =
        eval::EvaluateInstances(AsPersons(r.labels), t.instances, seg_options, "refined");
    iou_initial += initial.mean_instance_iou;
    iou_refined += refined.mean_instance_iou;
    ++views;
    const cv::Mat people = t.instances.ids > 0;
    depth_refined.Add(eval::EvaluateDepth(r.depth, t.depth, people, "refined depth"));
    double near = 1e9, far = 0;
    for (const JointObject& o : in.objects)
      near = std::min(near, o.depth_near), far = std::max(far, o.depth_far);
    const DepthCostVolume volume =
        ComputeDepthCostVolume(in.cameras_t, in.images_t, v, r.roi, near, far, options.depth);
    depth_wta.Add(eval::EvaluateDepth(WinnerTakeAllDepth(volume, r.roi), t.depth, people, "wta"));
    flow_refined.Add(eval::EvaluateFlow(r.flow, t.flow, t.flow_valid, people, "refined flow"));
    flow_zero.Add(eval::EvaluateFlow(cv::Mat::zeros(t.flow.size(), CV_32FC2), t.flow, t.flow_valid,
                                     people, "zero flow"));
    std::printf("view %d: IoU %.3f -> %.3f, %d depth / %d motion labels, %.2f s\n", v,
                initial.mean_instance_iou, refined.mean_instance_iou, r.num_depth_labels,
                r.num_motion_labels, r.seconds);
    for (const EnergyStep& step : r.energy_trace)
      std::printf("  %-7s E = %.1f (%.2f s)\n", step.block.c_str(), step.energy, step.seconds);
  }
  ASSERT_GT(views, 3);
  iou_initial /= views;
  iou_refined /= views;
  std::printf("mean instance IoU: initial %.3f, refined %.3f\n", iou_initial, iou_refined);
  std::printf("depth within 1%%: WTA %.3f, joint %.3f; within 5%%: WTA %.3f, joint %.3f\n",
              depth_wta.Delta1Pct(), depth_refined.Delta1Pct(), depth_wta.Delta5Pct(),
              depth_refined.Delta5Pct());
  std::printf("flow EPE on people: zero %.3f, joint %.3f\n", flow_zero.Epe(), flow_refined.Epe());
  // The issue asks for a clear improvement over the initial masks.
  EXPECT_GT(iou_refined, iou_initial + 0.05);
  // Regularised depth is at least as accurate as winner-take-all on the same cost.
  EXPECT_GE(depth_refined.Delta5Pct(), depth_wta.Delta5Pct());
  // The estimated motion explains part of the true motion. (The goal,
  // beating DeepFlow and DIS, is not met yet: bench/joint_bench prints both.)
  EXPECT_LT(flow_refined.Epe(), flow_zero.Epe());
}

TEST(JointViewTest, RejectsInconsistentInput) {
  JointViewInput in;
  JointViewOptions options;
  EXPECT_THROW(SolveJointView(in, options), Error);  // no views
  options.rounds = 0;
  EXPECT_THROW(options.Check(), Error);
}

TEST(JointParametersTest, AblationsSwitchTheirTerms) {
  EXPECT_FALSE(AblationTerms("P_M").flow);
  EXPECT_FALSE(AblationTerms("P_M").motion_reg);
  EXPECT_FALSE(AblationTerms("P_P").pose);
  EXPECT_FALSE(AblationTerms("P_PM").pose);
  EXPECT_FALSE(AblationTerms("P_PM").flow);
  EXPECT_FALSE(AblationTerms("P_S").semantic);
  EXPECT_FALSE(AblationTerms("P_PS").semantic);
  EXPECT_FALSE(AblationTerms("P_PS").pose);
  EXPECT_EQ(AblationTerms("full"), JointTerms());
  EXPECT_THROW(AblationTerms("P_X"), Error);
  // The paper's table: indoor with 8 views.
  const JointWeights w = PaperWeights(SceneType::kIndoor, 8);
  EXPECT_DOUBLE_EQ(w.semantic, 0.2);
  EXPECT_DOUBLE_EQ(w.pose_2d, 5.0);
  EXPECT_DOUBLE_EQ(PaperWeights(SceneType::kOutdoor, 8).depth, 1.2);
  JointWeights updated = w;
  UpdateFromJson(nlohmann::json{{"flow", 0.9}}, "test", &updated);
  EXPECT_DOUBLE_EQ(updated.flow, 0.9);
  EXPECT_THROW(UpdateFromJson(nlohmann::json{{"nope", 1}}, "test", &updated), Error);
  EXPECT_THROW(UpdateFromJson(nlohmann::json{{"flow", -1}}, "test", &updated), Error);
}

}  // namespace
}  // namespace u4d
