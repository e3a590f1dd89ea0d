// FitColorGmm (label_costs.h): the EM written out in label_costs.cc must give
// the fit of cv::ml::EM, the implementation it replaced (same algorithm, same
// initialisation), and recover a known mixture.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/ml.hpp>

#include "u4d/joint/label_costs.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

// 3000 BGR samples from three well separated Gaussian colour blobs (the ground truth).
std::vector<cv::Vec3b> Samples(std::vector<Eigen::Vector3d>* true_means) {
  *true_means = {{40, 60, 200}, {200, 180, 30}, {120, 120, 120}};
  const double sigma[3] = {6, 9, 4};
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, 1);
  std::vector<cv::Vec3b> s;
  for (int i = 0; i < 3000; ++i) {
    const int c = i % 3;
    cv::Vec3b v;
    for (int k = 0; k < 3; ++k)
      v[k] = cv::saturate_cast<uint8_t>((*true_means)[c][k] + sigma[c] * n(rng));
    s.push_back(v);
  }
  return s;
}

TEST(FitColorGmmTest, EqualsOpenCvEmAndRecoversTheMixture) {
  std::vector<Eigen::Vector3d> truth;
  const std::vector<cv::Vec3b> samples = Samples(&truth);
  const int k = 3;
  const uint64_t seed = 7;
  const ColorGmm gmm = FitColorGmm(samples, k, seed);
  ASSERT_EQ(gmm.weights.size(), 3u);

  cv::Mat data(static_cast<int>(samples.size()), 3, CV_64F);
  for (int i = 0; i < data.rows; ++i)
    for (int c = 0; c < 3; ++c) data.at<double>(i, c) = samples[i][c];
  cv::theRNG() = cv::RNG(seed);
  cv::Ptr<cv::ml::EM> em = cv::ml::EM::create();
  em->setClustersNumber(k);
  em->setCovarianceMatrixType(cv::ml::EM::COV_MAT_GENERIC);
  em->setTermCriteria(cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30, 1e-3));
  ASSERT_TRUE(em->trainEM(data));
  const cv::Mat means = em->getMeans(), weights = em->getWeights();
  for (int i = 0; i < k; ++i) {
    // Same algorithm and initialisation: equal up to floating-point rounding.
    EXPECT_NEAR(gmm.weights[i], weights.at<double>(0, i), 1e-9) << "component " << i;
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(gmm.means[i][c], means.at<double>(i, c), 1e-7) << "component " << i;
    // Ground truth: each blob found, its mean within 1 grey level (1000 samples,
    // sigma <= 9: the standard error is < 0.3).
    double best = 1e9;
    for (const Eigen::Vector3d& t : truth) best = std::min(best, (gmm.means[i] - t).norm());
    EXPECT_LT(best, 1.0) << "component " << i;
    EXPECT_NEAR(gmm.weights[i], 1.0 / 3, 0.01) << "component " << i;
  }
}

// E_sem over ψ_T (SemanticCosts of several maps): three masks of one true
// disc, each wrong in its own sector (dilated, eroded, dilated by 5 px), as a
// detector's independent per-frame boundary errors. The label preferred by
// the combined P_sem (median signed distance) must be the truth wherever at
// most one map errs (here everywhere), while the single-map E_sem copies the
// reference map's error.
TEST(SemanticCostsTest, CombinedMapsOutvoteOneMapsError) {
  const int w = 160, h = 120, cx = 80, cy = 60;
  const double radius = 30, err = 5;
  // The disc with its radius changed by `delta` in the sector of angles [a0, a1) (degrees).
  const auto disc = [&](double delta, double a0, double a1) {
    cv::Mat m = cv::Mat::zeros(h, w, CV_16U);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        double a = std::atan2(y - cy, x - cx) * 180 / 3.14159265358979;
        if (a < -45) a += 360;  // angles in [-45, 315)
        const double r = radius + (a >= a0 && a < a1 ? delta : 0.0);
        if (std::hypot(x - cx, y - cy) <= r) m.at<uint16_t>(y, x) = 1;
      }
    return m;
  };
  const cv::Mat truth = disc(0, 0, 0);
  const std::vector<cv::Mat> maps = {disc(err, -45, 45), disc(-err, 135, 225), disc(err, 225, 315)};
  const auto errors = [&](const LabelCostVolume& v) {
    int wrong = 0;
    for (int p = 0; p < w * h; ++p) {
      const int best = v.At(p, 1) < v.At(p, 0) ? 1 : 0;
      wrong += best != truth.ptr<uint16_t>()[p];
    }
    return wrong;
  };
  const int single = errors(SemanticCosts(maps[0], 2));
  const int combined = errors(SemanticCosts(maps, 2));
  // The reference map's dilated sector: a quarter of the annulus between r and r + 5.
  const double sector =
      0.25 * 3.14159265358979 * ((radius + err) * (radius + err) - radius * radius);
  EXPECT_GT(single, 0.8 * sector);
  // Only pixels on the true boundary can still go either way (rounding of the
  // discrete distances): far fewer than one map's error.
  EXPECT_LT(combined, 0.1 * single);
  std::printf("wrong pixels: single map %d, three maps %d (sector %.0f)\n", single, combined,
              sector);
  EXPECT_THROW(SemanticCosts(std::vector<cv::Mat>{}, 2), Error);
  EXPECT_THROW(SemanticCosts(std::vector<cv::Mat>{truth, cv::Mat::zeros(10, 10, CV_16U)}, 2),
               Error);
}

// A detector's score is the probability of its mask (SemanticCosts'
// label_scores): scores of 1 give the hard masks' E_sem exactly; a score of 0
// leaves no preference among the labels inside its mask; in between, the
// background's cost inside a mask falls as the score falls, and nothing
// changes outside the masks. Deep inside a mask of score s among L labels,
// P_sem(l) is proportional to min_probability + [l is the mask's] s + (1 − s) / L.
TEST(SemanticCostsTest, ADetectionsScoreIsItsProbability) {
  const int w = 140, h = 80;
  cv::Mat labels = cv::Mat::zeros(h, w, CV_16U);
  labels(cv::Rect(5, 5, 40, 50)).setTo(1);   // a person, high score
  labels(cv::Rect(55, 5, 40, 50)).setTo(2);  // a doubtful detection
  const LabelCostOptions options;
  const LabelCostVolume hard = SemanticCosts(labels, 3, options);
  const LabelCostVolume ones = SemanticCosts(labels, 3, options, {1.0, 1.0, 1.0});
  EXPECT_EQ(ones.cost, hard.cost);
  const int inside1 = 30 * w + 25, inside2 = 30 * w + 75, outside = 75 * w + 130;
  const double eps = options.min_probability, norm = -std::log(eps);
  const auto background_cost = [&](double s) {  // deep inside a mask of score s, 3 labels
    const double doubt = (1 - s) / 3;
    return std::min(1.0, std::log((eps + s + doubt) / (eps + doubt)) / norm);
  };
  for (const double s : {0.9, 0.6, 0.3}) {
    const LabelCostVolume v = SemanticCosts(labels, 3, options, {1.0, 1.0, s});
    EXPECT_NEAR(v.At(inside2, 0), background_cost(s), 1e-3) << "score " << s;
    EXPECT_EQ(v.At(inside2, 2), 0.f) << "the mask's own label stays the best";
    EXPECT_NEAR(v.At(inside1, 0), hard.At(inside1, 0), 1e-3) << "the other mask keeps its cost";
    EXPECT_NEAR(v.At(outside, 2), hard.At(outside, 2), 1e-3) << "outside the masks";
  }
  EXPECT_GT(SemanticCosts(labels, 3, options, {1.0, 1.0, 0.9}).At(inside2, 0),
            SemanticCosts(labels, 3, options, {1.0, 1.0, 0.6}).At(inside2, 0));
  const LabelCostVolume none = SemanticCosts(labels, 3, options, {1.0, 1.0, 0.0});
  for (int l = 0; l < 3; ++l) EXPECT_NEAR(none.At(inside2, l), 0.f, 1e-3) << "label " << l;
  EXPECT_THROW(SemanticCosts(labels, 3, options, {1.0, 1.0, 1.5}), Error);
  EXPECT_THROW(SemanticCosts(labels, 3, options, {1.0, -0.1}), Error);
}

// A label's score in a view is the mean detector score over its pixels.
TEST(LabelScoresTest, TheMeanScoreOverEachLabelsPixels) {
  cv::Mat labels = cv::Mat::zeros(4, 6, CV_16U), scores(4, 6, CV_32F, cv::Scalar(1));
  labels.colRange(0, 3).setTo(1);  // label 1: half at 0.5, half at 0.9
  scores(cv::Rect(0, 0, 3, 2)).setTo(0.5);
  scores(cv::Rect(0, 2, 3, 2)).setTo(0.9);
  labels.colRange(4, 6).setTo(3);  // label 3 at 0.2
  scores.colRange(4, 6).setTo(0.2);
  const std::vector<double> s = LabelScores(labels, scores, 4);
  ASSERT_EQ(s.size(), 4u);
  EXPECT_EQ(s[0], 1.0);  // the background
  EXPECT_NEAR(s[1], 0.7, 1e-6);
  EXPECT_EQ(s[2], 1.0);  // no pixel
  EXPECT_NEAR(s[3], 0.2, 1e-6);
  EXPECT_EQ(LabelScores(labels, cv::Mat(), 4), std::vector<double>(4, 1.0));
  EXPECT_THROW(LabelScores(labels, cv::Mat(3, 6, CV_32F), 4), Error);
}

// E_a on a two-colour image with known labels: the true label is the cheaper
// one; limited to `where`, the costs there are the same and elsewhere 0.
TEST(AppearanceCostsTest, FavoursTheTrueLabelAndEvaluatesOnlyWhereAsked) {
  const int w = 80, h = 60;
  cv::Mat image(h, w, CV_8UC3), truth(h, w, CV_16U, cv::Scalar(0));
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0, 5);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool person = x >= 20 && x < 50 && y >= 10 && y < 50;
      truth.at<uint16_t>(y, x) = person ? 1 : 0;
      const cv::Vec3d mean = person ? cv::Vec3d(40, 60, 200) : cv::Vec3d(190, 170, 60);
      for (int k = 0; k < 3; ++k)
        image.at<cv::Vec3b>(y, x)[k] = cv::saturate_cast<uint8_t>(mean[k] + n(rng));
    }
  const std::vector<LabelledImage> training{{image, truth}};
  const LabelCostVolume all = AppearanceCosts(image, training, 2, {});
  int right = 0;
  for (int p = 0; p < w * h; ++p) {
    const int l = truth.ptr<uint16_t>()[p];
    right += all.At(p, l) < all.At(p, 1 - l);
  }
  EXPECT_GT(right, 0.99 * w * h);

  cv::Mat where = cv::Mat::zeros(h, w, CV_8U);
  where(cv::Rect(10, 5, 30, 20)).setTo(1);
  const LabelCostVolume part = AppearanceCosts(image, training, 2, {}, {}, where);
  for (int p = 0; p < w * h; ++p)
    for (int l = 0; l < 2; ++l) {
      if (where.ptr<uint8_t>()[p])
        ASSERT_EQ(part.At(p, l), all.At(p, l)) << "pixel " << p;
      else
        ASSERT_EQ(part.At(p, l), 0.f) << "pixel " << p;
    }
  EXPECT_THROW(AppearanceCosts(image, training, 2, {}, {}, cv::Mat::zeros(h, w + 1, CV_8U)), Error);
  EXPECT_THROW(AppearanceCosts(image, training, 2, {}, {}, cv::Mat::zeros(h, w, CV_32F)), Error);
}

// A constructed scene whose truth is known: two people on a floor of light
// and green tiles in front of a mottled wall. One wears a shirt of the light
// tiles' colour and dark trousers, the other a blue shirt and tan trousers.
// Returns the image and its true labels; `shirt` and `tiles` receive the
// light shirt's and the light tiles' pixels.
void PeopleOnTiles(cv::Mat* image, cv::Mat* truth, cv::Mat* shirt, cv::Mat* tiles) {
  const int w = 140, h = 120;
  *image = cv::Mat(h, w, CV_8UC3);
  *truth = cv::Mat(h, w, CV_16U, cv::Scalar(0));
  *shirt = cv::Mat(h, w, CV_8U, cv::Scalar(0));
  *tiles = cv::Mat(h, w, CV_8U, cv::Scalar(0));
  const cv::Vec3d light(205, 205, 200);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, 5);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool light_tile = y >= 70 && (x / 10 + y / 10) % 2 == 1;
      cv::Vec3d c = y < 70
                        ? ((x / 7 + y / 5) % 2 ? cv::Vec3d(150, 90, 60) : cv::Vec3d(120, 100, 90))
                    : light_tile ? light
                                 : cv::Vec3d(90, 130, 60);
      int id = 0;
      if (x >= 30 && x < 52 && y >= 10 && y < 110) {
        id = 1;
        c = y < 65 ? light : cv::Vec3d(60, 55, 50);
      } else if (x >= 90 && x < 112 && y >= 14 && y < 110) {
        id = 2;
        c = y < 65 ? cv::Vec3d(200, 120, 40) : cv::Vec3d(140, 170, 190);
      }
      truth->at<uint16_t>(y, x) = static_cast<uint16_t>(id);
      if (id == 1 && y < 65) shirt->at<uint8_t>(y, x) = 255;
      if (id == 0 && light_tile) tiles->at<uint8_t>(y, x) = 255;
      for (int k = 0; k < 3; ++k)
        image->at<cv::Vec3b>(y, x)[k] = cv::saturate_cast<uint8_t>(c[k] + noise(rng));
    }
}

// Band models (LabelCostOptions::colour_bands): a colour that a person
// wears high and the background holds low (a light shirt, light floor
// tiles; a white shoe on white tiles is the same at other heights) is
// common in both of the whole models, and they give it to one label at
// both places. The band models must put it on the person at the shirt and
// on the background at the tiles.
TEST(AppearanceCostsTest, BandModelsTellAColourWornHighFromTheSameColourOnTheFloor) {
  cv::Mat image, truth, shirt, tiles;
  PeopleOnTiles(&image, &truth, &shirt, &tiles);
  const std::vector<LabelledImage> training{{image, truth}};
  // Share of the pixels in `where` at which the true label is the cheapest alone.
  auto right = [&](int bands, const cv::Mat& where) {
    LabelCostOptions options;
    options.colour_bands = bands;
    const LabelCostVolume e = AppearanceCosts(image, training, 3, {}, options);
    int n = 0, r = 0;
    for (int p = 0; p < image.cols * image.rows; ++p) {
      if (!where.ptr<uint8_t>()[p]) continue;
      const int l = truth.ptr<uint16_t>()[p];
      bool cheapest = true;
      for (int k = 0; k < 3; ++k) cheapest = cheapest && (k == l || e.At(p, l) < e.At(p, k));
      r += cheapest, ++n;
    }
    return static_cast<double>(r) / n;
  };
  const cv::Mat all(image.size(), CV_8U, cv::Scalar(255));
  std::printf(
      "true label cheapest: shirt %.3f / %.3f, light tiles %.3f / %.3f, image %.4f / "
      "%.4f (4 bands / 1)\n",
      right(4, shirt), right(1, shirt), right(4, tiles), right(1, tiles), right(4, all),
      right(1, all));
  // One model per label gives the light tiles to the person; the bands give
  // most of them to the background (not all: the band that holds the shirt's
  // lower half also holds the tiles' upper rows) and keep the shirt.
  EXPECT_LT(right(1, tiles), 0.5);
  EXPECT_GT(right(4, tiles), 0.5);
  EXPECT_GT(right(4, shirt), 0.95);
  EXPECT_GT(right(4, all), right(1, all));
  LabelCostOptions bad;
  bad.colour_bands = 0;
  EXPECT_THROW(AppearanceCosts(image, training, 3, {}, bad), Error);
}

// A band where the people have too few pixels of their own for band models
// (min_band_samples) weighs their whole models against the background's
// whole model, not against the band's: a band model fits its few colours
// more tightly and would win by its locality alone. When every object falls
// back so, the costs are those of one band.
TEST(AppearanceCostsTest, ABandWithoutTheObjectsOwnModelsWeighsWholeModels) {
  cv::Mat image, truth, shirt, tiles;
  PeopleOnTiles(&image, &truth, &shirt, &tiles);
  const std::vector<LabelledImage> training{{image, truth}};
  LabelCostOptions one, fallback;
  one.colour_bands = 1;
  fallback.colour_bands = 4;
  fallback.min_band_samples = 1500;  // each person has about 600 per band, the background more
  const LabelCostVolume a = AppearanceCosts(image, training, 3, {}, one);
  const LabelCostVolume b = AppearanceCosts(image, training, 3, {}, fallback);
  for (size_t i = 0; i < a.cost.size(); ++i) ASSERT_NEAR(a.cost[i], b.cost[i], 1e-5) << i;
}

// Two people whose ids a neighbouring frame's labels swapped give no colour
// samples there (DropSwappedSamples); a neighbour with the right ids, the
// reference frame and another view's image keep theirs.
TEST(DropSwappedSamplesTest, OnlyTheSwappedNeighboursObjectsGiveNoSamples) {
  cv::Mat image, truth, shirt, tiles;
  PeopleOnTiles(&image, &truth, &shirt, &tiles);
  cv::Mat swapped = truth.clone();
  swapped.setTo(2, truth == 1);
  swapped.setTo(1, truth == 2);
  std::vector<LabelledImage> training{
      {image, truth}, {image, swapped}, {image, truth}, {image, swapped, /*other_view=*/true}};
  const ColourHistograms reference = ObjectColourHistograms({training.front()}, 3);
  ASSERT_EQ(reference.size(), 3u);
  EXPECT_TRUE(reference[0].empty());
  DropSwappedSamples(reference, &training);
  auto same = [](const cv::Mat& a, const cv::Mat& b) { return cv::countNonZero(a != b) == 0; };
  EXPECT_TRUE(same(training[0].labels, truth));
  EXPECT_TRUE(same(training[2].labels, truth));
  EXPECT_TRUE(same(training[3].labels, swapped));
  cv::Mat expected = truth.clone();
  expected.setTo(kUnsampledLabel, truth > 0);
  EXPECT_TRUE(same(training[1].labels, expected));
  training.push_back({image, cv::Mat(3, 3, CV_16U, cv::Scalar(0))});
  EXPECT_THROW(DropSwappedSamples(reference, &training), Error);
}

TEST(RelaxSemanticCostsTest, TheOtherViewsObjectCostsNoMoreThanTheInitialLabel) {
  // A 20x10 image: object 1 in the left half; the hull support names object 1
  // on the right half too (a part the mask missed) and object 2 on one pixel
  // that the mask gives to object 1 (a person claimed by object 2, a box
  // merged with them in this view).
  cv::Mat labels = cv::Mat::zeros(10, 20, CV_16U);
  labels(cv::Rect(0, 0, 10, 10)).setTo(1);
  LabelCostVolume semantic = SemanticCosts(labels, 3);
  const LabelCostVolume before = semantic;
  cv::Mat support = cv::Mat::zeros(10, 20, CV_16U);
  support(cv::Rect(10, 0, 10, 10)).setTo(1);
  support.at<uint16_t>(5, 2) = 2;
  RelaxSemanticCosts(labels, support, &semantic);
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 20; ++x) {
      const int p = y * 20 + x;
      if (x >= 10) {
        EXPECT_FLOAT_EQ(semantic.At(p, 1), before.At(p, 0)) << x << "," << y;
        EXPECT_FLOAT_EQ(semantic.At(p, 0), before.At(p, 0));
      } else {
        for (int l = 0; l < 2; ++l) EXPECT_FLOAT_EQ(semantic.At(p, l), before.At(p, l));
      }
      const bool claimed = x == 2 && y == 5;
      EXPECT_FLOAT_EQ(semantic.At(p, 2), claimed ? before.At(p, 1) : before.At(p, 2));
    }
  EXPECT_LT(before.At(5 * 20 + 2, 1), before.At(5 * 20 + 2, 2));  // the claim lowered a cost
  EXPECT_THROW(RelaxSemanticCosts(labels, cv::Mat::zeros(5, 5, CV_16U), &semantic), Error);
}

TEST(TrustConfirmedLabelsTest, AConfirmedObjectCostsNoMoreThanTheBackgroundOrAHeldObject) {
  // A 10x10 volume of 4 labels: the colour costs prefer label 3, then 2, the
  // background 0, then 1. The view holds objects 1 and 2 (3 was not tested).
  // The other views confirm label 1 on the left half, alone on its top row,
  // and label 2 on one pixel of the right half.
  LabelCostVolume appearance;
  appearance.width = appearance.height = 10;
  appearance.num_labels = 4;
  appearance.cost.resize(400);
  const float cost_of[4] = {0.5f, 0.9f, 0.3f, 0.1f};
  for (int l = 0; l < 4; ++l)
    for (int p = 0; p < 100; ++p) appearance.cost[l * 100 + p] = cost_of[l];
  const LabelCostVolume before = appearance;
  cv::Mat confirmed = cv::Mat::zeros(10, 10, CV_16U);
  confirmed(cv::Rect(0, 0, 5, 10)).setTo(1);
  confirmed.at<uint16_t>(3, 7) = 2;
  cv::Mat alone = cv::Mat::zeros(10, 10, CV_8U);
  alone(cv::Rect(0, 0, 5, 1)).setTo(255);
  TrustConfirmedLabels(confirmed, alone, {false, true, true, false}, &appearance);
  for (int p = 0; p < 100; ++p) {
    const bool left = p % 10 < 5, top = p < 10;
    EXPECT_FLOAT_EQ(appearance.At(p, 0), before.At(p, 0));
    // Alone: lowered to the held object 2's (not to the untested 3's);
    // elsewhere to the background's.
    const float one = !left ? before.At(p, 1) : top ? before.At(p, 2) : before.At(p, 0);
    EXPECT_FLOAT_EQ(appearance.At(p, 1), one);
    EXPECT_FLOAT_EQ(appearance.At(p, 2), before.At(p, 2));  // already below the background's
    EXPECT_FLOAT_EQ(appearance.At(p, 3), before.At(p, 3));
  }
  EXPECT_THROW(TrustConfirmedLabels(cv::Mat::zeros(5, 5, CV_16U), {}, {}, &appearance), Error);
}

}  // namespace
}  // namespace u4d
