// FitColorGmm (label_costs.h): the EM written out in label_costs.cc must give
// the fit of cv::ml::EM, the implementation it replaced (same algorithm, same
// initialisation), and recover a known mixture.
#include <random>

#include <gtest/gtest.h>
#include <opencv2/ml.hpp>

#include "u4d/joint/label_costs.h"

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

}  // namespace
}  // namespace u4d
