#include "u4d/pipeline/camera_flow.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/imgproc.hpp>

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
  cv::Mat image_t, image_t1, labels, flow, valid;
};

class CameraFlowTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    synth::SynthOptions o = synth::SmallHandshakeOptions(2, 480, 270, 2);
    o.start_frame = 128;
    const Capture c = ReadCapture(synth::WriteCaptureToTempDir("camera_flow_test", o));
    frame_ = new Frame{ReadColorImage(c.ImagePath(0, 0)), ReadColorImage(c.ImagePath(0, 1)),
                       ReadLabelImage(c.root / layout::GtInstances(c.views[0].name, 0)),
                       ReadFlo(c.root / layout::GtFlow(c.views[0].name, 0)),
                       ReadLabelImage(c.root / layout::GtFlowValid(c.views[0].name, 0))};
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
    double sum = 0;
    for (int y = 0; y < flow.rows; ++y)
      for (int x = 0; x < flow.cols; ++x)
        if (f.labels.at<uint16_t>(y, x)) sum += cv::norm(flow.at<cv::Vec2f>(y, x));
    EXPECT_LE(sum / cv::countNonZero(f.labels), 0.05) << "object matches: " << !labels_t1.empty();
  }
}

// An object of one pixel in a corner, and an image too small for the dense
// match: no error, and the tiny image keeps its flow.
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
  }
}

// The realistic world at 960x540 (captured performances), frame 0 -> 1 of
// all 8 views, with a solve that found no motion: a striped performer
// overlaps another who moves the other way, and the whole image's match
// gives the stripes (one stripe over) and the dark trousers the other's
// motion. Each object's own match, with the other greyed out at t and at
// t+1 (the true labels), keeps to the object's motion: fewer people pixels
// off by more than 10 px, and a lower error, against the ground truth.
TEST(CameraFlow, EachObjectsOwnMatchIsNotDraggedByItsNeighbour) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  const Capture c = ReadCapture(synth::WriteCaptureToTempDir(
      "camera_flow_objects", synth::SmallRealisticOptions(data, 960, 540, 2)));
  double sum[2] = {0, 0};
  long far[2] = {0, 0}, n = 0;
  for (int v = 0; v < c.NumViews(); ++v) {
    const std::string& name = c.views[v].name;
    const cv::Mat image_t = ReadColorImage(c.ImagePath(v, 0)),
                  image_t1 = ReadColorImage(c.ImagePath(v, 1));
    const cv::Mat labels = ReadLabelImage(c.root / layout::GtInstances(name, 0)),
                  labels_t1 = ReadLabelImage(c.root / layout::GtInstances(name, 1));
    const cv::Mat truth = ReadFlo(c.root / layout::GtFlow(name, 0)),
                  valid = ReadLabelImage(c.root / layout::GtFlowValid(name, 0));
    cv::Mat flows[2] = {cv::Mat::zeros(truth.size(), CV_32FC2),
                        cv::Mat::zeros(truth.size(), CV_32FC2)};
    RefineFlowAtCameraSize(labels, image_t, image_t1, 7, &flows[0]);
    RefineFlowAtCameraSize(labels, image_t, image_t1, 7, &flows[1], labels_t1);
    for (int y = 0; y < truth.rows; ++y)
      for (int x = 0; x < truth.cols; ++x) {
        if (labels.at<uint16_t>(y, x) == 0 || valid.at<uint16_t>(y, x) == 0) continue;
        ++n;
        for (int k = 0; k < 2; ++k) {
          const double e = cv::norm(flows[k].at<cv::Vec2f>(y, x) - truth.at<cv::Vec2f>(y, x));
          sum[k] += e;
          far[k] += e > 10;
        }
      }
  }
  ASSERT_GT(n, 10000);
  const double epe[2] = {sum[0] / n, sum[1] / n};
  const double share[2] = {double(far[0]) / n, double(far[1]) / n};
  std::printf("people EPE %.3f -> %.3f px, off by > 10 px %.2f%% -> %.2f%%\n", epe[0], epe[1],
              100 * share[0], 100 * share[1]);
  EXPECT_LT(share[1], 0.75 * share[0]);
  EXPECT_LT(epe[1], epe[0]);
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
}

}  // namespace
}  // namespace u4d
