// Tests of the unsupervised initial masks (init.h) against the ground truth
// of a synthetic capture: the handshake preset with 4 static cameras.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "u4d/init/init.h"
#include "u4d/io/capture.h"
#include "u4d/io/clean_plate.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/synth/environment.h"
#include "u4d/synth/generate.h"
#include "u4d/synth/render.h"
#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

// The handshake at 2.25 frames/s over an 8 s script (18 frames) (they walk in, shake hands,
// walk a little apart and stand), seen by 4 static cameras. The people stay
// within ~1.5 m of the centre for the whole script, so the capture alone
// never shows the background behind them; a background model needs a
// sequence where the people are elsewhere most of the time. The background
// sequence here is what a recording that starts with the empty room gives:
// 2 * num_frames renders of the empty room (the same environment and
// cameras, each with its own sensor noise) followed by the capture's frames,
// so the people are in one third of the sampled frames.
struct SynthFixture {
  Capture capture;
  std::vector<std::vector<cv::Mat>> images;  // [view][frame]
  std::vector<BackgroundModel> backgrounds;
  // From the capture's own frames only (the people stay in place: the
  // median contains them wherever they are in most frames).
  std::vector<BackgroundModel> self_backgrounds;
  std::vector<Camera> cameras;
};

// Writes `o` and builds the fixture: backgrounds from 2 * num_frames empty
// renders plus the frames, and from the frames alone.
SynthFixture* MakeFixture(const std::string& name, const synth::SynthOptions& o) {
  auto* f = new SynthFixture;
  f->capture = ReadCapture(test_util::RemovedAtExit(synth::WriteCaptureToTempDir(name, o)));
  FrameReader reader(f->capture);
  const int nv = f->capture.NumViews();
  const int nt = f->capture.num_frames;
  for (int v = 0; v < nv; ++v) f->cameras.push_back(f->capture.views[v].CameraAt(0));
  std::vector<std::vector<cv::Mat>> sequence(nv);
  synth::SceneFrame empty;
  empty.statics = synth::MakeEnvironment(o.environment);
  const auto layers = synth::RenderStaticLayers(f->cameras, empty.statics, o.render);
  for (int k = 0; k < 2 * nt; ++k) {
    empty.time = 100.0 + k / o.fps;  // selects the noise stream
    const auto views = synth::RenderViews(f->cameras, empty, o.render, &layers);
    for (int v = 0; v < nv; ++v) sequence[v].push_back(views[v].color);
  }
  f->images.resize(nv);
  BackgroundOptions bo;
  bo.max_frames = 3 * nt;
  for (int v = 0; v < nv; ++v) {
    for (int t = 0; t < nt; ++t) f->images[v].push_back(reader.Read(v, t));
    sequence[v].insert(sequence[v].end(), f->images[v].begin(), f->images[v].end());
    f->backgrounds.push_back(EstimateBackground(sequence[v], bo));
    f->self_backgrounds.push_back(EstimateBackground(f->images[v], bo));
  }
  return f;
}

const SynthFixture& Fixture() {
  static const SynthFixture* fixture = [] {
    synth::SynthOptions o = synth::SmallHandshakeOptions(4, 320, 240, 18);
    o.fps = 2.25;
    o.script_seconds = 8.0;
    o.start_frame = 0;
    o.clean_plate_frames = 5;
    return MakeFixture("init_test", o);
  }();
  return *fixture;
}

cv::Mat GtIds(const Capture& c, int v, int t) {
  return ReadInstanceMask(c.root / layout::GtInstances(c.views[v].name, t),
                          c.root / layout::GtInstancesInfo(c.views[v].name, t))
      .ids;
}

// Per GT person (`truth`, per view), the pixels each of our ids (`named`,
// non-zero) covers, over every view but `skip_view`.
std::map<int, std::map<int, int>> IdVotes(const std::vector<cv::Mat>& truth,
                                          const std::vector<cv::Mat>& named, int skip_view = -1) {
  std::map<int, std::map<int, int>> votes;  // GT id -> our id -> pixels
  for (size_t v = 0; v < truth.size(); ++v)
    if (static_cast<int>(v) != skip_view)
      for (int y = 0; y < truth[v].rows; ++y)
        for (int x = 0; x < truth[v].cols; ++x)
          if (const int g = truth[v].at<uint16_t>(y, x))
            if (const int id = named[v].at<uint16_t>(y, x)) ++votes[g][id];
  return votes;
}

int CountIds(const cv::Mat& ids) {
  double mx = 0;
  cv::minMaxLoc(ids, nullptr, &mx);
  return static_cast<int>(mx);
}

// Distinct ids present (GT ids need not be contiguous).
int DistinctIds(const cv::Mat& ids) {
  std::vector<int> seen;
  for (int y = 0; y < ids.rows; ++y)
    for (int x = 0; x < ids.cols; ++x)
      if (const int id = ids.at<uint16_t>(y, x);
          id && std::find(seen.begin(), seen.end(), id) == seen.end())
        seen.push_back(id);
  return static_cast<int>(seen.size());
}

TEST(InitTest, ForegroundIoUAgainstGroundTruth) {
  const SynthFixture& f = Fixture();
  const int nv = f.capture.NumViews();
  for (const BackgroundModel& b : f.backgrounds) {
    std::printf("background noise sigma %.2f Lab from %d frames\n", b.sigma, b.frames_used);
    // Sensor noise is 1.5 grey levels: about that in 8-bit Lab units.
    EXPECT_LT(b.sigma, 3.0);
    EXPECT_GT(b.sigma, 0.3);
  }
  double inter = 0, uni = 0, inter_raw = 0, uni_raw = 0, inter_box = 0, uni_box = 0;
  InitOptions raw;
  raw.cross_view.enabled = false;
  InitOptions box;  // with GrabCut in weakly covered HOG boxes (off by default)
  box.people.box_fill = PeopleOptions::BoxFill::kAlways;
  for (int t = 0; t < f.capture.num_frames; t += 5) {
    std::vector<cv::Mat> images(nv);
    for (int v = 0; v < nv; ++v) images[v] = f.images[v][t];
    const std::vector<cv::Mat> ids = UnsupervisedInstanceMasks(f.cameras, images, f.backgrounds);
    const std::vector<cv::Mat> idsb =
        UnsupervisedInstanceMasks(f.cameras, images, f.backgrounds, box);
    for (int v = 0; v < nv; ++v) {
      const cv::Mat gt = GtIds(f.capture, v, t) > 0;
      const cv::Mat p = ids[v] > 0;
      inter += cv::countNonZero(gt & p);
      uni += cv::countNonZero(gt | p);
      const cv::Mat q = ForegroundMask(images[v], f.backgrounds[v], raw) > 0;
      const cv::Mat b = idsb[v] > 0;
      inter_box += cv::countNonZero(gt & b);
      uni_box += cv::countNonZero(gt | b);
      inter_raw += cv::countNonZero(gt & q);
      uni_raw += cv::countNonZero(gt | q);
    }
  }
  const double iou = inter / uni, iou_raw = inter_raw / uni_raw;
  std::printf(
      "foreground IoU: %.3f (background subtraction alone %.3f, with GrabCut in HOG boxes %.3f)\n",
      iou, iou_raw, inter_box / uni_box);
  // A static rig with a textured background, 1.5-level noise and no lighting
  // change: the background model sees the true background, so the errors are
  // only where a person's colour is close to what is behind it (dark trousers
  // on the dark wall, shadows classified as background and vice versa) and a
  // 1-2 px band at the silhouette from morphology and anti-aliasing. People
  // are ~50 px tall here, so that band alone is ~10% of their area; 0.75 is
  // what a working background model should reach.
  EXPECT_GT(iou, 0.75);
  EXPECT_GT(iou_raw, 0.75);
}

// Foreground IoU against the GT union of people over frames 0, 5, 10, 15 of
// the 4 views: [0] background subtraction alone (ForegroundMask, no
// cross-view check), then the chain with each of `options`.
std::vector<double> ForegroundIoUs(const SynthFixture& f,
                                   const std::vector<BackgroundModel>& backgrounds,
                                   const std::vector<InitOptions>& options) {
  const int nv = f.capture.NumViews();
  const int m = static_cast<int>(options.size()) + 1;
  InitOptions raw;
  raw.cross_view.enabled = false;
  std::vector<double> i(m, 0.0), u(m, 0.0);
  for (int t = 0; t < f.capture.num_frames; t += 5) {
    std::vector<cv::Mat> images(nv);
    for (int v = 0; v < nv; ++v) images[v] = f.images[v][t];
    std::vector<std::vector<cv::Mat>> ids(m);
    for (int k = 1; k < m; ++k)
      ids[k] = UnsupervisedInstanceMasks(f.cameras, images, backgrounds, options[k - 1]);
    for (int v = 0; v < nv; ++v) {
      const cv::Mat gt = GtIds(f.capture, v, t) > 0;
      for (int k = 0; k < m; ++k) {
        const cv::Mat p =
            k == 0 ? ForegroundMask(images[v], backgrounds[v], raw) > 0 : ids[k][v] > 0;
        i[k] += cv::countNonZero(gt & p);
        u[k] += cv::countNonZero(gt | p);
      }
    }
  }
  std::vector<double> iou(m);
  for (int k = 0; k < m; ++k) iou[k] = i[k] / u[k];
  return iou;
}

TEST(InitTest, StillSubjectsWithBackgroundFromTheCaptureAlone) {
  // The people walk in and then stand for most of the script, so the median
  // of the capture's own frames contains them where they stand: background
  // subtraction finds almost nothing of them in frames 5 and 10 (IoU ~0.01)
  // and ghosts of where they stand beside them in frames 0 and 15. Step 5
  // (ghosts out, GrabCut in the envelope's hull) should recover the standing
  // people in half of the judged frames, i.e. roughly half of the GT area
  // background subtraction misses: a gain of at least 0.2 in pooled IoU over
  // the best of background subtraction alone and the chain without step 5
  // is what a working fill gives (measured: 0.841 vs 0.413 / 0.399).
  // With a background that shows the empty room (the fixture's other
  // backgrounds), the model shows no subject, so step 5 must change nothing
  // beyond noise: not more than 0.005 lower (measured: 0.964 both).
  const SynthFixture& f = Fixture();
  InitOptions before;  // the chain without step 5
  before.still.remove_ghosts = false;
  before.still.still_grabcut_iterations = 0;
  std::vector<InitOptions> variants = {before, InitOptions()};
  std::vector<std::string> names = {"chain without step 5", "default"};
  if (std::getenv("U4D_INIT_ABLATION")) {  // the other variants of docs/init.md (slow)
    InitOptions ghosts_only = before, fill_only = before, no_carve, no_model;
    ghosts_only.still.remove_ghosts = true;
    fill_only.still.still_grabcut_iterations = InitOptions().still.still_grabcut_iterations;
    no_carve.still.carve_still_fill = false;
    no_model.still.still_require_model = false;
    variants.insert(variants.end(), {ghosts_only, fill_only, no_carve, no_model});
    names.insert(names.end(),
                 {"ghosts only", "fill only", "fill not carved", "model not required"});
  }
  std::vector<double> iou[2];
  for (int k = 0; k < 2; ++k) {
    iou[k] = ForegroundIoUs(f, k == 0 ? f.backgrounds : f.self_backgrounds, variants);
    std::printf("%s: IoU background subtraction alone %.3f",
                k == 0 ? "background with the empty room" : "background from the capture alone",
                iou[k][0]);
    for (size_t m = 0; m < names.size(); ++m)
      std::printf(", %s %.3f", names[m].c_str(), iou[k][m + 1]);
    std::printf("\n");
  }
  EXPECT_GE(iou[0][2], iou[0][1] - 0.005);
  EXPECT_GT(iou[0][2], 0.75);
  EXPECT_GT(iou[1][2], std::max(iou[1][0], iou[1][1]) + 0.2);
}

// Known foreground (EstimateBackground's known_foreground): given where the
// people are in each frame (their true masks, dilated by 3 px), the median
// of the capture's own frames leaves them out, so the pixels where they stood
// for most of the script show the room again. Scored on the pixels a person
// covers in some frame but not in every one (elsewhere the median has either
// no choice or nothing to leave out): the share whose background is off the
// empty room's (the fixture's other model) by more than 6 noise levels.
TEST(InitTest, KnownForegroundLeavesWhereThePeopleStoodOutOfTheMedian) {
  const SynthFixture& f = Fixture();
  const int nt = f.capture.num_frames;
  BackgroundOptions bo;
  bo.max_frames = nt;
  double off[2] = {0, 0}, judged = 0;
  for (int v = 0; v < f.capture.NumViews(); ++v) {
    std::vector<cv::Mat> known(nt);
    cv::Mat count = cv::Mat::zeros(f.images[v][0].size(), CV_32S);
    for (int t = 0; t < nt; ++t) {
      cv::dilate(GtIds(f.capture, v, t) > 0, known[t],
                 cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7}));
      cv::add(count, known[t] / 255, count, cv::noArray(), CV_32S);
    }
    const auto read = [&](int t) { return f.images[v][t]; };
    const BackgroundModel models[2] = {
        EstimateBackground(nt, read, bo),
        EstimateBackground(nt, read, bo, [&](int t) { return known[t]; })};
    const BackgroundModel& room = f.backgrounds[v];
    for (int y = 0; y < count.rows; ++y)
      for (int x = 0; x < count.cols; ++x) {
        const int c = count.at<int>(y, x);
        if (c == 0 || c == nt) continue;
        judged += 1;
        const double limit = 6 * std::max(2.0, room.sigma);
        for (int k = 0; k < 2; ++k)
          off[k] += cv::norm(cv::Vec3d(models[k].lab.at<cv::Vec3b>(y, x)) -
                             cv::Vec3d(room.lab.at<cv::Vec3b>(y, x))) > limit;
      }
  }
  std::printf(
      "pixels a person covers in some frames (%.0f): off the room's background %.3f "
      "from all frames, %.3f leaving the known foreground out\n",
      judged, off[0] / judged, off[1] / judged);
  ASSERT_GT(judged, 0);
  EXPECT_GT(off[0] / judged, 0.1) << "the world has people who stand still";
  EXPECT_LT(off[1] / judged, 0.02);
  // A known mask of another size is an error naming the frame.
  test_util::ExpectErrorMentions(
      [&] {
        EstimateBackground(
            nt, [&](int t) { return f.images[0][t]; }, bo,
            [](int) { return cv::Mat(4, 4, CV_8UC1, cv::Scalar(0)); });
      },
      {"frame 0", "known foreground"});
}

// The people stand still for most of the script, so a background from the
// capture alone holds them; the clean plate (5 frames of the empty stage,
// their own sensor noise) does not. The issue asks for a foreground IoU of
// at least 0.95 against ground truth from a plate, with the default chain;
// a single plate picture (noise from the take) must do as well.
TEST(InitTest, StillPeopleAgainstACleanPlate) {
  const SynthFixture& f = Fixture();
  std::vector<BackgroundModel> plates, single;
  for (int v = 0; v < f.capture.NumViews(); ++v) {
    const std::vector<cv::Mat> plate = ReadCleanPlate(f.capture.root, f.capture.views[v].name,
                                                      f.cameras[v].width, f.cameras[v].height);
    ASSERT_EQ(plate.size(), 5u);
    const auto read = [&](int t) { return f.images[v][t]; };
    plates.push_back(BackgroundFromPlate(plate, f.capture.num_frames, read));
    single.push_back(BackgroundFromPlate({plate[0]}, f.capture.num_frames, read));
  }
  const double from_plate = ForegroundIoUs(f, plates, {InitOptions()})[1];
  const double from_one = ForegroundIoUs(f, single, {InitOptions()})[1];
  const double from_take = ForegroundIoUs(f, f.self_backgrounds, {InitOptions()})[1];
  std::printf(
      "foreground IoU: clean plate (5 frames) %.3f, one plate picture %.3f, capture "
      "alone %.3f\n",
      from_plate, from_one, from_take);
  EXPECT_GE(from_plate, 0.95);
  EXPECT_GE(from_one, 0.95);
  EXPECT_LT(single[0].sigma, 3.0);  // sensor noise of 1.5 grey levels, as above
}

// People who never move: a background from the capture's own frames holds
// them entirely, so background subtraction (and step 5, which needs some
// motion) finds nothing. The default box fill (GrabCut in HOG boxes, in
// views the background leaves empty) must find a clear part of them (a
// quarter of the union) without a plate. The issue asks for 0.85; that is
// not reached: OpenCV's HOG finds one of the two people per view here (at
// 320x240 at most one in two views), so the test holds the gain, not the goal.
// Two people who stand still from the first frame, no plate: background
// subtraction finds nothing, so the automatic choice (box_fill kEmptyViews)
// runs GrabCut in person boxes. OpenCV's HOG boxes miss one of the two in
// most views and cut the other short; boxes of the people that two views'
// boxes place on the floor (step 4b) cover both in every view. The issue
// asks for a foreground IoU of at least 0.85 against ground truth: here the
// mean over two seeds (7, and 8 which the step was not developed on).
TEST(InitTest, StillPeopleWithoutAPlateFoundInHogBoxes) {
  InitOptions never, single_view;
  never.people.box_fill = PeopleOptions::BoxFill::kNever;
  single_view.people.boxes_from_views = false;
  std::vector<double> sum(4, 0.0);
  for (const int seed : {7, 8}) {
    synth::SynthOptions o = synth::SmallHandshakeOptions(4, 640, 480, 6);
    o.still_people = true;
    o.seed = seed;
    const std::unique_ptr<const SynthFixture> still(
        MakeFixture("init_still_test_" + std::to_string(seed), o));
    const std::vector<double> iou =
        ForegroundIoUs(*still, still->self_backgrounds, {never, single_view, {}});
    std::printf(
        "still people (seed %d), background from the capture alone: IoU without box fill %.3f, "
        "single-view HOG boxes %.3f, default (boxes from views) %.3f\n",
        seed, iou[1], iou[2], iou[3]);
    for (int k = 0; k < 4; ++k) sum[k] += iou[k] / 2;
  }
  EXPECT_LT(sum[1], 0.1);  // nothing to subtract: the people are the background
  EXPECT_GE(sum[3], 0.85);
  EXPECT_GT(sum[3], sum[2] + 0.1);
}

// A person who never moves, on a flat grey stage with sensor noise: the
// capture's own frames make them background, the plate does not. The
// foreground must be the true square (IoU with it >= 0.95: only noise can
// disagree), and plates that do not fit the frames are errors.
TEST(InitTest, PlateFindsAPersonTheFramesHide) {
  cv::RNG rng(3);
  const auto noisy = [&](bool person) {
    cv::Mat image(120, 160, CV_8UC3, cv::Scalar(120, 120, 120));
    if (person) image(cv::Rect(60, 30, 30, 70)).setTo(cv::Scalar(40, 60, 170));
    cv::Mat noise(image.size(), CV_16SC3);
    rng.fill(noise, cv::RNG::NORMAL, 0, 1.5);
    cv::Mat out;
    cv::add(image, noise, out, cv::noArray(), CV_8UC3);
    return out;
  };
  std::vector<cv::Mat> frames, plate;
  for (int t = 0; t < 8; ++t) frames.push_back(noisy(true));
  for (int k = 0; k < 3; ++k) plate.push_back(noisy(false));
  const auto read = [&](int t) { return frames[t]; };
  const cv::Mat truth = cv::Mat::zeros(120, 160, CV_8UC1);
  truth(cv::Rect(60, 30, 30, 70)).setTo(255);
  const auto iou = [&](const cv::Mat& fg) {
    return cv::countNonZero(fg & truth) / static_cast<double>(cv::countNonZero(fg | truth));
  };
  EXPECT_LT(iou(ForegroundMask(frames[0], EstimateBackground(frames))), 0.05);
  EXPECT_GE(iou(ForegroundMask(frames[0], BackgroundFromPlate(plate, 8, read))), 0.95);
  EXPECT_GE(iou(ForegroundMask(frames[0], BackgroundFromPlate({plate[0]}, 8, read))), 0.95);

  test_util::ExpectErrorMentions(
      [&] {
        BackgroundFromPlate({plate[0], cv::Mat(10, 10, CV_8UC3)}, 8, read);
      },
      {"clean plate", "frame 1"});
  test_util::ExpectErrorMentions(
      [&] { BackgroundFromPlate({cv::Mat(10, 10, CV_8UC3, cv::Scalar::all(9))}, 8, read); },
      {"160x120", "10x10"});
  EXPECT_THROW(BackgroundFromPlate({}, 8, read), Error);
}

TEST(InitTest, InstanceCountWhenPeopleApart) {
  const SynthFixture& f = Fixture();
  const int nv = f.capture.NumViews();
  int judged = 0, right = 0;
  for (int t = 0; t < f.capture.num_frames; t += 3) {
    std::vector<cv::Mat> images(nv);
    for (int v = 0; v < nv; ++v) images[v] = f.images[v][t];
    const std::vector<cv::Mat> ids = UnsupervisedInstanceMasks(f.cameras, images, f.backgrounds);
    for (int v = 0; v < nv; ++v) {
      const cv::Mat gt = GtIds(f.capture, v, t);
      const int n_gt = DistinctIds(gt);
      if (n_gt == 0) continue;
      // People apart: the GT components of the union are as many as the people
      // (no touching or occlusion in this view), each bigger than 100 px.
      cv::Mat labels, stats, cents;
      const int nc = cv::connectedComponentsWithStats(gt > 0, labels, stats, cents, 8) - 1;
      if (nc != n_gt) continue;
      bool all_big = true;
      for (int c = 1; c <= nc; ++c) all_big &= stats.at<int>(c, cv::CC_STAT_AREA) > 100;
      if (!all_big) continue;
      ++judged;
      right += DistinctIds(ids[v]) == n_gt;
      if (DistinctIds(ids[v]) != n_gt)
        std::printf("t %d view %d: %d ids, %d people\n", t, v, DistinctIds(ids[v]), n_gt);
    }
  }
  std::printf("instance count right in %d of %d view-frames with people apart\n", right, judged);
  ASSERT_GT(judged, 10);
  // Separate people give separate components unless a person's part is lost
  // (splitting them) or a shadow links them: "most" frames, i.e. >= 80%.
  EXPECT_GE(right, 0.8 * judged);
}

TEST(InitTest, DetectorBoxesSplitTouchingPeople) {
  // Where the two people touch (one GT component), boxes around each person
  // (what a perfect HOG detector gives, 10% margin) must split the union of
  // the GT silhouettes into two instances. Pixels are assigned by the nearest
  // box centre column, so only where the boxes overlap (the clasped hands and
  // arms, ~10% of a person) can a pixel go to the wrong person: per-person
  // IoU >= 0.7 is what the split should reach.
  const SynthFixture& f = Fixture();
  int tested = 0;
  for (int t = 0; t < f.capture.num_frames && tested < 4; ++t) {
    for (int v = 0; v < f.capture.NumViews() && tested < 4; ++v) {
      const cv::Mat gt = GtIds(f.capture, v, t);
      if (DistinctIds(gt) != 2) continue;
      cv::Mat labels;
      if (cv::connectedComponents(gt > 0, labels, 8) - 1 != 1) continue;
      std::vector<int> ids;
      for (int y = 0; y < gt.rows; ++y)
        for (int x = 0; x < gt.cols; ++x)
          if (const int id = gt.at<uint16_t>(y, x);
              id && std::find(ids.begin(), ids.end(), id) == ids.end())
            ids.push_back(id);
      std::vector<PersonBox> boxes;
      bool big = true;
      for (const int id : ids) {
        const cv::Mat m = gt == id;
        big &= cv::countNonZero(m) > 150;
        const cv::Rect r = cv::boundingRect(m);
        const int mx = r.width / 10, my = r.height / 10;
        boxes.push_back({cv::Rect(r.x - mx, r.y - my, r.width + 2 * mx, r.height + 2 * my) &
                             cv::Rect(0, 0, gt.cols, gt.rows),
                         1.0});
      }
      // Boxes must be apart horizontally (half a box width), else it is an occlusion.
      const double c0 = boxes[0].box.x + 0.5 * boxes[0].box.width;
      const double c1 = boxes[1].box.x + 0.5 * boxes[1].box.width;
      if (!big || std::abs(c0 - c1) < 0.5 * std::min(boxes[0].box.width, boxes[1].box.width))
        continue;
      ++tested;
      InitOptions options;
      options.people.min_instance_fraction = 0;
      const cv::Mat split = SplitInstances(f.images[v][t], gt > 0, boxes, options);
      ASSERT_EQ(CountIds(split), 2) << "view " << v << " frame " << t;
      for (const int id : ids) {
        const cv::Mat g = gt == id;
        double best = 0;
        for (int k = 1; k <= 2; ++k) {
          const cv::Mat p = split == k;
          best = std::max(best,
                          static_cast<double>(cv::countNonZero(g & p)) / cv::countNonZero(g | p));
        }
        std::printf("view %d frame %d person %d: IoU %.3f\n", v, t, id, best);
        EXPECT_GT(best, 0.7);
      }
    }
  }
  std::printf("touching view-frames tested: %d\n", tested);
  EXPECT_GT(tested, 0);
}

TEST(InitTest, CrossViewCheckRemovesInjectedBlob) {
  const SynthFixture& f = Fixture();
  const int nv = f.capture.NumViews();
  const int t = f.capture.num_frames / 2;
  std::vector<cv::Mat> masks(nv);
  for (int v = 0; v < nv; ++v) masks[v] = (GtIds(f.capture, v, t) > 0);
  // A false blob in view 0 away from the people: a disc in the upper left.
  cv::Mat people = masks[0].clone();
  const cv::Point centre(masks[0].cols / 6, masks[0].rows / 5);
  ASSERT_EQ(cv::countNonZero(people(cv::Rect(centre - cv::Point(20, 20), cv::Size(40, 40)))), 0);
  cv::circle(masks[0], centre, 12, cv::Scalar(255), cv::FILLED);
  std::vector<double> share;
  const std::vector<cv::Mat> out = CrossViewConsistentMasks(f.cameras, masks, {}, &share);
  std::printf("consistent share per view:");
  for (const double s : share) std::printf(" %.3f", s);
  std::printf("\n");
  // The blob is gone, the people stay (true silhouettes are consistent).
  EXPECT_EQ(out[0].at<uint8_t>(centre), 0);
  for (int v = 0; v < nv; ++v) {
    const cv::Mat& truth = v == 0 ? people : masks[v];
    const double kept = static_cast<double>(cv::countNonZero(out[v] & truth)) /
                        std::max(1, cv::countNonZero(truth));
    EXPECT_GT(kept, 0.95) << "view " << v;
  }
}

// Three people meet (the meetup preset: one driven by CMU mocap, outdoors),
// seen by the preset's 8 static cameras at 320x240, 6 frames at 0.9 fps
// over the 6.7 s script: they walk in from apart, meet and stand close.
const SynthFixture& MeetupFixture() {
  static const SynthFixture* fixture = [] {
    synth::SynthOptions o = synth::SynthPreset("meetup");
    o.mocap_bvh = ShippedDataFile(fs::path("mocap") / "scaled_131_02.bvh");
    o.rig.num_views = 8;
    o.rig.image_width = 320;
    o.rig.image_height = 240;
    o.num_frames = 6;
    o.fps = 0.9;
    o.script_seconds = 6.7;
    o.start_frame = 0;
    o.write_meshes = false;
    return MakeFixture("init_meetup", o);
  }();
  return *fixture;
}

// Instances against the GT people, pooled over the fixture's frames and views.
struct InstanceScores {
  double mean_iou = 0;   // per GT person-view: IoU of its one-to-one matched instance (0 if none)
  double found = 0;      // share of GT person-views matched with IoU >= 0.5
  double same_id = 0;    // of (frame, person) found in >= 2 views: share with one id in all
  int person_views = 0;  // GT person-views judged (> 50 px)
};

// `instances(t)`: the ids of every view at frame t.
InstanceScores ScoreInstances(const SynthFixture& f,
                              const std::function<std::vector<cv::Mat>(int)>& instances) {
  const int nv = f.capture.NumViews();
  InstanceScores s;
  int groups = 0, same = 0;
  for (int t = 0; t < f.capture.num_frames; ++t) {
    const std::vector<cv::Mat> ids = instances(t);
    std::map<int, std::vector<int>> matched;  // GT person -> predicted ids (IoU >= 0.5)
    for (int v = 0; v < nv; ++v) {
      const cv::Mat gt = GtIds(f.capture, v, t);
      std::vector<int> gt_ids, pred_ids;
      for (const auto& [image, list] : {std::pair{&gt, &gt_ids}, std::pair{&ids[v], &pred_ids}})
        for (int y = 0; y < image->rows; ++y)
          for (int x = 0; x < image->cols; ++x)
            if (const int id = image->at<uint16_t>(y, x);
                id && std::find(list->begin(), list->end(), id) == list->end())
              list->push_back(id);
      struct Pair {
        double iou;
        int g, p;
      };
      std::vector<Pair> pairs;
      std::vector<int> judged;
      for (const int g : gt_ids) {
        const cv::Mat gm = gt == g;
        if (cv::countNonZero(gm) <= 50) continue;
        judged.push_back(g);
        for (const int p : pred_ids) {
          const cv::Mat pm = ids[v] == p;
          pairs.push_back(
              {static_cast<double>(cv::countNonZero(gm & pm)) / cv::countNonZero(gm | pm), g, p});
        }
      }
      std::sort(pairs.begin(), pairs.end(),
                [](const Pair& a, const Pair& b) { return a.iou > b.iou; });
      std::vector<int> used_g, used_p;
      for (const Pair& q : pairs) {
        if (std::count(used_g.begin(), used_g.end(), q.g) ||
            std::count(used_p.begin(), used_p.end(), q.p))
          continue;
        used_g.push_back(q.g);
        used_p.push_back(q.p);
        s.mean_iou += q.iou;
        if (q.iou >= 0.5) {
          s.found += 1;
          matched[q.g].push_back(q.p);
        }
      }
      s.person_views += static_cast<int>(judged.size());
    }
    for (const auto& [g, preds] : matched) {
      if (preds.size() < 2) continue;
      ++groups;
      same += std::all_of(preds.begin(), preds.end(), [&](int p) { return p == preds[0]; });
    }
  }
  s.mean_iou /= std::max(1, s.person_views);
  s.found /= std::max(1, s.person_views);
  s.same_id = static_cast<double>(same) / std::max(1, groups);
  return s;
}

TEST(InitTest, GroundOccupancySplitsMergedPeopleWithOneIdAcrossViews) {
  // Step 6 alone on the GT silhouettes of the three people meeting, merged
  // into one instance per view (the worst a per-view split can do): the
  // people must come apart on the ground plane and each be named alike in
  // all views. Where two stand close in a view's line of sight the ray's
  // nearest person takes the pixels of both, so not every person-view is
  // recovered; "most" (>= 0.75 matched with IoU >= 0.5) is what separation
  // on the ground gives with 8 views, and ids must agree across views for
  // >= 0.9 of the people found in two views or more.
  const SynthFixture& f = MeetupFixture();
  const auto unsplit = [&](int t) {
    std::vector<cv::Mat> instances;
    for (int v = 0; v < f.capture.NumViews(); ++v) {
      cv::Mat one;
      cv::Mat(GtIds(f.capture, v, t) > 0).convertTo(one, CV_16U, 1.0 / 255);
      instances.push_back(one);
    }
    return instances;
  };
  const auto merged = [&](int t) { return SeparatePeopleOnGround(f.cameras, unsplit(t)); };
  const InstanceScores a = ScoreInstances(f, unsplit);
  const InstanceScores b = ScoreInstances(f, merged);
  std::printf("merged: mean matched IoU %.3f, found %.3f of %d person-views\n", a.mean_iou, a.found,
              a.person_views);
  std::printf("step 6: mean matched IoU %.3f, found %.3f, same id across views %.3f\n", b.mean_iou,
              b.found, b.same_id);
  ASSERT_GT(b.person_views, 60);
  EXPECT_GE(b.found, 0.75);
  EXPECT_GT(b.found, a.found + 0.3);
  EXPECT_GE(b.same_id, 0.9);
}

// People who touch merge on the ground map; the previous frame's people
// keep them apart (SeparatePeopleOnGround's previous_people). The realistic
// world's two captured performers touch within its first 10 frames; frame
// by frame, carrying each frame's positions to the next as the pipeline
// does, step 6 on their true silhouettes (one instance per view, the worst
// a detector can merge) must see two people in every frame.
const SynthFixture& TouchFixture(const fs::path& captured_meshes) {
  static const SynthFixture* touch = [&] {
    return MakeFixture("init_touch", synth::SmallRealisticOptions(captured_meshes, 320, 180, 10));
  }();
  return *touch;
}

TEST(InitTest, GroundOccupancyKeepsApartPeopleWhoWereApart) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  const SynthFixture& f = TouchFixture(data);
  std::vector<Eigen::Vector3d> previous;
  int two_alone = 0, two_carried = 0;
  for (int t = 0; t < f.capture.num_frames; ++t) {
    std::vector<cv::Mat> union_masks;
    for (int v = 0; v < f.capture.NumViews(); ++v) {
      cv::Mat one;
      cv::Mat(GtIds(f.capture, v, t) > 0).convertTo(one, CV_16U, 1.0 / 255);
      union_masks.push_back(one);
    }
    OccupancyMap alone, carried;
    SeparatePeopleOnGround(f.cameras, union_masks, {}, &alone);
    SeparatePeopleOnGround(f.cameras, union_masks, {}, &carried, previous);
    previous.assign(carried.positions.begin() + 1, carried.positions.end());
    std::printf("frame %d: people on the map alone %d, with the previous frame's %d\n", t,
                alone.num_people, carried.num_people);
    two_alone += alone.num_people == 2;
    two_carried += carried.num_people == 2;
  }
  EXPECT_LT(two_alone, f.capture.num_frames);  // they do merge on the map alone
  EXPECT_EQ(two_carried, f.capture.num_frames);
}

// Touching people are one region on the map; when the given instances hold
// them apart (true masks, numbered anew in every view, as a detector does),
// step 6 must split the region by them and name them, without any previous
// frame: in every frame exactly the two people, each one id in every view
// where it is visible, two people never one id (against the ground truth).
TEST(InitTest, GroundOccupancySplitsTouchingPeopleByTheirInstances) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  const SynthFixture& f = TouchFixture(data);
  const int nv = f.capture.NumViews();
  for (int t = 0; t < f.capture.num_frames; ++t) {
    std::vector<cv::Mat> truth, given;
    for (int v = 0; v < nv; ++v) {
      truth.push_back(GtIds(f.capture, v, t));
      // Renumbered per view: GT id g becomes (g + v) % 7 + 1.
      cv::Mat local = cv::Mat::zeros(truth[v].size(), CV_16UC1);
      for (int y = 0; y < local.rows; ++y)
        for (int x = 0; x < local.cols; ++x)
          if (const int g = truth[v].at<uint16_t>(y, x))
            local.at<uint16_t>(y, x) = static_cast<uint16_t>((g + v) % 7 + 1);
      given.push_back(local);
    }
    OccupancyMap map;
    const std::vector<cv::Mat> named = SeparatePeopleOnGround(f.cameras, given, {}, &map, {},
                                                              /*instances_are_people=*/true);
    EXPECT_EQ(map.num_people, 2) << "frame " << t;
    const auto votes = IdVotes(truth, named);
    std::set<int> ids;
    for (const auto& [g, by_id] : votes) {
      int total = 0, best = 0, best_id = 0;
      for (const auto& [id, n] : by_id) {
        total += n;
        if (n > best) best = n, best_id = id;
      }
      EXPECT_GE(best, 0.99 * total) << "frame " << t << ": GT person " << g << " has several ids";
      ids.insert(best_id);
    }
    EXPECT_EQ(ids.size(), votes.size()) << "frame " << t << ": two people share one id";
  }
}

// A detector that merges two people in one view often also keeps a scrap of
// the one it merged as an instance of its own (a foot, a hand). That scrap is
// then the person's pair in the view, and the merged instance must still be
// split by the person's rays: on the realistic world's true silhouettes
// (renumbered per view), in the view where both performers are seen largest,
// the smaller one's instance is merged into the other's but for its lowest
// 15 % of rows, kept apart. Against the ground truth, in that view, at least
// 0.8 of the smaller performer's merged pixels must take the id it has in the
// other views, and at least 0.9 of the other's keep its own.
TEST(InitTest, GroundOccupancySplitsAMergeWhoseSecondPersonKeptAScrap) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  const SynthFixture& f = TouchFixture(data);
  const int nv = f.capture.NumViews(), t = 0;
  std::vector<cv::Mat> truth;
  int view = -1, best = 0;
  for (int v = 0; v < nv; ++v) {
    truth.push_back(GtIds(f.capture, v, t));
    const int smaller = std::min(cv::countNonZero(truth[v] == 1), cv::countNonZero(truth[v] == 2));
    if (smaller > best) best = smaller, view = v;
  }
  ASSERT_GE(view, 0);
  const int scrap_person =
      cv::countNonZero(truth[view] == 1) < cv::countNonZero(truth[view] == 2) ? 1 : 2;
  const cv::Rect box = cv::boundingRect(truth[view] == scrap_person);
  const int scrap_top = box.y + box.height * 85 / 100;
  std::vector<cv::Mat> given;
  for (int v = 0; v < nv; ++v) {
    cv::Mat local = cv::Mat::zeros(truth[v].size(), CV_16UC1);
    for (int y = 0; y < local.rows; ++y)
      for (int x = 0; x < local.cols; ++x)
        if (const int g = truth[v].at<uint16_t>(y, x))
          local.at<uint16_t>(y, x) = static_cast<uint16_t>(
              v != view ? g : (g == scrap_person && y >= scrap_top ? 2 : 1));  // merged: 1
    given.push_back(local);
  }
  const std::vector<cv::Mat> named = SeparatePeopleOnGround(f.cameras, given, {}, nullptr, {},
                                                            /*instances_are_people=*/true);
  // Each person's id: the one it holds most in the other views.
  std::map<int, int> id_of;
  for (const auto& [g, by_id] : IdVotes(truth, named, view))
    id_of[g] = std::max_element(by_id.begin(), by_id.end(), [](const auto& a, const auto& b) {
                 return a.second < b.second;
               })->first;
  ASSERT_EQ(id_of.size(), 2u);
  ASSERT_NE(id_of[1], id_of[2]);
  std::map<int, std::pair<int, int>> kept;  // GT id -> (merged pixels with its id, merged pixels)
  for (int y = 0; y < truth[view].rows; ++y)
    for (int x = 0; x < truth[view].cols; ++x)
      if (given[view].at<uint16_t>(y, x) == 1) {
        const int g = truth[view].at<uint16_t>(y, x);
        kept[g].first += named[view].at<uint16_t>(y, x) == id_of[g];
        ++kept[g].second;
      }
  const double scrap_share =
      kept[scrap_person].first / std::max(1.0, 1.0 * kept[scrap_person].second);
  const double other_share =
      kept[3 - scrap_person].first / std::max(1.0, 1.0 * kept[3 - scrap_person].second);
  std::printf(
      "view %d: merged pixels under their own id: the scrap's person %.3f of %d, the other %.3f of "
      "%d\n",
      view, scrap_share, kept[scrap_person].second, other_share, kept[3 - scrap_person].second);
  EXPECT_GE(scrap_share, 0.8);
  EXPECT_GE(other_share, 0.9);
}

// The realistic world's detector-like masks at 960x540 (seed 1, frame 0):
// the detector merges the two performers in four of the eight views and
// drops one view, so their cones are fat, and in the views that keep them
// apart one performer's instance meets the other's cone first: the instance
// split cut that performer in two (three people on the map, a spare id
// through the run). A split is kept only when its parts are seen apart
// (min_split_exclusive_share): two people, each one id in every view
// (against the ground truth).
TEST(InitTest, GroundOccupancyDoesNotCutAPersonTheDetectorMergedInHalfTheViews) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  const fs::path dir = test_util::RemovedAtExit(synth::WriteCaptureToTempDir(
      "init_merged_half", synth::SmallRealisticOptions(data, 960, 540, 2)));
  const Capture capture = ReadCapture(dir);
  std::vector<Camera> cameras;
  std::vector<cv::Mat> given, truth;
  for (int v = 0; v < capture.NumViews(); ++v) {
    cameras.push_back(capture.views[v].CameraAt(0));
    truth.push_back(ReadLabelImage(dir / layout::GtInstances(capture.views[v].name, 0)));
    const fs::path png = dir / layout::Mask(capture.views[v].name, 0);
    cv::Mat ids = fs::exists(png) ? ReadLabelImage(png) : cv::Mat();
    if (ids.empty()) ids = cv::Mat::zeros(cameras[v].height, cameras[v].width, CV_16UC1);
    ids.convertTo(ids, CV_16U);
    given.push_back(ids);
  }
  // Per GT person, the share of its named pixels (all views) under its main id.
  const auto main_id_share = [&](const std::vector<cv::Mat>& named) {
    std::map<int, double> share;
    for (const auto& [g, by_id] : IdVotes(truth, named)) {
      int total = 0, best = 0;
      for (const auto& [id, n] : by_id) total += n, best = std::max(best, n);
      share[g] = static_cast<double>(best) / total;
    }
    return share;
  };
  InitOptions keep_all;
  keep_all.ground.min_split_exclusive_share = 0;
  OccupancyMap map, map_keep_all;
  const auto share = main_id_share(SeparatePeopleOnGround(cameras, given, {}, &map, {},
                                                          /*instances_are_people=*/true));
  const auto share_keep_all =
      main_id_share(SeparatePeopleOnGround(cameras, given, keep_all, &map_keep_all, {}, true));
  std::printf("people on the map: %d (every split kept: %d)\n", map.num_people,
              map_keep_all.num_people);
  EXPECT_EQ(map.num_people, 2);
  ASSERT_EQ(share.size(), 2u);
  for (const auto& [g, s] : share) {
    std::printf(
        "GT person %d: %.3f of its named pixels under its main id (every split kept: %.3f)\n", g, s,
        share_keep_all.count(g) ? share_keep_all.at(g) : 0.0);
    EXPECT_GT(s, 0.8) << "GT person " << g << " is cut between ids";
  }
  fs::remove_all(dir);
}

TEST(InitTest, GroundOccupancyNamesPeopleAlikeInAllViews) {
  // The whole chain on the three people meeting, with step 6 (default) and
  // without (step 4 per view). Step 6 keeps step 4's instances unless the
  // hull shows one holds two people (it splits it) or none (it drops it), so
  // it must find at least as many person-views, and it names a person alike
  // in every view (>= 0.9 of the people found in two views or more), where
  // step 4 numbers each view left to right.
  const SynthFixture& f = MeetupFixture();
  const auto chain = [&](const InitOptions& options) {
    return [&f, options](int t) {
      std::vector<cv::Mat> images;
      for (const auto& view : f.images) images.push_back(view[t]);
      return UnsupervisedInstanceMasks(f.cameras, images, f.backgrounds, options);
    };
  };
  InitOptions per_view;
  per_view.ground.enabled = false;
  const InstanceScores a = ScoreInstances(f, chain(per_view));
  const InstanceScores b = ScoreInstances(f, chain(InitOptions()));
  for (const auto& [name, sc] :
       {std::pair{"per view (step 4)", a}, std::pair{"ground occupancy (step 6)", b}})
    std::printf(
        "%s: mean matched IoU %.3f, found %.3f of %d person-views, same id across views %.3f\n",
        name, sc.mean_iou, sc.found, sc.person_views, sc.same_id);
  ASSERT_GT(b.person_views, 60);
  EXPECT_GE(b.found, a.found);
  EXPECT_GE(b.same_id, 0.9);
}

TEST(InitTest, RigUpDirectionIsTheSyntheticWorldsUp) {
  // Synthetic worlds are y up (docs/conventions.md); the cameras look down
  // at the people from 1.5-3 m, so their -y axes lean towards the centre
  // while their x axes stay horizontal.
  for (const SynthFixture* f : {&Fixture(), &MeetupFixture()}) {
    const Eigen::Vector3d up = RigUpDirection(f->cameras);
    const double degrees = std::acos(std::clamp(up.y(), -1.0, 1.0)) * 180 / M_PI;
    std::printf("%zu cameras: up (%.4f, %.4f, %.4f), %.3f degrees from +y\n", f->cameras.size(),
                up.x(), up.y(), up.z(), degrees);
    EXPECT_LT(degrees, 1.0);
  }
}

TEST(InitTest, FailsClearlyOnBadInput) {
  const SynthFixture& f = Fixture();
  EXPECT_THROW(EstimateBackground(std::vector<cv::Mat>{}), Error);
  EXPECT_THROW(EstimateBackground({cv::Mat()}), Error);
  EXPECT_THROW(EstimateBackground({cv::Mat(10, 10, CV_8UC3), cv::Mat(12, 10, CV_8UC3)}), Error);
  EXPECT_THROW(ForegroundMask(cv::Mat(10, 10, CV_8UC3), f.backgrounds[0]), Error);
  EXPECT_THROW(UnsupervisedInstanceMasks(f.cameras, {f.images[0][0]}, f.backgrounds), Error);
  // Step 6: instance images must be CV_16UC1 of the cameras' sizes, one per camera.
  std::vector<cv::Mat> none(f.cameras.size(), cv::Mat::zeros(240, 320, CV_16UC1));
  EXPECT_NO_THROW(SeparatePeopleOnGround(f.cameras, none));
  none[1] = cv::Mat::zeros(240, 320, CV_8UC1);
  EXPECT_THROW(SeparatePeopleOnGround(f.cameras, none), Error);
  none[1] = cv::Mat::zeros(120, 160, CV_16UC1);
  EXPECT_THROW(SeparatePeopleOnGround(f.cameras, none), Error);
  none.pop_back();
  EXPECT_THROW(SeparatePeopleOnGround(f.cameras, none), Error);
  EXPECT_THROW(RigUpDirection({}), Error);
  InitOptions bad;
  bad.cross_view.min_view_fraction = 1.5;
  EXPECT_THROW(bad.Check(), Error);
  try {
    bad.Check();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("min_view_fraction"), std::string::npos);
  }
  // An InstanceMask that round-trips through the capture format.
  const int t = f.capture.num_frames / 2;
  const std::vector<cv::Mat> ids = UnsupervisedInstanceMasks(
      f.cameras, {f.images[0][t], f.images[1][t], f.images[2][t], f.images[3][t]}, f.backgrounds);
  ASSERT_EQ(ids.size(), 4u);
  EXPECT_EQ(ids[0].type(), CV_16UC1);
  const InstanceMask m = ToInstanceMask(ids[0]);
  EXPECT_EQ(static_cast<int>(m.instances.size()), CountIds(ids[0]));  // ids 1..n, contiguous
  for (const InstanceInfo& info : m.instances) EXPECT_EQ(info.label, "person");
  EXPECT_THROW(ToInstanceMask(cv::Mat(4, 4, CV_8UC1)), Error);
  // Step 5: bad options name their field, sizes must match.
  InitOptions bad_still;
  bad_still.still.still_max_side = 8;
  try {
    bad_still.Check();
    ADD_FAILURE() << "still_max_side = 8 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("still_max_side"), std::string::npos);
  }
  BackgroundOptions bad_bg;
  bad_bg.envelope_min_frames = 0;
  EXPECT_THROW(bad_bg.Check(), Error);
  EXPECT_THROW(FillStillSubjects(f.images[0][t], cv::Mat(10, 10, CV_8UC1), f.backgrounds[0]),
               Error);
  EXPECT_THROW(RemoveGhosts(cv::Mat(10, 10, CV_8UC3), cv::Mat(10, 10, CV_8UC1), f.backgrounds[0]),
               Error);
  // The envelope is the people's sweep: some foreground, far from all of it.
  const double env_share = static_cast<double>(cv::countNonZero(f.backgrounds[0].envelope)) /
                           f.backgrounds[0].envelope.total();
  EXPECT_GT(env_share, 0.0);
  EXPECT_LT(env_share, 0.5);
}

}  // namespace
}  // namespace u4d
