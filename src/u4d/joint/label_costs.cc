#include "u4d/joint/label_costs.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <tbb/parallel_for.h>
#include <Eigen/LU>
#include <opencv2/imgproc.hpp>
#include <opencv2/ml.hpp>

#include "u4d/util/check.h"

namespace u4d {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Normalises per pixel: (c_l − min_l c_l) / scale, clamped to [0, 1].
void NormaliseToBest(double scale, LabelCostVolume* volume) {
  const size_t n = static_cast<size_t>(volume->width) * volume->height;
  tbb::parallel_for(size_t{0}, n, [&](size_t p) {
    float best = std::numeric_limits<float>::max();
    for (int l = 0; l < volume->num_labels; ++l) best = std::min(best, volume->cost[l * n + p]);
    for (int l = 0; l < volume->num_labels; ++l) {
      float& c = volume->cost[l * n + p];
      c = static_cast<float>(std::clamp((c - best) / scale, 0.0, 1.0));
    }
  });
}

}  // namespace

double ColorGmm::LogLikelihood(const cv::Vec3b& bgr) const {
  const Eigen::Vector3d x(bgr[0], bgr[1], bgr[2]);
  double best = -std::numeric_limits<double>::infinity();
  double terms[32];
  const int k = static_cast<int>(weights.size());
  for (int i = 0; i < k; ++i) {
    const Eigen::Vector3d d = x - means[i];
    terms[i] = log_norms[i] - 0.5 * d.dot(inv_covs[i] * d);
    best = std::max(best, terms[i]);
  }
  double sum = 0;
  for (int i = 0; i < k; ++i) sum += std::exp(terms[i] - best);
  return best + std::log(sum);
}

ColorGmm FitColorGmm(const std::vector<cv::Vec3b>& samples, int components, uint64_t seed) {
  U4D_CHECK(!samples.empty(), "FitColorGmm: no colour samples");
  U4D_CHECK(components >= 1 && components <= 32,
            "FitColorGmm: components must be in [1, 32], got {}", components);
  const int k = std::max(1, std::min<int>(components, static_cast<int>(samples.size()) / 8));
  cv::Mat data(static_cast<int>(samples.size()), 3, CV_64F);
  for (int i = 0; i < data.rows; ++i)
    for (int c = 0; c < 3; ++c) data.at<double>(i, c) = samples[i][c];
  ColorGmm gmm;
  auto add_component = [&](double w, const Eigen::Vector3d& mean, Eigen::Matrix3d cov) {
    cov +=
        Eigen::Matrix3d::Identity() * 4.0;  // sensor noise floor (2 grey levels) keeps Σ invertible
    gmm.weights.push_back(w);
    gmm.means.push_back(mean);
    gmm.inv_covs.push_back(cov.inverse());
    gmm.log_norms.push_back(std::log(std::max(w, 1e-12)) -
                            0.5 * (3 * std::log(2 * kPi) + std::log(cov.determinant())));
  };
  if (k == 1) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& s : samples) mean += Eigen::Vector3d(s[0], s[1], s[2]);
    mean /= samples.size();
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& s : samples) {
      const Eigen::Vector3d d = Eigen::Vector3d(s[0], s[1], s[2]) - mean;
      cov += d * d.transpose();
    }
    add_component(1.0, mean, cov / samples.size());
    return gmm;
  }
  cv::RNG rng_state(seed);
  cv::theRNG() = rng_state;  // EM's k-means initialisation draws from OpenCV's thread-local RNG
  cv::Ptr<cv::ml::EM> em = cv::ml::EM::create();
  em->setClustersNumber(k);
  em->setCovarianceMatrixType(cv::ml::EM::COV_MAT_GENERIC);
  em->setTermCriteria(cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30, 1e-3));
  U4D_CHECK(em->trainEM(data), "FitColorGmm: EM failed on {} samples", samples.size());
  const cv::Mat means = em->getMeans();
  const cv::Mat weights = em->getWeights();
  std::vector<cv::Mat> covs;
  em->getCovs(covs);
  for (int i = 0; i < k; ++i) {
    Eigen::Vector3d mean(means.at<double>(i, 0), means.at<double>(i, 1), means.at<double>(i, 2));
    Eigen::Matrix3d cov;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) cov(r, c) = covs[i].at<double>(r, c);
    add_component(weights.at<double>(0, i), mean, cov);
  }
  return gmm;
}

void LabelCostOptions::Check() const {
  U4D_CHECK(gmm_components >= 1 && gmm_components <= 32,
            "LabelCostOptions.gmm_components must be in [1, 32], got {}", gmm_components);
  U4D_CHECK(max_samples_per_label >= 16, "LabelCostOptions.max_samples_per_label must be >= 16");
  U4D_CHECK(background_band_px >= 1, "LabelCostOptions.background_band_px must be >= 1");
  U4D_CHECK(mask_softness_px > 0, "LabelCostOptions.mask_softness_px must be > 0");
  U4D_CHECK(min_probability > 0 && min_probability < 1,
            "LabelCostOptions.min_probability must be in (0, 1), got {}", min_probability);
}

LabelCostVolume AppearanceCosts(const cv::Mat& image, const std::vector<LabelledImage>& training,
                                int num_labels,
                                const std::vector<std::vector<Eigen::Vector2d>>& markers,
                                const LabelCostOptions& options) {
  options.Check();
  U4D_CHECK(image.type() == CV_8UC3, "AppearanceCosts: image must be BGR 8-bit");
  U4D_CHECK(num_labels >= 1, "AppearanceCosts: need at least one label");
  // Samples per label from the temporal neighbourhood's masks. Background
  // samples come from a band around the objects: that is the background the
  // objects' pixels compete with.
  std::vector<std::vector<cv::Vec3b>> samples(num_labels);
  for (const LabelledImage& t : training) {
    U4D_CHECK(t.image.size() == image.size() && t.labels.size() == image.size() &&
                  t.labels.type() == CV_16UC1 && t.image.type() == CV_8UC3,
              "AppearanceCosts: training image/labels must be {}x{} BGR / CV_16U", image.cols,
              image.rows);
    cv::Mat objects = t.labels > 0, band;
    cv::dilate(
        objects, band,
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * options.background_band_px + 1,
                                                              2 * options.background_band_px + 1)));
    for (int y = 0; y < image.rows; ++y)
      for (int x = 0; x < image.cols; ++x) {
        const int l = t.labels.at<uint16_t>(y, x);
        if (l >= num_labels) continue;
        if (l == 0 && !band.at<uint8_t>(y, x)) continue;
        samples[l].push_back(t.image.at<cv::Vec3b>(y, x));
      }
  }
  for (int l = 0; l < num_labels && l < static_cast<int>(markers.size()); ++l)
    for (const Eigen::Vector2d& m : markers[l]) {
      const int x = static_cast<int>(std::lround(m.x())), y = static_cast<int>(std::lround(m.y()));
      if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) continue;
      samples[l].push_back(image.at<cv::Vec3b>(y, x));
    }
  std::mt19937_64 rng(options.seed);
  std::vector<ColorGmm> gmms(num_labels);
  for (int l = 0; l < num_labels; ++l) {
    auto& s = samples[l];
    if (s.empty()) continue;
    if (static_cast<int>(s.size()) > options.max_samples_per_label) {
      std::shuffle(s.begin(), s.end(), rng);
      s.resize(options.max_samples_per_label);
    }
    gmms[l] = FitColorGmm(s, options.gmm_components, options.seed + l);
  }
  LabelCostVolume volume{image.cols, image.rows, num_labels, {}};
  const size_t n = static_cast<size_t>(image.cols) * image.rows;
  volume.cost.assign(n * num_labels, 0.f);
  const double floor_nll = -std::log(options.min_probability);
  tbb::parallel_for(0, image.rows, [&](int y) {
    for (int x = 0; x < image.cols; ++x) {
      const size_t p = static_cast<size_t>(y) * image.cols + x;
      const cv::Vec3b c = image.at<cv::Vec3b>(y, x);
      for (int l = 0; l < num_labels; ++l)
        volume.cost[l * n + p] = gmms[l].Empty() ? std::numeric_limits<float>::max() / 4
                                                 : static_cast<float>(-gmms[l].LogLikelihood(c));
    }
  });
  NormaliseToBest(floor_nll, &volume);
  return volume;
}

LabelCostVolume SemanticCosts(const cv::Mat& initial_labels, int num_labels,
                              const LabelCostOptions& options) {
  options.Check();
  U4D_CHECK(initial_labels.type() == CV_16UC1, "SemanticCosts: labels must be CV_16U");
  U4D_CHECK(num_labels >= 1, "SemanticCosts: need at least one label");
  const int w = initial_labels.cols, h = initial_labels.rows;
  const size_t n = static_cast<size_t>(w) * h;
  LabelCostVolume volume{w, h, num_labels, {}};
  volume.cost.assign(n * num_labels, 0.f);
  // Signed distance to each label's region: positive inside.
  std::vector<cv::Mat> signed_distance(num_labels);
  for (int l = 0; l < num_labels; ++l) {
    cv::Mat inside = initial_labels == l, outside = initial_labels != l, d_in, d_out;
    cv::distanceTransform(inside, d_in, cv::DIST_L2, 3);
    cv::distanceTransform(outside, d_out, cv::DIST_L2, 3);
    signed_distance[l] = d_in - d_out;
  }
  const double eps = options.min_probability;
  tbb::parallel_for(0, h, [&](int y) {
    std::vector<double> prob(num_labels);
    for (int x = 0; x < w; ++x) {
      double sum = 0;
      for (int l = 0; l < num_labels; ++l) {
        // Inside pixels are at distance >= 1 from the boundary, outside <= -1
        // (distanceTransform counts to the nearest other pixel).
        const double s = signed_distance[l].at<float>(y, x);
        const double inside = s > 0 ? s - 0.5 : s + 0.5;
        prob[l] = eps + 1.0 / (1.0 + std::exp(-inside / options.mask_softness_px));
        sum += prob[l];
      }
      const size_t p = static_cast<size_t>(y) * w + x;
      for (int l = 0; l < num_labels; ++l)
        volume.cost[l * n + p] = static_cast<float>(-std::log(prob[l] / sum));
    }
  });
  NormaliseToBest(-std::log(eps), &volume);
  return volume;
}

namespace {

template <typename Distance>
std::vector<float> ExpWeights(int width, const std::vector<std::pair<int, int>>& pairs,
                              Distance distance2) {
  std::vector<float> d2(pairs.size());
  double sum = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    d2[i] = static_cast<float>(distance2(pairs[i].first, pairs[i].second));
    sum += d2[i];
  }
  const double beta = pairs.empty() ? 1.0 : std::max(sum / pairs.size(), 1e-6);
  std::vector<float> w(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    const auto [p, q] = pairs[i];
    const int dx = q % width - p % width, dy = q / width - p / width;
    w[i] = static_cast<float>(std::exp(-d2[i] / (2 * beta)) / std::sqrt(double(dx * dx + dy * dy)));
  }
  return w;
}

}  // namespace

std::vector<float> ContrastWeights(const cv::Mat& image,
                                   const std::vector<std::pair<int, int>>& pairs) {
  U4D_CHECK(image.type() == CV_8UC3 && image.isContinuous(),
            "ContrastWeights: image must be continuous BGR 8-bit");
  const cv::Vec3b* pixels = image.ptr<cv::Vec3b>();
  return ExpWeights(image.cols, pairs, [&](int p, int q) {
    const cv::Vec3i d = cv::Vec3i(pixels[p]) - cv::Vec3i(pixels[q]);
    return double(d.dot(d));
  });
}

std::vector<float> SemanticContrastWeights(const LabelCostVolume& semantic,
                                           const std::vector<std::pair<int, int>>& pairs) {
  const size_t n = static_cast<size_t>(semantic.width) * semantic.height;
  return ExpWeights(semantic.width, pairs, [&](int p, int q) {
    double s = 0;
    for (int l = 0; l < semantic.num_labels; ++l) {
      const double d = semantic.cost[l * n + p] - semantic.cost[l * n + q];
      s += d * d;
    }
    return s;
  });
}

}  // namespace u4d
