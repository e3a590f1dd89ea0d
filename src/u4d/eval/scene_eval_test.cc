// The figures of a written 4D scene (vertex drift, consistency without GT),
// measured on the oracle scene built from a synthetic capture's ground truth,
// where each figure's value is known, and on copies of it with one thing
// broken, where the figure must see the damage.
#include <fstream>

#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>

#include "u4d/eval/baseline_grabcut.h"
#include "u4d/eval/baseline_overlap.h"
#include "u4d/eval/fused_reconstruction.h"
#include "u4d/eval/mesh_metrics.h"
#include "u4d/eval/scene_consistency.h"
#include "u4d/eval/segment_drift.h"
#include "u4d/fusion/gltf.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/scene_index.h"
#include "u4d/synth/generate.h"
#include "u4d/util/testing.h"

namespace u4d::eval {
namespace {

constexpr int kFrames = 4;

class SceneEvalTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // 4 views, 4 frames of the walk towards each other (centimetres per frame).
    synth::SynthOptions o = synth::SmallHandshakeOptions(4, 320, 180, kFrames);
    o.write_meshes = true;
    o.start_frame = 10;
    capture_dir_ = test_util::RemovedAtExit(synth::WriteCaptureToTempDir("eval_scene_test", o));
    capture_ = ReadCapture(capture_dir_);
  }
  static void TearDownTestSuite() { fs::remove_all(capture_dir_); }

  // The oracle scene: GT masks, depth, flow and meshes in the layout of
  // `u4d run`, one segment over all frames whose .glb holds the GT meshes.
  static fs::path WriteOracleScene(const std::string& name) {
    const fs::path dir = test_util::FreshTestDir("eval_scene", name);
    SceneIndex index;
    index.name = capture_.name;
    for (int f = 0; f < kFrames; ++f) index.frames.push_back(f);
    for (const CaptureView& v : capture_.views)
      index.views.push_back({v.name, v.cameras[0].width, v.cameras[0].height});
    SceneSegmentInfo seg{0, 0, 0, kFrames - 1, layout::SceneSegmentDir(0).string(), {}};
    for (int id = 1; id <= 2; ++id) {
      index.objects.push_back({id, "person", {200, 50, 50}});
      AnimatedMesh anim;
      anim.object_id = id;
      for (int f = 0; f < kFrames; ++f) {
        const fs::path gt = capture_dir_ / layout::GtMesh(id, f);
        fs::create_directories((dir / layout::SceneMesh(id, f)).parent_path());
        fs::copy_file(gt, dir / layout::SceneMesh(id, f));
        const open3d::geometry::TriangleMesh m = ReadMesh(gt);
        if (f == 0) anim.triangles = m.triangles_;
        anim.positions.push_back(m.vertices_);
      }
      const fs::path glb = layout::SceneSegmentDir(0) / fmt::format("{}.glb", id);
      WriteSegmentGlb(dir / glb, anim, {});
      seg.glb[id] = glb.string();
    }
    index.segments.push_back(seg);
    index.keyframes.push_back({0, {0, 1, 2, 3}});
    index.has_meshes = true;
    for (const CaptureView& v : capture_.views)
      for (int f = 0; f < kFrames; ++f) {
        const InstanceMask m = ReadInstanceMask(capture_dir_ / layout::GtInstances(v.name, f),
                                                capture_dir_ / layout::GtInstancesInfo(v.name, f));
        WriteInstanceMask(dir / layout::SceneInstances(v.name, f),
                          dir / layout::SceneInstancesInfo(v.name, f), m);
        WritePfm(dir / layout::SceneDepth(v.name, f),
                 ReadPfm(capture_dir_ / layout::GtDepth(v.name, f)));
        if (f + 1 < kFrames)
          WriteFlo(dir / layout::SceneFlow(v.name, f),
                   ReadFlo(capture_dir_ / layout::GtFlow(v.name, f)));
      }
    WriteSceneIndex(dir, index);
    return dir;
  }

  static inline fs::path capture_dir_;
  static inline Capture capture_;
};

// Ground-truth segments do not drift (float rounding only); a segment frozen
// at its first frame drifts by exactly the true motion, which on this walk is
// centimetres after three frames.
TEST_F(SceneEvalTest, DriftIsZeroForGtAndEqualsTheMotionForAFrozenMesh) {
  const fs::path scene = WriteOracleScene("drift");
  const DriftReport gt = EvaluateSegmentDrift(capture_dir_, scene);
  ASSERT_EQ(gt.segments.size(), 2u);
  for (const SegmentDrift& s : gt.segments) {
    EXPECT_EQ(s.gt_id, s.object_id);
    EXPECT_EQ(s.followed, s.vertices);
    ASSERT_EQ(s.median_drift.size(), static_cast<size_t>(kFrames));
  }
  EXPECT_LT(gt.last_frame_drift.Mean(), 1e-5);
  EXPECT_GT(gt.last_frame_motion.Mean(), 0.02);

  // Freeze person 2's mesh at frame 0.
  const fs::path glb = scene / layout::SceneSegmentDir(0) / "2.glb";
  AnimatedMesh frozen = ReadSegmentGlb(glb);
  for (auto& p : frozen.positions) p = frozen.positions[0];
  WriteSegmentGlb(glb, frozen, {});
  const DriftReport r = EvaluateSegmentDrift(capture_dir_, scene);
  const SegmentDrift& s2 = r.segments[1];
  ASSERT_EQ(s2.object_id, 2);
  EXPECT_NEAR(s2.median_drift.back(), s2.median_motion.back(), 1e-5);
  EXPECT_GT(s2.median_drift.back(), 0.02);
  EXPECT_LT(r.segments[0].median_drift.back(), 1e-5);
  const nlohmann::json j = r.ToJson();
  EXPECT_EQ(j["segments"].size(), 2u);
  EXPECT_EQ(j["by_frame_offset"].size(), static_cast<size_t>(kFrames - 1));
}

// On the oracle scene: the meshes project exactly onto the masks (the
// generator rasterises the same meshes); the masks carried by the true flow
// land on the next masks except where forward splatting rounds or a part
// becomes occluded or disoccluded (under 10 % after up to three frames); and,
// with exact depth, a cross-view point can only disagree by landing on the
// wrong side of a silhouette edge, which the 2x2 neighbourhood of the check
// rules out, so at least 99 % agree in depth and label.
TEST_F(SceneEvalTest, OracleSceneIsConsistent) {
  const fs::path scene = WriteOracleScene("oracle");
  ConsistencyOptions o;
  o.baseline_flows = {baselines::FlowBaseline::kDis};
  const ConsistencyReport r = EvaluateSceneConsistency(capture_, scene, o);
  std::printf("%s", r.FormatTable().c_str());
  EXPECT_EQ(r.projection_error.Mean(), 0.0);
  EXPECT_EQ(r.projection_error.count, 2 * 4 * kFrames);
  EXPECT_LT(r.se_own_flow.Mean(), 0.1);
  EXPECT_EQ(r.se_own_flow.count, 2 * 4 * (kFrames - 1));
  ASSERT_TRUE(r.se_baseline.count("dis"));
  EXPECT_GT(r.se_baseline.at("dis").Mean(), r.se_own_flow.Mean());  // GT flow is the best flow
  EXPECT_GT(r.cross_view.points, 10000);
  EXPECT_GT(r.cross_view.DepthAgreement(), 0.99);
  EXPECT_GT(r.cross_view.LabelAgreement(), 0.99);
}

// A scene whose segments are single frames (every frame after a cut in
// time) has no S_e: the table says so instead of printing NaN.
TEST(ConsistencyReport, NoPropagationIsNotANumber) {
  const std::string table = ConsistencyReport().FormatTable();
  const size_t row = table.find("| S_e, masks propagated with our flow");
  ASSERT_NE(row, std::string::npos);
  const std::string line = table.substr(row, table.find('\n', row) - row);
  EXPECT_NE(line.find("n/a (no segment spans two frames)"), std::string::npos) << line;
  EXPECT_EQ(line.find("nan"), std::string::npos) << line;
}

// Breaking one view must show in the figure that measures it: depth of cam00
// pulled 30 % towards its camera puts its points in front of what the other
// views see (conflicts), instance ids swapped in cam01 disagree wherever
// depths agree, and zero flow propagates masks worse than the true flow.
TEST_F(SceneEvalTest, BrokenViewsAreSeen) {
  const fs::path scene = WriteOracleScene("broken");
  const ConsistencyReport before = EvaluateSceneConsistency(capture_, scene);
  const std::string v0 = capture_.views[0].name, v1 = capture_.views[1].name;
  for (int f = 0; f < kFrames; ++f) {
    const fs::path d = scene / layout::SceneDepth(v0, f);
    WritePfm(d, ReadPfm(d) * 0.7);
    const fs::path png = scene / layout::SceneInstances(v1, f);
    const fs::path json = scene / layout::SceneInstancesInfo(v1, f);
    InstanceMask m = ReadInstanceMask(png, json);
    cv::Mat swapped = m.ids.clone();
    swapped.setTo(2, m.ids == 1);
    swapped.setTo(1, m.ids == 2);
    m.ids = swapped;
    WriteInstanceMask(png, json, m);
    if (f + 1 < kFrames) {
      const fs::path flo = scene / layout::SceneFlow(v0, f);
      WriteFlo(flo, cv::Mat::zeros(ReadFlo(flo).size(), CV_32FC2));
    }
  }
  const ConsistencyReport after = EvaluateSceneConsistency(capture_, scene);
  EXPECT_LT(after.cross_view_by_view.at(v0).DepthAgreement(), 0.1);
  EXPECT_GT(after.cross_view_by_view.at(v0).conflict, 1000);
  EXPECT_NEAR(after.cross_view_by_view.at(capture_.views[2].name).DepthAgreement(),
              before.cross_view_by_view.at(capture_.views[2].name).DepthAgreement(), 0.01);
  // cam01's points agree with no other view's ids, the other views' points
  // disagree only with cam01: label agreement drops well below the oracle's.
  EXPECT_LT(after.cross_view_by_view.at(v1).LabelAgreement(), 0.1);
  EXPECT_LT(after.cross_view.LabelAgreement(), before.cross_view.LabelAgreement() - 0.3);
  EXPECT_GT(after.se_own_flow.Mean(), before.se_own_flow.Mean());
}

// S_e against the GT masks (the protocol of `u4d eval`) for the GT flow, no
// flow at all, and the OpenCV baselines on the capture's images. The people
// walk centimetres per frame, so a mask left in place loses overlap; the GT
// flow carries it (rounding and the crack closing aside); a dense flow that
// follows the walk must do better than no flow.
TEST_F(SceneEvalTest, BaselineFlowsCarryGtMasksBetterThanNoFlow) {
  EvalOptions o;
  const RatioMean gt = GtSilhouetteOverlap(
      capture_,
      [&](int v, int f) {
        return ReadFlo(capture_dir_ / layout::GtFlow(capture_.views[v].name, f));
      },
      o);
  const RatioMean zero = GtSilhouetteOverlap(
      capture_,
      [&](int v, int f) {
        const cv::Mat like = ReadFlo(capture_dir_ / layout::GtFlow(capture_.views[v].name, f));
        return cv::Mat(like.size(), CV_32FC2, cv::Scalar(0, 0));
      },
      o);
  // Key-frame 0 and the 3 frames after it, in each of the 4 views.
  EXPECT_EQ(gt.count, 4 * (kFrames - 1));
  EXPECT_LT(gt.Mean(), zero.Mean());
  const auto se = BaselineSilhouetteOverlap(
      capture_, {baselines::FlowBaseline::kDis, baselines::FlowBaseline::kFarneback}, o);
  ASSERT_EQ(se.size(), 2u);
  for (const auto& [name, r] : se) {
    SCOPED_TRACE(name);
    EXPECT_EQ(r.count, gt.count);
    EXPECT_LT(r.Mean(), zero.Mean());
  }
  std::printf("S_e vs GT masks: GT flow %.4f, zero flow %.4f, DIS %.4f, Farneback %.4f\n",
              gt.Mean(), zero.Mean(), se.at("dis").Mean(), se.at("farneback").Mean());
}

// The GrabCut baseline as a prediction: one file per view-frame with an
// initial mask, the initial instances' classes kept, and measured against
// the GT as `u4d eval --grabcut` does (GrabCut moves the initial masks'
// boundaries, so the figure differs from theirs).
TEST_F(SceneEvalTest, GrabCutPredictionIsEvaluatedAgainstTheTruth) {
  const fs::path out = test_util::FreshTestDir("eval_scene", "grabcut");
  int masks = 0;
  for (const CaptureView& v : capture_.views)
    for (int f = 0; f < kFrames; ++f) masks += fs::exists(capture_dir_ / layout::Mask(v.name, f));
  EXPECT_EQ(WriteGrabCutPrediction(capture_, out), masks);
  const InstanceMask initial = ReadInstanceMask(capture_dir_ / layout::Mask("cam00", 0),
                                                capture_dir_ / layout::MaskInfo("cam00", 0));
  const InstanceMask grabcut =
      ReadInstanceMask(out / "instances/cam00/000000.png", out / "instances/cam00/000000.json");
  ASSERT_EQ(grabcut.instances.size(), initial.instances.size());
  for (size_t i = 0; i < initial.instances.size(); ++i)
    EXPECT_EQ(grabcut.instances[i].label, initial.instances[i].label);
  EvalInput by_grabcut{capture_dir_, out, false}, by_initial{capture_dir_, {}, true};
  const double g = EvaluateCapture(by_grabcut).instances->MeanInstanceIoU();
  const double i = EvaluateCapture(by_initial).instances->MeanInstanceIoU();
  std::printf("mean instance IoU: initial masks %.4f, GrabCut %.4f\n", i, g);
  EXPECT_GT(g, 0.5);
  EXPECT_NE(g, i);
  fs::remove_all(out);
}

// Depth maps through the fusion, against the GT masks and meshes: the GT
// depth must rebuild the people closely, a depth 5 % too far (the people
// pushed back and shrunk in every view) must score clearly worse, and no
// depth at all gives no mesh (error 1).
TEST_F(SceneEvalTest, FusedDepthIsMeasuredAgainstGtMasksAndMeshes) {
  const int f = 1;
  FrameReader reader(capture_);
  std::vector<Camera> cameras;
  std::vector<cv::Mat> depth, far, none, ids, images;
  for (int v = 0; v < capture_.NumViews(); ++v) {
    const std::string& name = capture_.views[v].name;
    cameras.push_back(capture_.views[v].CameraAt(f));
    depth.push_back(ReadPfm(capture_dir_ / layout::GtDepth(name, f)));
    far.push_back(depth.back() * 1.05);
    none.push_back(cv::Mat::zeros(depth.back().size(), CV_32FC1));
    ids.push_back(ReadInstanceMask(capture_dir_ / layout::GtInstances(name, f),
                                   capture_dir_ / layout::GtInstancesInfo(name, f))
                      .ids);
    images.push_back(reader.Read(v, f));
  }
  std::vector<open3d::geometry::TriangleMesh> gt_meshes;
  for (int id = 1; id <= 2; ++id)
    gt_meshes.push_back(ReadMesh(capture_dir_ / layout::GtMesh(id, f)));
  const std::map<int, const open3d::geometry::TriangleMesh*> gt = {{1, &gt_meshes[0]},
                                                                   {2, &gt_meshes[1]}};
  const FusedReconstruction exact = EvaluateFusedDepth(cameras, depth, ids, images, gt);
  const FusedReconstruction pushed = EvaluateFusedDepth(cameras, far, ids, images, gt);
  const FusedReconstruction empty = EvaluateFusedDepth(cameras, none, ids, images, gt);
  EXPECT_EQ(exact.objects, 2);
  EXPECT_EQ(exact.empty, 0);
  EXPECT_EQ(exact.projection_error.count, 8);  // 2 people in each of 4 views
  // The fused surface of exact depth loses only a 1-2 px band at the
  // silhouettes and thin parts (fingers) of people 50-100 px tall: ~10 %.
  EXPECT_LT(exact.projection_error.Mean(), 0.2);
  EXPECT_LT(exact.chamfer_m.Mean(), 0.03);
  EXPECT_GT(pushed.chamfer_m.Mean(), exact.chamfer_m.Mean() + 0.05);  // ~5 % of 4.5 m
  EXPECT_EQ(empty.empty, 2);
  EXPECT_DOUBLE_EQ(empty.projection_error.Mean(), 1.0);
  std::printf(
      "fused GT depth: projection error %.3f, Chamfer %.1f mm; 5 %% farther: %.3f, %.1f mm\n",
      exact.projection_error.Mean(), exact.chamfer_m.Mean() * 1e3, pushed.projection_error.Mean(),
      pushed.chamfer_m.Mean() * 1e3);
  EXPECT_THROW(EvaluateFusedDepth(cameras, depth, ids, {}), Error);
}

TEST_F(SceneEvalTest, MissingAndCorruptFilesAreNamed) {
  const fs::path scene = WriteOracleScene("bad");
  const std::string v0 = capture_.views[0].name;
  std::ofstream(scene / layout::SceneDepth(v0, 1)) << "not a pfm";
  test_util::ExpectErrorMentions([&] { EvaluateSceneConsistency(capture_, scene); },
                                 {layout::SceneDepth(v0, 1).string()});
  std::ofstream(scene / layout::SceneSegmentDir(0) / "1.glb") << "x";
  test_util::ExpectErrorMentions([&] { EvaluateSegmentDrift(capture_dir_, scene); }, {"1.glb"});
  fs::remove(scene / layout::SceneFlow(v0, 0));
  test_util::ExpectErrorMentions([&] { EvaluateSceneConsistency(capture_, scene); },
                                 {layout::SceneFlow(v0, 0).string()});
}

}  // namespace
}  // namespace u4d::eval
