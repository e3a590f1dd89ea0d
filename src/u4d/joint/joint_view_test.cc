#include "u4d/joint/joint_view.h"

#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "u4d/baselines/flow_baselines.h"
#include "u4d/baselines/grabcut_baseline.h"
#include "u4d/eval/dense_metrics.h"
#include "u4d/eval/segmentation_metrics.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/poses.h"
#include "u4d/joint/frame_setup.h"
#include "u4d/synth/generate.h"
#include "u4d/testing/capture_inputs.h"
#include "u4d/testing/truth_inputs.h"
#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

class JointViewSynthTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    synth::SynthOptions options = synth::SmallHandshakeOptions(6, 320, 180, 3);
    options.start_frame = 128;  // the people walk apart: there is motion to estimate
    dir_ =
        new fs::path(test_util::RemovedAtExit(synth::WriteCaptureToTempDir("joint_view", options)));
  }
  static void TearDownTestSuite() { delete dir_; }
  // The frame's joint inputs with the GT 3D poses standing in for the
  // estimated ones (pose/ measures its own accuracy: 27 mm MPJPE on this
  // preset); the sparse motions are left empty.
  static JointFrameData GtPoseFrameData(const Capture& capture, FrameReader* reader, int frame) {
    const std::vector<std::vector<Pose3d>> poses = ReadGtPoses3d(capture);
    return ReadJointFrameData(capture, reader, frame, poses);
  }
  // Frame 1's per-view inputs and truth. GT sparse correspondences stand in
  // for the temporal tracks (measured in features/temporal_tracks_test.cc,
  // precision 0.98).
  static std::vector<JointViewInput> FrameInputs(const Capture& capture,
                                                 std::vector<ViewTruth>* truth) {
    FrameReader reader(capture);
    const int frame = 1;
    JointFrameData data = GtPoseFrameData(capture, &reader, frame);
    for (int v = 0; v < capture.NumViews(); ++v) {
      truth->push_back(ReadViewTruth(capture, v, frame));
      data.sparse[v] = SparseMotionsFromTruth(truth->back(), 150, 11 + v);
    }
    double scale = 0;
    std::vector<JointViewInput> inputs = MakeJointViewInputs(data, {}, &scale);
    EXPECT_EQ(scale, 1.0);  // 320 wide: solved at full resolution
    return inputs;
  }
  static fs::path* dir_;
};
fs::path* JointViewSynthTest::dir_ = nullptr;

TEST_F(JointViewSynthTest, EnergyDecreasesAndImprovesLabelsDepthAndFlow) {
  const Capture capture = ReadCapture(*dir_);
  std::vector<ViewTruth> truth;
  const std::vector<JointViewInput> inputs = FrameInputs(capture, &truth);

  JointViewOptions options;
  options.weights = PaperWeights(capture.scene, capture.NumViews());
  eval::InstanceSegOptions seg_options;
  double iou_initial = 0, iou_refined = 0, iou_grabcut = 0;
  int views = 0;
  eval::DepthMetrics depth_refined, depth_wta;
  eval::FlowMetrics flow_refined, flow_zero, flow_deepflow, flow_dis;
  for (int v = 0; v < 4; ++v) {  // four of the six views keep the test short
    const JointViewInput& in = inputs[v];
    if (in.objects.empty()) continue;
    const JointViewResult r = SolveJointView(in, options);
    // The energy never increases from block to block.
    for (size_t i = 1; i < r.energy_trace.size(); ++i)
      EXPECT_LE(r.energy_trace[i].energy, r.energy_trace[i - 1].energy + 1e-6)
          << "view " << v << " block " << r.energy_trace[i].block;
    const ViewTruth& t = truth[v];
    const auto initial = eval::EvaluateInstances(PersonInstances(in.initial_labels), t.instances,
                                                 seg_options, "initial");
    const auto refined =
        eval::EvaluateInstances(PersonInstances(r.labels), t.instances, seg_options, "refined");
    iou_grabcut +=
        eval::EvaluateInstances(
            PersonInstances(baselines::GrabCutInstances(in.images_t[v], in.initial_labels)),
            t.instances, seg_options, "grabcut")
            .mean_instance_iou;
    iou_initial += initial.mean_instance_iou;
    iou_refined += refined.mean_instance_iou;
    ++views;
    const cv::Mat people = t.instances.ids > 0;
    depth_refined.Add(eval::EvaluateDepth(r.depth, t.depth, people, "refined depth"));
    depth_wta.Add(eval::EvaluateDepth(r.plane_sweep_depth, t.depth, people, "plane sweep"));
    flow_refined.Add(eval::EvaluateFlow(r.flow, t.flow, t.flow_valid, people, "refined flow"));
    flow_zero.Add(eval::EvaluateFlow(cv::Mat::zeros(t.flow.size(), CV_32FC2), t.flow, t.flow_valid,
                                     people, "zero flow"));
    flow_deepflow.Add(eval::EvaluateFlow(baselines::BaselineFlow(baselines::FlowBaseline::kDeepFlow,
                                                                 in.images_t[v], in.images_t1[v]),
                                         t.flow, t.flow_valid, people, "deepflow"));
    flow_dis.Add(eval::EvaluateFlow(
        baselines::BaselineFlow(baselines::FlowBaseline::kDis, in.images_t[v], in.images_t1[v]),
        t.flow, t.flow_valid, people, "dis"));
    std::printf("view %d: IoU %.3f -> %.3f, %d depth / %d motion labels, %.2f s\n", v,
                initial.mean_instance_iou, refined.mean_instance_iou, r.num_depth_labels,
                r.num_motion_labels, r.seconds);
    for (const EnergyStep& step : r.energy_trace)
      std::printf("  %-7s E = %.1f (%.2f s)\n", step.block.c_str(), step.energy, step.seconds);
  }
  ASSERT_GT(views, 3);
  iou_initial /= views;
  iou_refined /= views;
  iou_grabcut /= views;
  std::printf("mean instance IoU: initial %.3f, GrabCut %.3f, refined %.3f\n", iou_initial,
              iou_grabcut, iou_refined);
  std::printf("depth within 1%%: WTA %.3f, joint %.3f; within 5%%: WTA %.3f, joint %.3f\n",
              depth_wta.Delta1Pct(), depth_refined.Delta1Pct(), depth_wta.Delta5Pct(),
              depth_refined.Delta5Pct());
  std::printf("flow EPE on people: zero %.3f, DeepFlow %.3f, DIS %.3f, joint %.3f\n",
              flow_zero.Epe(), flow_deepflow.Epe(), flow_dis.Epe(), flow_refined.Epe());
  // The issue asks for a clear improvement over the initial masks.
  EXPECT_GT(iou_refined, iou_initial + 0.05);
  // ... and segmentation better than GrabCut seeded with the same masks (the
  // issue's baseline; the joint energy adds depth, pose and semantics).
  EXPECT_GT(iou_refined, iou_grabcut);
  // Regularised depth is at least as accurate as winner-take-all on the same cost.
  EXPECT_GE(depth_refined.Delta5Pct(), depth_wta.Delta5Pct());
  // The estimated motion explains part of the true motion, and (the issue's
  // goal) better than OpenCV's DeepFlow and DIS on the same frames: both are
  // proposals of the fusion stage, kept only where they lower the full energy.
  EXPECT_LT(flow_refined.Epe(), flow_zero.Epe());
  EXPECT_LT(flow_refined.Epe(), flow_deepflow.Epe());
  EXPECT_LT(flow_refined.Epe(), flow_dis.Epe());
}

// JointViewOptions::motion_candidates_per_pixel (the motion block's moves
// limited to each pixel's lowest unaries) against every motion: the flow on
// the people stays as accurate against the GT, and the final energy (after
// the unlimited flow fusion) within 1 %. A guard of the accuracy only: the
// flow fusion recovers so much that a limit of 1 passes too; the time saved
// is measured by joint_bench --motion-candidates.
TEST_F(JointViewSynthTest, MotionCandidatesPerPixelKeepTheFlowAccuracy) {
  const Capture capture = ReadCapture(*dir_);
  std::vector<ViewTruth> truth;
  const std::vector<JointViewInput> inputs = FrameInputs(capture, &truth);
  JointViewOptions limited;
  limited.weights = PaperWeights(capture.scene, capture.NumViews());
  ASSERT_GT(limited.motion_candidates_per_pixel, 0);
  JointViewOptions every = limited;
  every.motion_candidates_per_pixel = 0;
  eval::FlowMetrics flow_limited, flow_every;
  int views = 0;
  for (int v = 0; v < 2; ++v) {
    if (inputs[v].objects.empty()) continue;
    const JointViewResult a = SolveJointView(inputs[v], limited);
    const JointViewResult b = SolveJointView(inputs[v], every);
    ASSERT_GT(a.num_motion_labels, 2 * limited.motion_candidates_per_pixel);
    const cv::Mat people = truth[v].instances.ids > 0;
    flow_limited.Add(
        eval::EvaluateFlow(a.flow, truth[v].flow, truth[v].flow_valid, people, "limited"));
    flow_every.Add(eval::EvaluateFlow(b.flow, truth[v].flow, truth[v].flow_valid, people, "all"));
    EXPECT_LE(a.energy_trace.back().energy, 1.01 * b.energy_trace.back().energy) << "view " << v;
    ++views;
  }
  std::printf("EPE on people: %d candidates per pixel %.3f px, every motion %.3f px\n",
              limited.motion_candidates_per_pixel, flow_limited.Epe(), flow_every.Epe());
  ASSERT_EQ(views, 2);
  EXPECT_LE(flow_limited.Epe(), flow_every.Epe() + 0.02);
}

// Still is still (issue 23): frame t shown twice — the same images (with new
// sensor noise, σ = 2 grey levels), cameras and poses at t and t+1, and sparse
// correspondences that do not move — must
// give no motion on the people: mean |flow| at most 0.05 px over their GT
// pixels, in every view solved.
TEST_F(JointViewSynthTest, TheSameFrameTwiceHasNoMotion) {
  const Capture capture = ReadCapture(*dir_);
  FrameReader reader(capture);
  JointFrameData data = GtPoseFrameData(capture, &reader, 1);
  // A camera's sensor noise differs between two exposures of a still scene.
  cv::RNG rng(7);
  data.images_t1.clear();
  for (const cv::Mat& image : data.images_t) {
    cv::Mat noise(image.size(), CV_16SC3), noisy;
    rng.fill(noise, cv::RNG::NORMAL, 0, 2.0);
    image.convertTo(noisy, CV_16SC3);
    cv::Mat(noisy + noise).convertTo(noisy, CV_8UC3);
    data.images_t1.push_back(noisy);
  }
  data.cameras_t1 = data.cameras_t;
  data.masks_t1 = data.masks_t;
  data.poses_t1 = data.poses_t;
  for (int v = 0; v < capture.NumViews(); ++v) {
    data.sparse[v] = SparseMotionsFromTruth(ReadViewTruth(capture, v, 1), 150, 11 + v);
    for (SparseMotion& s : data.sparse[v]) s.displacement.setZero();
  }
  double scale = 0;
  const std::vector<JointViewInput> inputs = MakeJointViewInputs(data, {}, &scale);
  JointViewOptions options;
  options.weights = PaperWeights(capture.scene, capture.NumViews());
  int views = 0;
  for (int v = 0; v < 4; ++v) {
    if (inputs[v].objects.empty()) continue;
    const JointViewResult r = SolveJointView(inputs[v], options);
    const cv::Mat people = ReadViewTruth(capture, v, 1).instances.ids > 0;
    double sum = 0, largest = 0;
    int count = 0;
    for (int y = 0; y < r.flow.rows; ++y)
      for (int x = 0; x < r.flow.cols; ++x) {
        if (!people.at<uint8_t>(y, x)) continue;
        const double len = cv::norm(r.flow.at<cv::Vec2f>(y, x));
        sum += len;
        largest = std::max(largest, len);
        ++count;
      }
    ASSERT_GT(count, 0);
    std::printf("view %d: mean |flow| on people %.4f px, largest %.3f px\n", v, sum / count,
                largest);
    EXPECT_LE(sum / count, 0.05) << "view " << v;
    ++views;
  }
  EXPECT_GE(views, 3);
}

// Frame `frame` with the true instance masks of t-1, t and t+1 as the
// detector's (object ids = person ids), no poses, and per view the people's
// depth ranges from the true depths widened by 0.35 m.
JointFrameData TrueMaskFrameData(const Capture& capture, FrameReader* reader, int frame) {
  JointFrameData data = ReadJointFrameData(capture, reader, frame, {});
  data.masks_are_object_ids = true;
  data.object_depth_ranges.assign(capture.NumViews(), {});
  for (int v = 0; v < capture.NumViews(); ++v) {
    const std::string& view = capture.views[v].name;
    for (int f : {frame - 1, frame, frame + 1})
      (f == frame  ? data.masks_t
       : f < frame ? data.masks_prev
                   : data.masks_t1)[v] =
          ReadInstanceMask(capture.root / layout::GtInstances(view, f),
                           capture.root / layout::GtInstancesInfo(view, f))
              .ids.clone();
    const ViewTruth truth = ReadViewTruth(capture, v, frame);
    for (int id : {1, 2}) {
      double near = 0, far = 0;
      cv::minMaxLoc(truth.depth, &near, &far, nullptr, nullptr, truth.instances.ids == id);
      if (far > 0) data.object_depth_ranges[v][id] = {std::max(0.05, near - 0.35), far + 0.35};
    }
  }
  return data;
}

// Issue 22, "missing parts come back": the head of person 1 is cut from
// view 0's initial masks at t-1, t and t+1 (a detector's misses persist in
// time, so E_sem's temporal maps do not restore it), the other views keep
// it, and no pose is given (no capsules). The true masks stand in for the
// detector elsewhere. With the objects' regions grown by the other views'
// visual hull (FrameSetupOptions::hull, with colour_samples: the head's
// colours are in no initial mask of the neighbourhood) the solve gives the
// head back.
TEST_F(JointViewSynthTest, AHeadCutFromOneViewsMasksComesBackFromTheOtherViews) {
  const Capture capture = ReadCapture(*dir_);
  FrameReader reader(capture);
  const int frame = 1, ref = 0, person = 1;
  JointFrameData data = TrueMaskFrameData(capture, &reader, frame);
  cv::Mat cut_t;
  for (cv::Mat* ids : {&data.masks_prev[ref], &data.masks_t[ref], &data.masks_t1[ref]}) {
    // The top 15 % of the person's box.
    const cv::Rect box = cv::boundingRect(*ids == person);
    cv::Mat cut = cv::Mat::zeros(ids->size(), CV_8U);
    cut(cv::Rect(box.x, box.y, box.width, static_cast<int>(0.15 * box.height))).setTo(255);
    cut &= *ids == person;
    ids->setTo(0, cut);
    if (ids == &data.masks_t[ref]) cut_t = cut;
  }
  ASSERT_GT(cv::countNonZero(cut_t), 100);
  JointViewOptions options;
  options.weights = PaperWeights(capture.scene, capture.NumViews());
  auto recovered = [&](bool hull) {
    FrameSetupOptions setup;
    setup.hull.enabled = hull;
    setup.hull.colour_samples = hull;
    const JointViewResult r =
        SolveJointView(MakeJointViewInputs(data, setup, nullptr)[ref], options);
    return static_cast<double>(cv::countNonZero((r.labels == person) & cut_t)) /
           cv::countNonZero(cut_t);
  };
  const double with_hull = recovered(true), without = recovered(false);
  std::printf("head cut from view %d (%d px): recovered %.3f with the hull, %.3f without\n", ref,
              cv::countNonZero(cut_t), with_hull, without);
  EXPECT_GE(with_hull, 0.7);
}

// Issue 22, "given perfect masks, the refined masks must stay perfect": the
// true masks of t-1, t and t+1 in every view, no poses. The solve's colour
// models cut off parts whose colours the background or the other person
// shares (shoes on the floor), fewer with bands in height
// (LabelCostOptions::colour_bands) or where the other views' hulls confirm a
// view's label (FrameSetupOptions::hull.confirm). The settings for masks the
// capture trusts (docs/formats.md) also sample every pixel of the masks for
// the colour models (LabelCostOptions::appearance_inset_px 0): with no
// boundary error to keep out, a thin part's rim is most of its colours.
// Mean instance IoU of every view's refined labels against the truth (the
// masks given: 1.0).
TEST_F(JointViewSynthTest, TheTrueMasksStayTrue) {
  const Capture capture = ReadCapture(*dir_);
  FrameReader reader(capture);
  const int frame = 1;
  const JointFrameData data = TrueMaskFrameData(capture, &reader, frame);
  JointViewOptions options;
  options.weights = PaperWeights(capture.scene, capture.NumViews());
  auto mean_iou = [&](bool confirm, int inset_px) {
    FrameSetupOptions setup;
    setup.hull.confirm = confirm;
    const std::vector<JointViewInput> inputs = MakeJointViewInputs(data, setup, nullptr);
    JointViewOptions o = options;
    o.labels.appearance_inset_px = inset_px;
    double sum = 0;
    int n = 0;
    for (int v = 0; v < capture.NumViews(); ++v) {
      const cv::Mat& truth = data.masks_t[v];
      const cv::Mat labels = SolveJointView(inputs[v], o).labels;
      for (int id : {1, 2}) {
        const int inter = cv::countNonZero((truth == id) & (labels == id));
        const int uni = cv::countNonZero((truth == id) | (labels == id));
        if (cv::countNonZero(truth == id) > 0) sum += static_cast<double>(inter) / uni, ++n;
      }
    }
    return sum / n;
  };
  const int inset_px = LabelCostOptions{}.appearance_inset_px;
  const double trusted = mean_iou(true, 0), confirmed = mean_iou(true, inset_px),
               colours_alone = mean_iou(false, inset_px);
  std::printf(
      "true masks refined: mean instance IoU %.4f (trusted-mask settings), %.4f (hull "
      "confirmation), %.4f (default)\n",
      trusted, confirmed, colours_alone);
  EXPECT_GE(trusted, 0.98);
  EXPECT_GE(confirmed, 0.98);
  EXPECT_GE(colours_alone, 0.98);  // the default options (issue 22)
}

// The capsules' z-buffer against the GT instances, and
// PosePriorOptions::occluder_limb_radius_m: where one person is seen in front
// of the other, a capsule behind should not claim the front person's pixels.
// Counted over every view of the fixture's frame: claims of person k on GT
// pixels of another person ("swapped") and on k's own GT pixels ("right").
TEST_F(JointViewSynthTest, OccluderMarginRemovesSwappedPoseClaims) {
  const Capture capture = ReadCapture(*dir_);
  FrameReader reader(capture);
  const int frame = 1;
  const JointFrameData data = GtPoseFrameData(capture, &reader, frame);
  double scale = 0;
  const std::vector<JointViewInput> inputs = MakeJointViewInputs(data, {}, &scale);
  const auto count = [&](double occluder_limb_radius_m, int* swapped, int* right) {
    *swapped = *right = 0;
    PosePriorOptions o;
    o.occluder_limb_radius_m = occluder_limb_radius_m;
    for (int v = 0; v < capture.NumViews(); ++v) {
      const JointViewInput& in = inputs[v];
      const ViewTruth t = ReadViewTruth(capture, v, frame);
      const PosePriorMap map =
          RenderPosePrior(in.cameras_t[v], in.cameras_t1[v], in.images_t[v], in.people, o);
      for (int p = 0; p < map.width * map.height; ++p) {
        const int k = map.object.ptr<uint16_t>()[p], g = t.instances.ids.ptr<uint16_t>()[p];
        if (k == 0 || g == 0) continue;
        (g == k ? *right : *swapped) += 1;
      }
    }
  };
  int swapped_plain = 0, right_plain = 0, swapped = 0, right = 0;
  count(PosePriorOptions{}.occluder_limb_radius_m, &swapped_plain, &right_plain);
  count(0.10, &swapped, &right);  // clothed limbs of 10 cm as occluders
  std::printf(
      "pose claims on other / own person: plain z-buffer %d / %d, occluder margin %d / %d\n",
      swapped_plain, right_plain, swapped, right);
  ASSERT_GT(swapped_plain, 0);  // the frame has people in front of each other
  // The capsules are a thin-body prior drawn with a z-buffer: they should claim
  // the wrong person rarely, here on < 2 % of their claims on people (a person
  // is ~4x wider than the 1-2 px the capsule edges may be off at this size).
  EXPECT_LT(swapped_plain, 0.02 * (swapped_plain + right_plain));
  // The margin removes swapped claims (its purpose); it also removes more
  // right claims than swapped ones, which is why it is off by default
  // (pose_prior.h).
  EXPECT_LT(swapped, swapped_plain);
}

// A meetup frame (3 small people outdoors, 4 views at 320x180) with GT poses.
class JointViewMeetupTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    synth::SynthOptions o = synth::SynthPreset("meetup");
    o.mocap_bvh = ShippedDataFile(fs::path("mocap") / "scaled_131_02.bvh");
    o.rig.num_views = 4;
    o.rig.image_width = 320;
    o.rig.image_height = 180;
    o.num_frames = 2;
    dir_ = new fs::path(
        test_util::RemovedAtExit(synth::WriteCaptureToTempDir("joint_view_meetup", o)));
    capture_ = new Capture(ReadCapture(*dir_));
    FrameReader reader(*capture_);
    const JointFrameData data = ReadJointFrameData(*capture_, &reader, 0, ReadGtPoses3d(*capture_));
    double scale = 0;
    inputs_ = new std::vector<JointViewInput>(MakeJointViewInputs(data, {}, &scale));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete inputs_;
    delete capture_;
    delete dir_;
  }
  static JointViewOptions PaperOptions() {
    JointViewOptions options;
    options.weights = PaperWeights(capture_->scene, capture_->NumViews());
    return options;
  }
  static fs::path* dir_;
  static Capture* capture_;
  static std::vector<JointViewInput>* inputs_;
};
fs::path* JointViewMeetupTest::dir_ = nullptr;
Capture* JointViewMeetupTest::capture_ = nullptr;
std::vector<JointViewInput>* JointViewMeetupTest::inputs_ = nullptr;

// The solve's region of interest is the objects' regions dilated by
// roi_margin_px; outside it every pixel is background with no depth or
// motion. Its border pixels are almost all true background (the initial
// masks are dilated by a few pixels, the margin is 8), and nothing in the
// energy favours a person there: the solve must keep them background. (The
// placeholder depth U of the outside pixels once entered E_s and made the
// border ring switch to a person label on textured floor: on a meetup
// frame 154 of 237 false person pixels outside the initial masks of view 0
// lay on that ring.)
TEST_F(JointViewMeetupTest, RegionBorderStaysBackground) {
  int border_background = 0, border_claimed = 0;
  for (int v = 0; v < 2; ++v) {
    const JointViewResult r = SolveJointView((*inputs_)[v], PaperOptions());
    const ViewTruth t = ReadViewTruth(*capture_, v, 0);
    cv::Mat inner;
    cv::erode(r.roi, inner, cv::Mat::ones(3, 3, CV_8U), cv::Point(-1, -1), 1, cv::BORDER_CONSTANT,
              cv::Scalar(0));
    for (int y = 0; y < r.roi.rows; ++y)
      for (int x = 0; x < r.roi.cols; ++x) {
        if (!r.roi.at<uint8_t>(y, x) || inner.at<uint8_t>(y, x)) continue;
        if (t.instances.ids.at<uint16_t>(y, x) != 0) continue;
        ++border_background;
        if (r.labels.at<uint16_t>(y, x) != 0) ++border_claimed;
      }
  }
  std::printf("region border, GT background: %d pixels, labelled a person: %d\n", border_background,
              border_claimed);
  ASSERT_GT(border_background, 100);
  EXPECT_LT(border_claimed, 0.01 * border_background);
}

// JointViewOptions::depth_object_ranges: a person pixel's depth stays within
// the depth range of an object whose grown region holds it (up to the half
// label step of the sub-label refinement), and restricting the depths to the
// objects' ranges costs no depth accuracy against the GT (joint_bench,
// meetup, 3 views: within 5 % 0.988 -> 0.989 with a 1.7x cheaper depth block).
TEST_F(JointViewMeetupTest, DepthObjectRangesHoldAndCostNoDepthAccuracy) {
  eval::DepthMetrics with_ranges, without;
  int checked = 0, outside = 0;
  for (int v = 0; v < 2; ++v) {
    const JointViewInput& in = (*inputs_)[v];
    JointViewOptions options = PaperOptions();
    const JointViewResult r = SolveJointView(in, options);
    // Other labels move the boundaries elsewhere: with E_a's bands the label
    // block once carried an object's depth to a pixel its region does not
    // hold (block_schedule.cc, LabelDepthBlock).
    JointViewOptions banded = options;
    banded.labels.colour_bands = 4;
    const JointViewResult r_banded = SolveJointView(in, banded);
    options.depth_object_ranges = false;
    const JointViewResult r_all = SolveJointView(in, options);
    const ViewTruth t = ReadViewTruth(*capture_, v, 0);
    const cv::Mat people = t.instances.ids > 0;
    with_ranges.Add(eval::EvaluateDepth(r.depth, t.depth, people, "ranges"));
    without.Add(eval::EvaluateDepth(r_all.depth, t.depth, people, "all depths"));
    // Each object's region grown like the ROI.
    const int m = options.roi_margin_px;
    const cv::Mat disk =
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * m + 1, 2 * m + 1));
    std::vector<cv::Mat> grown;
    for (const JointObject& obj : in.objects) {
      cv::Mat g = (in.initial_labels == obj.id) | (obj.region > 0);
      cv::dilate(g, g, disk);
      grown.push_back(g);
    }
    // One depth label step (inverse depth, over the union range) bounds the
    // sub-label refinement (at most half a step).
    double near = 1e30, far = 0;
    for (const JointObject& obj : in.objects)
      near = std::min(near, obj.depth_near), far = std::max(far, obj.depth_far);
    const double step = (1 / near - 1 / far) / (r.num_depth_labels - 2);  // labels: depths + U
    for (const JointViewResult* solved : {&r, &r_banded})
      for (int y = 0; y < r.depth.rows; ++y)
        for (int x = 0; x < r.depth.cols; ++x) {
          const float z = solved->depth.at<float>(y, x);
          if (!(z > 0)) continue;
          bool in_some_region = false, in_range = false;
          for (size_t o = 0; o < in.objects.size(); ++o) {
            if (!grown[o].at<uint8_t>(y, x)) continue;
            in_some_region = true;
            const JointObject& obj = in.objects[o];
            in_range = in_range ||
                       (1 / z <= 1 / obj.depth_near + step && 1 / z >= 1 / obj.depth_far - step);
          }
          if (!in_some_region) continue;
          ++checked;
          if (!in_range) ++outside;
        }
  }
  std::printf("depth within 5%%: object ranges %.3f, every depth %.3f; %d of %d depths outside\n",
              with_ranges.Delta5Pct(), without.Delta5Pct(), outside, checked);
  ASSERT_GT(checked, 500);
  EXPECT_EQ(outside, 0);
  EXPECT_GE(with_ranges.Delta5Pct(), without.Delta5Pct() - 0.005);
  EXPECT_LE(with_ranges.AbsRel(), without.AbsRel() + 0.001);
}

// The people here are ~20 px wide and the detector's masks are dilated by
// 1-2 px, so a quarter of a mask's pixels are background colour: colour
// models learnt from the whole masks (the paper's E_a) take the rim's
// colours into the person model. Learning them from 2 px inside the masks and
// refitting once on the label-only solve (GrabCut's iteration) must raise the
// instance IoU against the GT (joint_bench on 4 meetup views: 0.839 -> 0.878).
TEST_F(JointViewMeetupTest, AppearanceFromInsideTheMasksAndOneRefitRaisesIoU) {
  JointViewOptions paper = PaperOptions();
  paper.appearance_refits = 0;
  paper.labels.appearance_inset_px = 0;
  eval::InstanceSegOptions seg;
  double iou_paper = 0, iou_default = 0;
  for (int v = 0; v < 2; ++v) {
    const ViewTruth t = ReadViewTruth(*capture_, v, 0);
    const auto score = [&](const JointViewOptions& o) {
      const JointViewResult r = SolveJointView((*inputs_)[v], o);
      return eval::EvaluateInstances(PersonInstances(r.labels), t.instances, seg, "refined")
          .mean_instance_iou;
    };
    iou_paper += score(paper) / 2;
    iou_default += score(PaperOptions()) / 2;
  }
  std::printf("mean instance IoU: GMMs of the whole masks %.3f, inside + one refit %.3f\n",
              iou_paper, iou_default);
  EXPECT_GT(iou_default, iou_paper + 0.01);
}

// The initial masks are dilated, so the first depth block gives the false
// person pixels around a person (between the legs, between two people) depths
// that continue the person's surface. A label move at fixed depth then cannot
// make them background: as background they would keep a person's depth against
// their background neighbours (E_s). With the depth carried by the label move
// (the nearest background pixel's depth) they can, and the instance IoU against
// the GT rises (joint_bench on 4 meetup views: 0.878 -> 0.942). The
// energy-trace test above covers the energy never increasing with these moves.
TEST_F(JointViewMeetupTest, LabelMovesCarryingDepthFreeTheBackgroundBetweenLegs) {
  JointViewOptions fixed_depth = PaperOptions();
  fixed_depth.label_moves_carry_depth = false;
  eval::InstanceSegOptions seg;
  double iou_fixed = 0, iou_carried = 0;
  int false_fixed = 0, false_carried = 0;
  for (int v = 0; v < 2; ++v) {
    const ViewTruth t = ReadViewTruth(*capture_, v, 0);
    const auto score = [&](const JointViewOptions& o, int* false_person) {
      const JointViewResult r = SolveJointView((*inputs_)[v], o);
      *false_person += cv::countNonZero((r.labels != 0) & (t.instances.ids == 0));
      return eval::EvaluateInstances(PersonInstances(r.labels), t.instances, seg, "refined")
          .mean_instance_iou;
    };
    iou_fixed += score(fixed_depth, &false_fixed) / 2;
    iou_carried += score(PaperOptions(), &false_carried) / 2;
  }
  std::printf(
      "mean instance IoU: labels at fixed depth %.3f (%d false person pixels), "
      "depth carried %.3f (%d)\n",
      iou_fixed, false_fixed, iou_carried, false_carried);
  EXPECT_GT(iou_carried, iou_fixed + 0.02);
  EXPECT_LT(false_carried, 0.7 * false_fixed);
}

TEST(JointViewTest, RejectsInconsistentInput) {
  JointViewInput in;
  JointViewOptions options;
  EXPECT_THROW(SolveJointView(in, options), Error);  // no views
  options.rounds = 0;
  EXPECT_THROW(options.Check(), Error);
  options = JointViewOptions();
  options.motion_rounds = 0;
  test_util::ExpectErrorMentions([&] { options.Check(); }, {"motion_rounds"});
  options = JointViewOptions();
  options.depth_coarse_step = -1;
  test_util::ExpectErrorMentions([&] { options.Check(); }, {"depth_coarse_step"});
  options = JointViewOptions();
  options.depth_refine_band = -1;
  test_util::ExpectErrorMentions([&] { options.Check(); }, {"depth_refine_band"});
}

// A textured image shifted by a known (3, -2) px: every default proposal
// (DIS fine, DIS medium, their mean) recovers the shift inside the image, and
// the enabled ones come in the documented order and number.
TEST(FlowFusionProposalsTest, RecoverAKnownShiftInTheDocumentedOrder) {
  cv::Mat a(96, 128, CV_8U);
  cv::randu(a, 0, 255);
  cv::GaussianBlur(a, a, cv::Size(5, 5), 1.5);
  cv::Mat b;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 3, 0, 1, -2);
  cv::warpAffine(a, b, shift, a.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  const FlowFusionOptions defaults;
  const std::vector<cv::Mat> proposals = FlowFusionProposals(a, b, defaults);
  ASSERT_EQ(proposals.size(), 3u);  // DIS fine, DIS medium, mean
  const cv::Rect inner(16, 16, 96, 64);
  for (const cv::Mat& f : proposals) {
    ASSERT_EQ(f.type(), CV_32FC2);
    const cv::Scalar mean = cv::mean(f(inner));
    EXPECT_NEAR(mean[0], 3.0, 0.1);
    EXPECT_NEAR(mean[1], -2.0, 0.1);
  }
  FlowFusionOptions one = defaults;
  one.dis_fine = false;
  EXPECT_EQ(FlowFusionProposals(a, b, one).size(), 1u);  // one proposal: no mean
  EXPECT_THROW(FlowFusionProposals(a, b(cv::Rect(0, 0, 64, 64)).clone(), defaults), Error);
  cv::Mat colour;
  cv::cvtColor(a, colour, cv::COLOR_GRAY2BGR);
  EXPECT_THROW(FlowFusionProposals(colour, b, defaults), Error);
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
