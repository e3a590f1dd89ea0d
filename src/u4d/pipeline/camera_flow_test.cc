#include "u4d/pipeline/camera_flow.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "u4d/baselines/dense_flow.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

// The synthetic handshake where the people walk apart (docs/flow.md), 2
// views at 480x270: view 0 of frame 0 with its GT labels and flow.
struct Frame {
  cv::Mat image_t, image_t1, labels, flow, valid, labels_t1;
};

class CameraFlowTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    synth::SynthOptions o = synth::SmallHandshakeOptions(2, 480, 270, 2);
    o.start_frame = 128;
    const Capture c =
        ReadCapture(test_util::RemovedAtExit(synth::WriteCaptureToTempDir("camera_flow_test", o)));
    frame_ = new Frame{ReadColorImage(c.ImagePath(0, 0)),
                       ReadColorImage(c.ImagePath(0, 1)),
                       ReadLabelImage(c.root / layout::GtInstances(c.views[0].name, 0)),
                       ReadFlo(c.root / layout::GtFlow(c.views[0].name, 0)),
                       ReadLabelImage(c.root / layout::GtFlowValid(c.views[0].name, 0)),
                       ReadLabelImage(c.root / layout::GtInstances(c.views[0].name, 1))};
  }
  static void TearDownTestSuite() { delete frame_; }

  // Mean end-point error against the GT flow over the people's GT-valid pixels.
  static double PeopleEpe(const cv::Mat& flow) {
    double sum = 0;
    long n = 0;
    for (int y = 0; y < flow.rows; ++y)
      for (int x = 0; x < flow.cols; ++x) {
        if (frame_->labels.at<uint16_t>(y, x) == 0 || frame_->valid.at<uint16_t>(y, x) == 0)
          continue;
        sum += cv::norm(flow.at<cv::Vec2f>(y, x) - frame_->flow.at<cv::Vec2f>(y, x));
        ++n;
      }
    return sum / std::max(1L, n);
  }

  static Frame* frame_;
};

Frame* CameraFlowTest::frame_ = nullptr;

TEST_F(CameraFlowTest, TheCameraSizeMatchReplacesACoarseFlowWhereItKeepsTheBrightness) {
  const Frame& f = *frame_;
  ASSERT_GT(PeopleEpe(cv::Mat::zeros(f.flow.size(), CV_32FC2)), 1.0);  // the people move
  // A working-resolution flow: the truth at a quarter of the size, blurred
  // and upscaled, then off by a pixel (what a coarse solve's error looks like).
  cv::Mat coarse;
  cv::resize(f.flow, coarse, {}, 0.25, 0.25, cv::INTER_AREA);
  cv::resize(coarse, coarse, f.flow.size(), 0, 0, cv::INTER_LINEAR);
  coarse += cv::Scalar(1.0, -0.5);
  const cv::Mat dense =
      baselines::DenseFlow(baselines::DenseFlowMethod::kDisFine, f.image_t, f.image_t1);
  cv::Mat refined = coarse.clone();
  RefineFlowAtCameraSize(f.labels, f.image_t, f.image_t1, 7, &refined);
  const double before = PeopleEpe(coarse), after = PeopleEpe(refined);
  EXPECT_LT(after, 0.6 * before) << before;
  EXPECT_LE(after, PeopleEpe(dense) + 0.05);
  // The background keeps its flow.
  const cv::Mat background = f.labels == 0;
  EXPECT_EQ(cv::norm(refined, coarse, cv::NORM_INF, background), 0);
}

// Given the true flow, the choice keeps enough of it to stay closer to the
// truth than the dense match alone.
TEST_F(CameraFlowTest, TheTrueFlowBeatsTheDenseMatch) {
  const Frame& f = *frame_;
  cv::Mat refined = f.flow.clone();
  RefineFlowAtCameraSize(f.labels, f.image_t, f.image_t1, 7, &refined);
  const double dense =
      PeopleEpe(baselines::DenseFlow(baselines::DenseFlowMethod::kDisFine, f.image_t, f.image_t1));
  EXPECT_LT(PeopleEpe(refined), dense);
}

// Still is still: the same frame twice, each with its own sensor noise, and
// the solve's zero flow; with and without the objects' own matches (the
// same labels at t+1).
TEST_F(CameraFlowTest, TheSameFrameTwiceKeepsNoMotion) {
  const Frame& f = *frame_;
  cv::Mat noise_t(f.image_t.size(), CV_16SC3), noise_t1(f.image_t.size(), CV_16SC3);
  cv::theRNG().state = 11;
  cv::randn(noise_t, 0, 2);
  cv::randn(noise_t1, 0, 2);
  cv::Mat image_t, image_t1;
  cv::add(f.image_t, noise_t, image_t, cv::noArray(), CV_8UC3);
  cv::add(f.image_t, noise_t1, image_t1, cv::noArray(), CV_8UC3);
  for (const cv::Mat& labels_t1 : {cv::Mat(), f.labels}) {
    cv::Mat flow = cv::Mat::zeros(f.flow.size(), CV_32FC2);
    RefineFlowAtCameraSize(f.labels, image_t, image_t1, 7, &flow, labels_t1);
    if (!labels_t1.empty()) {
      FillInconsistentObjectFlow(f.labels, labels_t1, image_t, image_t1, 6, &flow);
      RefineObjectFlowVariationally(f.labels, labels_t1, image_t, image_t1, 20, &flow);
    }
    double sum = 0;
    for (int y = 0; y < flow.rows; ++y)
      for (int x = 0; x < flow.cols; ++x)
        if (f.labels.at<uint16_t>(y, x)) sum += cv::norm(flow.at<cv::Vec2f>(y, x));
    EXPECT_LE(sum / cv::countNonZero(f.labels), 0.05) << "object matches: " << !labels_t1.empty();
  }
}

// An object of one pixel in a corner, and an image too small for the dense
// match: no error, the background keeps its flow and the tiny image keeps
// it everywhere; the variational refinement runs on both without error and
// leaves their background alone.
TEST(CameraFlow, TinyObjectsAndImagesAreHandled) {
  for (const cv::Size size : {cv::Size(64, 36), cv::Size(10, 8)}) {
    cv::Mat image_t(size, CV_8UC3), image_t1(size, CV_8UC3);
    cv::theRNG().state = 5;
    cv::randu(image_t, 0, 255);
    cv::randu(image_t1, 0, 255);
    cv::Mat labels = cv::Mat::zeros(size, CV_16U);
    labels.at<uint16_t>(size.height - 1, size.width - 1) = 1;
    const cv::Mat before(size, CV_32FC2, cv::Scalar(0.5f, -0.5f));
    cv::Mat flow = before.clone();
    ASSERT_NO_THROW(RefineFlowAtCameraSize(labels, image_t, image_t1, 7, &flow)) << size;
    const cv::Mat background = labels == 0;
    EXPECT_EQ(cv::norm(flow, before, cv::NORM_INF, background), 0) << size;
    if (size.width < 16) {
      EXPECT_EQ(cv::norm(flow, before, cv::NORM_INF), 0);
    }
    ASSERT_NO_THROW(RefineObjectFlowVariationally(labels, labels, image_t, image_t1, 20, &flow))
        << size;
    EXPECT_EQ(cv::norm(flow, before, cv::NORM_INF, background), 0) << size;
  }
}

// One view of the realistic world at 960x540 (captured performances),
// frame f -> f + 1, with its true labels at t and t+1 and its true flow, and
// the capture and view it comes from.
struct RealisticView {
  cv::Mat image_t, image_t1, labels, labels_t1, truth, valid;
  const Capture* capture = nullptr;
  int view = 0;
};

// The people errors of several flows against the truth over all views.
struct FlowErrors {
  std::vector<double> epe;
  std::vector<double> far;  // share of the pixels off by more than 10 px
  long n = 0;
};

// `flows_of` gives the same number of flows for each of the 8 views of the
// realistic world (frames 0 to `frame` + 1) written to a temporary folder
// named after `name`, frame `frame` -> `frame` + 1; their errors over the
// GT-valid people pixels, printed in turn.
FlowErrors CompareOnTheRealisticWorld(
    const fs::path& data, const std::string& name,
    const std::function<std::vector<cv::Mat>(const RealisticView&)>& flows_of, int frame = 0) {
  const Capture c = ReadCapture(test_util::RemovedAtExit(
      synth::WriteCaptureToTempDir(name, synth::SmallRealisticOptions(data, 960, 540, frame + 2))));
  FlowErrors errors;
  for (int v = 0; v < c.NumViews(); ++v) {
    const std::string& view = c.views[v].name;
    const RealisticView r{ReadColorImage(c.ImagePath(v, frame)),
                          ReadColorImage(c.ImagePath(v, frame + 1)),
                          ReadLabelImage(c.root / layout::GtInstances(view, frame)),
                          ReadLabelImage(c.root / layout::GtInstances(view, frame + 1)),
                          ReadFlo(c.root / layout::GtFlow(view, frame)),
                          ReadLabelImage(c.root / layout::GtFlowValid(view, frame)),
                          &c,
                          v};
    const std::vector<cv::Mat> flows = flows_of(r);
    errors.epe.resize(flows.size());
    errors.far.resize(flows.size());
    for (int y = 0; y < r.truth.rows; ++y)
      for (int x = 0; x < r.truth.cols; ++x) {
        if (r.labels.at<uint16_t>(y, x) == 0 || r.valid.at<uint16_t>(y, x) == 0) continue;
        ++errors.n;
        for (size_t k = 0; k < flows.size(); ++k) {
          const double e = cv::norm(flows[k].at<cv::Vec2f>(y, x) - r.truth.at<cv::Vec2f>(y, x));
          errors.epe[k] += e;
          errors.far[k] += e > 10;
        }
      }
  }
  for (size_t k = 0; k < errors.epe.size(); ++k) {
    errors.epe[k] /= std::max(1L, errors.n);
    errors.far[k] /= std::max(1L, errors.n);
    std::printf("%speople EPE %.3f px, off by > 10 px %.2f%%", k ? " -> " : "", errors.epe[k],
                100 * errors.far[k]);
  }
  std::printf("\n");
  return errors;
}

// The realistic world, with a solve that found no motion: a striped
// performer overlaps another who moves the other way, and the whole image's
// match gives the stripes (one stripe over) and the dark trousers the
// other's motion. Each object's own match, with the other greyed out at t
// and at t+1 (the true labels), keeps to the object's motion: fewer people
// pixels off by more than 10 px, and a lower error, against the ground
// truth.
TEST(CameraFlow, EachObjectsOwnMatchIsNotDraggedByItsNeighbour) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  const FlowErrors e =
      CompareOnTheRealisticWorld(data, "camera_flow_objects", [](const RealisticView& r) {
        std::vector<cv::Mat> flows = {cv::Mat::zeros(r.truth.size(), CV_32FC2),
                                      cv::Mat::zeros(r.truth.size(), CV_32FC2)};
        RefineFlowAtCameraSize(r.labels, r.image_t, r.image_t1, 7, &flows[0]);
        RefineFlowAtCameraSize(r.labels, r.image_t, r.image_t1, 7, &flows[1], r.labels_t1);
        return flows;
      });
  ASSERT_GT(e.n, 10000);
  EXPECT_LT(e.far[1], 0.75 * e.far[0]);
  EXPECT_LT(e.epe[1], e.epe[0]);
}

// The same world and frames, the pipeline's chain at camera size on the
// true labels at t and t+1 (the pick with the objects' own matches, then
// the median over 11 px, the solve's 5 working pixels). The
// forward-backward fill (radius 12 px, 6 working pixels) then leaves fewer
// people pixels off by more than 10 px and a lower error against the ground
// truth; its errors are where a limb passes behind the other performer or
// where weak texture misled every candidate. The variational refinement
// (20 fixed-point iterations) after it lowers the error again and adds no
// gross errors; where every candidate was wrong together it cannot help,
// its data term only sees a pixel's neighbourhood.
TEST(CameraFlow, TheFillAndTheVariationalRefinementLowerTheRealisticWorldsError) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  const FlowErrors e =
      CompareOnTheRealisticWorld(data, "camera_flow_fill", [](const RealisticView& r) {
        std::vector<cv::Mat> flows = {cv::Mat::zeros(r.truth.size(), CV_32FC2)};
        RefineFlowAtCameraSize(r.labels, r.image_t, r.image_t1, 7, &flows[0], r.labels_t1);
        MedianFilterObjectFlow(r.labels, 11, &flows[0]);
        flows.push_back(flows[0].clone());
        FillInconsistentObjectFlow(r.labels, r.labels_t1, r.image_t, r.image_t1, 12, &flows[1]);
        flows.push_back(flows[1].clone());
        RefineObjectFlowVariationally(r.labels, r.labels_t1, r.image_t, r.image_t1, 20, &flows[2]);
        return flows;
      });
  ASSERT_GT(e.n, 10000);
  EXPECT_LT(e.far[1], e.far[0]);
  EXPECT_LT(e.epe[1], e.epe[0]);
  EXPECT_LT(e.epe[2], e.epe[1]);
  EXPECT_LE(e.far[2], e.far[1]);
}

// The pipeline's chain at camera size on view `v` of capture `c`, frame f ->
// f + 1, from a solve that found no motion, with the true labels and the
// candidate `carried` (empty = none).
cv::Mat CameraSizeChain(const Capture& c, int v, int f, const cv::Mat& carried) {
  const std::string& view = c.views[v].name;
  const cv::Mat image_t = ReadColorImage(c.ImagePath(v, f)),
                image_t1 = ReadColorImage(c.ImagePath(v, f + 1));
  const cv::Mat labels = ReadLabelImage(c.root / layout::GtInstances(view, f)),
                labels_t1 = ReadLabelImage(c.root / layout::GtInstances(view, f + 1));
  cv::Mat flow = cv::Mat::zeros(labels.size(), CV_32FC2);
  RefineFlowAtCameraSize(labels, image_t, image_t1, 7, &flow, labels_t1, carried);
  MedianFilterObjectFlow(labels, 11, &flow);
  FillInconsistentObjectFlow(labels, labels_t1, image_t, image_t1, 12, &flow);
  RefineObjectFlowVariationally(labels, labels_t1, image_t, image_t1, 20, &flow);
  return flow;
}

// The realistic world's frames 0 -> 1 -> 2: the chain's own flow of frame
// 0 (not the truth), carried forward to frame 1 as a candidate of the pick,
// lowers frame 1's error against the ground truth and its share of pixels
// off by more than 10 px: the fast limbs keep their motion.
TEST(CameraFlow, TheFrameBeforesFlowCarriedForwardLowersTheRealisticWorldsError) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  const FlowErrors e = CompareOnTheRealisticWorld(
      data, "camera_flow_carried",
      [](const RealisticView& r) {
        const cv::Mat labels_0 =
            ReadLabelImage(r.capture->root / layout::GtInstances(r.capture->views[r.view].name, 0));
        const cv::Mat carried =
            CarriedObjectFlow(labels_0, CameraSizeChain(*r.capture, r.view, 0, {}), r.labels,
                              cv::Mat::zeros(r.labels.size(), CV_32FC2));
        return std::vector<cv::Mat>{CameraSizeChain(*r.capture, r.view, 1, {}),
                                    CameraSizeChain(*r.capture, r.view, 1, carried)};
      },
      1);
  ASSERT_GT(e.n, 10000);
  EXPECT_LT(e.epe[1], e.epe[0]);
  EXPECT_LT(e.far[1], e.far[0]);
}

// A square of object 1 that moves by (6, -3) pixels per frame, and object 2
// still beside it where the square's right part lands: the square's flow of
// the frame before, carried forward, gives its pixels at t the same motion
// where it lands on object 1; where it lands on object 2 and everywhere
// else the field keeps the flow given.
TEST(CameraFlow, TheCarriedFlowKeepsEachObjectsVelocity) {
  const cv::Size size(64, 48);
  const cv::Vec2f motion(6, -3);
  cv::Mat labels_prev = cv::Mat::zeros(size, CV_16U), labels = cv::Mat::zeros(size, CV_16U);
  labels_prev(cv::Rect(10, 20, 16, 16)).setTo(1);
  labels(cv::Rect(16, 17, 16, 16)).setTo(1);
  labels(cv::Rect(28, 17, 4, 16)).setTo(2);  // covers the square's right part at t
  cv::Mat flow_prev(size, CV_32FC2, cv::Scalar(0, 0));
  flow_prev.setTo(cv::Scalar(motion[0], motion[1]), labels_prev == 1);
  const cv::Mat given(size, CV_32FC2, cv::Scalar(0.5, 0.25));
  const cv::Mat carried = CarriedObjectFlow(labels_prev, flow_prev, labels, given);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const cv::Vec2f expected =
          labels.at<uint16_t>(y, x) == 1 ? motion : given.at<cv::Vec2f>(y, x);
      EXPECT_EQ(carried.at<cv::Vec2f>(y, x), expected) << x << ", " << y;
    }
  EXPECT_THROW(CarriedObjectFlow(labels_prev, flow_prev, labels(cv::Rect(0, 0, 32, 32)), given),
               Error);
  cv::Mat wrong;
  labels.convertTo(wrong, CV_32F);
  EXPECT_THROW(CarriedObjectFlow(labels_prev, flow_prev, wrong, given), Error);
}

// The handshake's true flow, off by a smooth sub-pixel field on the people
// (what the picks leave: whole-pixel-right candidates, a median and a fill
// that copy their neighbours): the refinement removes more than a quarter
// of the error (the data term is weak where the texture is), started from
// the truth it stays within 0.1 px of it, the background keeps its flow,
// and without the objects at t+1 nothing changes.
TEST_F(CameraFlowTest, TheVariationalRefinementFindsTheSubPixelMotion) {
  const Frame& f = *frame_;
  cv::Mat off = f.flow.clone();
  for (int y = 0; y < off.rows; ++y)
    for (int x = 0; x < off.cols; ++x)
      if (f.labels.at<uint16_t>(y, x))
        off.at<cv::Vec2f>(y, x) += cv::Vec2f(0.6f * std::cos(x / 20.0), 0.6f * std::sin(y / 20.0));
  cv::Mat refined = off.clone();
  RefineObjectFlowVariationally(f.labels, f.labels_t1, f.image_t, f.image_t1, 20, &refined);
  cv::Mat from_truth = f.flow.clone();
  RefineObjectFlowVariationally(f.labels, f.labels_t1, f.image_t, f.image_t1, 20, &from_truth);
  const double before = PeopleEpe(off), after = PeopleEpe(refined);
  std::printf("people EPE %.3f -> %.3f px (from the truth: %.3f px)\n", before, after,
              PeopleEpe(from_truth));
  EXPECT_LT(after, 0.75 * before);
  EXPECT_LT(PeopleEpe(from_truth), 0.1);
  const cv::Mat background = f.labels == 0;
  EXPECT_EQ(cv::norm(refined, off, cv::NORM_INF, background), 0);
  cv::Mat unchanged = off.clone();
  RefineObjectFlowVariationally(f.labels, cv::Mat(), f.image_t, f.image_t1, 20, &unchanged);
  EXPECT_EQ(cv::norm(unchanged, off, cv::NORM_INF), 0);
}

// Two objects side by side moving differently, each pixel's flow off at
// random by up to 40 px at 3 % of the pixels: the median gives every object
// pixel its object's motion back, at the boundaries too (the other object's
// and the background's pixels do not vote), and the background keeps its
// flow.
TEST(CameraFlow, TheObjectMedianRemovesOutliersInsideTheObjects) {
  cv::Mat labels = cv::Mat::zeros(60, 80, CV_16U);
  labels(cv::Rect(10, 10, 30, 40)).setTo(1);
  labels(cv::Rect(40, 10, 30, 40)).setTo(2);
  const cv::Vec2f motion[3] = {{0.5f, -0.5f}, {3, 1}, {-6, 2}};
  cv::Mat flow(labels.size(), CV_32FC2);
  cv::RNG rng(3);
  int outliers = 0;
  for (int y = 0; y < flow.rows; ++y)
    for (int x = 0; x < flow.cols; ++x) {
      cv::Vec2f f = motion[labels.at<uint16_t>(y, x)];
      if (labels.at<uint16_t>(y, x) && rng.uniform(0.0, 1.0) < 0.03) {
        f += cv::Vec2f(rng.uniform(-40.f, 40.f), rng.uniform(-40.f, 40.f));
        ++outliers;
      }
      flow.at<cv::Vec2f>(y, x) = f;
    }
  ASSERT_GT(outliers, 40);
  const cv::Mat before = flow.clone();
  MedianFilterObjectFlow(labels, 7, &flow);
  for (int y = 0; y < flow.rows; ++y)
    for (int x = 0; x < flow.cols; ++x) {
      const int id = labels.at<uint16_t>(y, x);
      const cv::Vec2f want = id ? motion[id] : before.at<cv::Vec2f>(y, x);
      ASSERT_EQ(flow.at<cv::Vec2f>(y, x), want) << "at (" << x << ", " << y << ")";
    }
  EXPECT_THROW(MedianFilterObjectFlow(labels, 4, &flow), Error);
  cv::Mat wrong = cv::Mat::zeros(30, 40, CV_32FC2);
  EXPECT_THROW(MedianFilterObjectFlow(labels, 7, &wrong), Error);
}

// On the handshake's people (480x270), the true flow with 2 % of its pixels
// off by up to 30 px: the median brings the error down to a fraction, inside
// the people and within its window of their boundaries alike.
TEST_F(CameraFlowTest, TheObjectMedianBringsAnOutlierFieldBackToTheTruth) {
  const Frame& f = *frame_;
  cv::Mat noisy = f.flow.clone();
  cv::RNG rng(5);
  for (int y = 0; y < noisy.rows; ++y)
    for (int x = 0; x < noisy.cols; ++x)
      if (f.labels.at<uint16_t>(y, x) && rng.uniform(0.0, 1.0) < 0.02)
        noisy.at<cv::Vec2f>(y, x) += cv::Vec2f(rng.uniform(-30.f, 30.f), rng.uniform(-30.f, 30.f));
  cv::Mat filtered = noisy.clone();
  MedianFilterObjectFlow(f.labels, 5, &filtered);
  double before[2] = {0, 0}, after[2] = {0, 0};  // [0] inside, [1] near a boundary
  long n[2] = {0, 0};
  for (int y = 2; y + 2 < f.labels.rows; ++y)
    for (int x = 2; x + 2 < f.labels.cols; ++x) {
      const uint16_t id = f.labels.at<uint16_t>(y, x);
      if (id == 0 || f.valid.at<uint16_t>(y, x) == 0) continue;
      const int k = cv::countNonZero(f.labels(cv::Rect(x - 2, y - 2, 5, 5)) != id) > 0 ? 1 : 0;
      before[k] += cv::norm(noisy.at<cv::Vec2f>(y, x) - f.flow.at<cv::Vec2f>(y, x));
      after[k] += cv::norm(filtered.at<cv::Vec2f>(y, x) - f.flow.at<cv::Vec2f>(y, x));
      ++n[k];
    }
  for (int k = 0; k < 2; ++k) {
    ASSERT_GT(n[k], 300) << k;
    EXPECT_GT(before[k] / n[k], 0.2) << k;
    EXPECT_LT(after[k], 0.2 * before[k]) << k << ": " << before[k] / n[k] << " px";
  }
}

// On the handshake's people (480x270), the true flow with three 13x13
// patches off by (6, -4) px deep inside them: too large for a median, and
// each patch's match still lands on its person at t+1. The backward match
// does not lead back there, and the fill brings the patches back near the
// truth while the rest keeps its error.
TEST_F(CameraFlowTest, TheForwardBackwardFillRestoresWrongPatches) {
  const Frame& f = *frame_;
  cv::Mat inside;
  cv::distanceTransform(f.labels > 0, inside, cv::DIST_L2, 5);
  std::vector<cv::Point> centres;
  for (int y = 0; y < inside.rows && centres.size() < 3; ++y)
    for (int x = 0; x < inside.cols && centres.size() < 3; ++x) {
      if (inside.at<float>(y, x) < 10) continue;
      bool apart = true;
      for (const cv::Point& c : centres) apart = apart && cv::norm(c - cv::Point(x, y)) > 30;
      if (apart) centres.emplace_back(x, y);
    }
  ASSERT_EQ(centres.size(), 3u);
  cv::Mat wrong = f.flow.clone(), patches = cv::Mat::zeros(f.flow.size(), CV_8U);
  for (const cv::Point& c : centres) {
    const cv::Rect patch(c.x - 6, c.y - 6, 13, 13);
    wrong(patch) += cv::Scalar(6, -4);
    patches(patch).setTo(255);
  }
  cv::Mat filled = wrong.clone();
  FillInconsistentObjectFlow(f.labels, f.labels_t1, f.image_t, f.image_t1, 6, &filled);
  double before[2] = {0, 0}, after[2] = {0, 0};  // [0] the patches, [1] the rest
  long n[2] = {0, 0};
  for (int y = 0; y < f.labels.rows; ++y)
    for (int x = 0; x < f.labels.cols; ++x) {
      if (f.labels.at<uint16_t>(y, x) == 0 || f.valid.at<uint16_t>(y, x) == 0) continue;
      const int k = patches.at<uint8_t>(y, x) ? 0 : 1;
      before[k] += cv::norm(wrong.at<cv::Vec2f>(y, x) - f.flow.at<cv::Vec2f>(y, x));
      after[k] += cv::norm(filled.at<cv::Vec2f>(y, x) - f.flow.at<cv::Vec2f>(y, x));
      ++n[k];
    }
  ASSERT_GT(n[0], 300);
  std::printf("patches %.3f -> %.3f px, the rest %.3f -> %.3f px\n", before[0] / n[0],
              after[0] / n[0], before[1] / n[1], after[1] / n[1]);
  EXPECT_LT(after[0], 0.2 * before[0]);
  EXPECT_LT(after[1] / n[1], before[1] / n[1] + 0.05);
  const cv::Mat background = f.labels == 0;
  EXPECT_EQ(cv::norm(filled, wrong, cv::NORM_INF, background), 0);
  // No objects known at t+1: nothing to check against, the flow stays.
  cv::Mat unchecked = wrong.clone();
  FillInconsistentObjectFlow(f.labels, cv::Mat(), f.image_t, f.image_t1, 6, &unchecked);
  EXPECT_EQ(cv::norm(unchecked, wrong, cv::NORM_INF), 0);
}

TEST_F(CameraFlowTest, BadInputThrows) {
  const Frame& f = *frame_;
  cv::Mat flow = f.flow.clone();
  EXPECT_THROW(RefineFlowAtCameraSize(f.labels, f.image_t, f.image_t1, 6, &flow), Error);
  cv::Mat small;
  cv::resize(f.image_t1, small, {}, 0.5, 0.5);
  EXPECT_THROW(RefineFlowAtCameraSize(f.labels, f.image_t, small, 7, &flow), Error);
  cv::Mat grey;
  cv::cvtColor(f.image_t, grey, cv::COLOR_BGR2GRAY);
  EXPECT_THROW(RefineFlowAtCameraSize(f.labels, grey, f.image_t1, 7, &flow), Error);
  cv::Mat labels_t1;
  cv::resize(f.labels, labels_t1, {}, 0.5, 0.5, cv::INTER_NEAREST);
  EXPECT_THROW(RefineFlowAtCameraSize(f.labels, f.image_t, f.image_t1, 7, &flow, labels_t1), Error);
  f.labels.convertTo(labels_t1, CV_32F);
  EXPECT_THROW(RefineFlowAtCameraSize(f.labels, f.image_t, f.image_t1, 7, &flow, labels_t1), Error);
  EXPECT_THROW(FillInconsistentObjectFlow(f.labels, labels_t1, f.image_t, f.image_t1, 6, &flow),
               Error);
  EXPECT_THROW(FillInconsistentObjectFlow(f.labels, f.labels, f.image_t, f.image_t1, 0, &flow),
               Error);
  EXPECT_THROW(FillInconsistentObjectFlow(f.labels, f.labels, f.image_t, small, 6, &flow), Error);
  EXPECT_THROW(RefineObjectFlowVariationally(f.labels, labels_t1, f.image_t, f.image_t1, 20, &flow),
               Error);
  EXPECT_THROW(RefineObjectFlowVariationally(f.labels, f.labels, f.image_t, f.image_t1, 0, &flow),
               Error);
  EXPECT_THROW(RefineObjectFlowVariationally(f.labels, f.labels, f.image_t, small, 20, &flow),
               Error);
}

}  // namespace
}  // namespace u4d
