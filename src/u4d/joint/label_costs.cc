#include "u4d/joint/label_costs.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include <tbb/parallel_for.h>
#include <Eigen/LU>
#include <opencv2/imgproc.hpp>

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

// A full-covariance GMM as cv::ml::EM returns it.
struct GmmParameters {
  std::vector<double> weights;
  std::vector<Eigen::Vector3d> means;
  std::vector<Eigen::Matrix3d> covs;
};

// Eigen-decomposition of one covariance as cv::ml::EM keeps it (SVD, eigenvalues
// floored at DBL_EPSILON).
struct CovarianceBasis {
  Eigen::Matrix3d rotate;     // columns: eigenvectors (svd.u)
  Eigen::Vector3d inv_eigen;  // 1 / eigenvalue
  double log_det = 0;         // sum of log eigenvalues
};

CovarianceBasis Decompose(const Eigen::Matrix3d& cov) {
  cv::Mat c(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int j = 0; j < 3; ++j) c.at<double>(r, j) = cov(r, j);
  const cv::SVD svd(c, cv::SVD::FULL_UV);
  CovarianceBasis b;
  for (int d = 0; d < 3; ++d) {
    const double e = std::max(svd.w.at<double>(d), DBL_EPSILON);
    b.inv_eigen[d] = 1.0 / e;
    b.log_det += std::log(e);
    for (int r = 0; r < 3; ++r) b.rotate(r, d) = svd.u.at<double>(r, d);
  }
  return b;
}

// EM for a full-covariance GMM over 3-vectors: the algorithm and arithmetic of
// cv::ml::EM::trainEM (OpenCV 4.x, START_AUTO_STEP, COV_MAT_GENERIC) written
// out, because cv::ml::EM evaluates every sample and component with small
// cv::Mat operations, which made the GMM fits a large share of a joint view
// solve (kernels_bench BM_GmmFit times both). Initialisation: cv::kmeans (k-means++, 10
// attempts, 10 iterations; draws from cv::theRNG()), covariances of the
// clusters; then E and M steps until the log-likelihood gains less than
// `eps` relative or `max_iters` E steps. The fit equals cv::ml::EM's up to
// floating-point rounding (same initialisation, same update order).
GmmParameters TrainGmm(const cv::Mat& samples64, int k, int max_iters, double eps) {
  const int n = samples64.rows;
  U4D_CHECK(samples64.type() == CV_64FC1 && samples64.cols == 3 && n >= k && k >= 1,
            "TrainGmm: need a CV_64F n x 3 sample matrix with n >= k = {}, got {} x {}", k, n,
            samples64.cols);
  cv::Mat samples32;
  samples64.convertTo(samples32, CV_32F);
  cv::Mat labels, centres32;
  cv::kmeans(samples32, k, labels, cv::TermCriteria(cv::TermCriteria::COUNT, 10, 0.5), 10,
             cv::KMEANS_PP_CENTERS, centres32);
  std::vector<Eigen::Vector3d> x(n);
  for (int s = 0; s < n; ++s)
    x[s] = Eigen::Vector3d(samples32.at<float>(s, 0), samples32.at<float>(s, 1),
                           samples32.at<float>(s, 2));

  GmmParameters g;
  g.weights.assign(k, 0.0);
  g.means.resize(k);
  g.covs.resize(k);
  std::vector<CovarianceBasis> basis(k);
  for (int c = 0; c < k; ++c) {
    g.means[c] = Eigen::Vector3d(centres32.at<float>(c, 0), centres32.at<float>(c, 1),
                                 centres32.at<float>(c, 2));
    cv::Mat members;
    for (int s = 0; s < n; ++s)
      if (labels.at<int>(s) == c) members.push_back(samples64.row(s));
    U4D_CHECK(!members.empty(), "TrainGmm: k-means left cluster {} of {} empty", c, k);
    const cv::Mat mean = (cv::Mat_<double>(1, 3) << g.means[c].x(), g.means[c].y(), g.means[c].z());
    cv::Mat cov;
    cv::calcCovarMatrix(members, cov, mean,
                        cv::COVAR_NORMAL | cv::COVAR_ROWS | cv::COVAR_USE_AVG | cv::COVAR_SCALE,
                        CV_64F);
    for (int r = 0; r < 3; ++r)
      for (int j = 0; j < 3; ++j) g.covs[c](r, j) = cov.at<double>(r, j);
    g.weights[c] = static_cast<double>(members.rows) / n;
    basis[c] = Decompose(g.covs[c]);
  }

  std::vector<double> probs(static_cast<size_t>(n) * k), L(k);
  const double log_2pi = std::log(2 * kPi);
  double prev_log_likelihood = 0, log_likelihood = 0;
  for (int iter = 0;; ++iter) {
    // E step.
    std::vector<double> log_weight_div_det(k);
    for (int c = 0; c < k; ++c) {
      g.weights[c] = std::max(g.weights[c], DBL_MIN);
      log_weight_div_det[c] = std::log(g.weights[c]) - 0.5 * basis[c].log_det;
    }
    log_likelihood = 0;
    for (int s = 0; s < n; ++s) {
      int label = 0;
      for (int c = 0; c < k; ++c) {
        const Eigen::Vector3d d = x[s] - g.means[c];
        double l = 0;
        for (int j = 0; j < 3; ++j) {
          const Eigen::Matrix3d& u = basis[c].rotate;
          const double v = d[0] * u(0, j) + d[1] * u(1, j) + d[2] * u(2, j);
          l += basis[c].inv_eigen[j] * v * v;
        }
        L[c] = log_weight_div_det[c] - 0.5 * l;
        if (L[c] > L[label]) label = c;
      }
      const double max_l = L[label];
      double sum = 0;
      for (int c = 0; c < k; ++c) sum += (L[c] = std::exp(L[c] - max_l));
      const double scale = 1.0 / sum;
      for (int c = 0; c < k; ++c) probs[static_cast<size_t>(s) * k + c] = L[c] * scale;
      log_likelihood += std::log(sum) + max_l - 1.5 * log_2pi;
    }
    if (iter >= max_iters - 1) break;
    const double delta = log_likelihood - prev_log_likelihood;
    if (iter != 0 && (delta < -DBL_EPSILON || delta < eps * std::abs(log_likelihood))) break;

    // M step.
    std::fill(g.weights.begin(), g.weights.end(), 0.0);
    for (int s = 0; s < n; ++s)
      for (int c = 0; c < k; ++c) g.weights[c] += probs[static_cast<size_t>(s) * k + c];
    const double min_pos_weight = n * DBL_EPSILON;
    double min_weight = DBL_MAX;
    int min_weight_cluster = -1;
    for (int c = 0; c < k; ++c) {
      g.means[c].setZero();
      if (g.weights[c] <= min_pos_weight) continue;
      if (g.weights[c] < min_weight) min_weight = g.weights[c], min_weight_cluster = c;
      for (int s = 0; s < n; ++s) g.means[c] += probs[static_cast<size_t>(s) * k + c] * x[s];
      g.means[c] /= g.weights[c];
    }
    for (int c = 0; c < k; ++c) {
      if (g.weights[c] <= min_pos_weight) continue;
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (int s = 0; s < n; ++s) {
        const Eigen::Vector3d d = x[s] - g.means[c];
        const double p = probs[static_cast<size_t>(s) * k + c];
        for (int r = 0; r < 3; ++r)
          for (int j = 0; j < 3; ++j) cov(r, j) += p * (d[r] * d[j]);
      }
      g.covs[c] = cov / g.weights[c];
      basis[c] = Decompose(g.covs[c]);
    }
    for (int c = 0; c < k; ++c)
      if (g.weights[c] <= min_pos_weight) {
        g.means[c] = g.means[min_weight_cluster];
        g.covs[c] = g.covs[min_weight_cluster];
        basis[c] = basis[min_weight_cluster];
      }
    for (double& w : g.weights) w /= n;
    prev_log_likelihood = log_likelihood;
  }
  U4D_CHECK(log_likelihood > -DBL_MAX / 10000., "TrainGmm: EM diverged on {} samples", n);
  return g;
}

// Pixels at least `inset` px from their label's boundary (per label, a
// morphological erosion); a label whose inside is too small to describe it
// (under a quarter of its pixels or 32 pixels: a thin limb, a far person)
// keeps all its pixels.
cv::Mat SureSamplePixels(const cv::Mat& labels, int num_labels, int inset) {
  cv::Mat sure(labels.size(), CV_8U, cv::Scalar(255));
  if (inset <= 0) return sure;
  const cv::Mat kernel =
      cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * inset + 1, 2 * inset + 1));
  for (int l = 0; l < num_labels; ++l) {
    const cv::Mat mask = labels == l;
    const int area = cv::countNonZero(mask);
    if (area == 0) continue;
    cv::Mat inside;
    cv::erode(mask, inside, kernel, cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
    const int kept = cv::countNonZero(inside);
    if (kept < 32 || 4 * kept < area) continue;
    sure.setTo(0, mask & ~inside);
  }
  return sure;
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
  cv::theRNG() = rng_state;  // k-means++ initialisation draws from OpenCV's thread-local RNG
  const GmmParameters fit = TrainGmm(data, k, 30, 1e-3);
  for (int i = 0; i < k; ++i) add_component(fit.weights[i], fit.means[i], fit.covs[i]);
  return gmm;
}

void LabelCostOptions::Check() const {
  U4D_CHECK(gmm_components >= 1 && gmm_components <= 32,
            "LabelCostOptions.gmm_components must be in [1, 32], got {}", gmm_components);
  U4D_CHECK(max_samples_per_label >= 16, "LabelCostOptions.max_samples_per_label must be >= 16");
  U4D_CHECK(background_band_px >= 1, "LabelCostOptions.background_band_px must be >= 1");
  U4D_CHECK(mask_softness_px > 0, "LabelCostOptions.mask_softness_px must be > 0");
  U4D_CHECK(appearance_inset_px >= 0, "LabelCostOptions.appearance_inset_px must be >= 0, got {}",
            appearance_inset_px);
  U4D_CHECK(colour_bands >= 1, "LabelCostOptions.colour_bands must be >= 1, got {}", colour_bands);
  U4D_CHECK(max_samples_per_band >= 16, "LabelCostOptions.max_samples_per_band must be >= 16");
  U4D_CHECK(min_band_samples >= 1, "LabelCostOptions.min_band_samples must be >= 1, got {}",
            min_band_samples);
  U4D_CHECK(min_probability > 0 && min_probability < 1,
            "LabelCostOptions.min_probability must be in (0, 1), got {}", min_probability);
}

namespace {

// Each label's colour samples and, with bands, the image row each came from
// (-1: another view's, which has no row in this image and serves every band).
struct ColourSamples {
  std::vector<std::vector<cv::Vec3b>> colours;
  std::vector<std::vector<int>> rows;
  int top = 0, bottom = -1;  // the rows the objects span in the view's own maps
};

// Samples per label from the temporal neighbourhood's masks. Background
// samples come from a band around the objects: that is the background the
// objects' pixels compete with.
ColourSamples CollectColourSamples(const cv::Mat& image, const std::vector<LabelledImage>& training,
                                   int num_labels,
                                   const std::vector<std::vector<Eigen::Vector2d>>& markers,
                                   const LabelCostOptions& options) {
  const bool keep_rows = options.colour_bands > 1;  // only the bands read them
  ColourSamples out;
  out.colours.resize(num_labels);
  out.rows.resize(num_labels);
  out.top = image.rows;
  for (const LabelledImage& t : training) {
    U4D_CHECK(t.image.size() == image.size() && t.labels.size() == image.size() &&
                  t.labels.type() == CV_16UC1 && t.image.type() == CV_8UC3,
              "AppearanceCosts: training image/labels must be {}x{} BGR / CV_16U", image.cols,
              image.rows);
    // Another view's image lends only its objects' samples: no band.
    cv::Mat band;
    if (!t.other_view)
      cv::dilate(t.labels > 0, band,
                 cv::getStructuringElement(cv::MORPH_ELLIPSE,
                                           cv::Size(2 * options.background_band_px + 1,
                                                    2 * options.background_band_px + 1)));
    const cv::Mat sure = SureSamplePixels(t.labels, num_labels, options.appearance_inset_px);
    for (int y = 0; y < image.rows; ++y)
      for (int x = 0; x < image.cols; ++x) {
        const int l = t.labels.at<uint16_t>(y, x);
        if (l >= num_labels) continue;
        if (l > 0 && !t.other_view)
          out.top = std::min(out.top, y), out.bottom = std::max(out.bottom, y);
        if (!sure.at<uint8_t>(y, x)) continue;
        if (l == 0 && (band.empty() || !band.at<uint8_t>(y, x))) continue;
        out.colours[l].push_back(t.image.at<cv::Vec3b>(y, x));
        if (keep_rows) out.rows[l].push_back(t.other_view ? -1 : y);
      }
  }
  for (int l = 0; l < num_labels && l < static_cast<int>(markers.size()); ++l)
    for (const Eigen::Vector2d& m : markers[l]) {
      const int x = static_cast<int>(std::lround(m.x())), y = static_cast<int>(std::lround(m.y()));
      if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) continue;
      out.colours[l].push_back(image.at<cv::Vec3b>(y, x));
      if (keep_rows) out.rows[l].push_back(y);
    }
  return out;
}

// Horizontal bands of equal height over the objects' rows. Band b holds the
// samples within one band height of its centre (it overlaps each neighbour
// by half of it); a row takes the band whose centre is nearest.
struct ColourBands {
  int count = 1;
  double top = 0, height = 1;
  double Centre(int b) const { return top + (b + 0.5) * height; }
  bool Holds(int b, int row) const { return row < 0 || std::abs(row - Centre(b)) <= height; }
  int Of(int row) const {
    return std::clamp(static_cast<int>(std::floor((row - top) / height)), 0, count - 1);
  }
};

// A random subset of at most `cap` colours (drawn with `rng`), fitted.
ColorGmm FitSubset(std::vector<cv::Vec3b> colours, int cap, int components, uint64_t seed,
                   std::mt19937_64* rng) {
  if (colours.empty()) return {};
  if (static_cast<int>(colours.size()) > cap) {
    std::shuffle(colours.begin(), colours.end(), *rng);
    colours.resize(cap);
  }
  return FitColorGmm(colours, components, seed);
}

// The colour models: whole[l] from all of label l's samples, band[b][l] from
// band b's where the band holds at least min_band_samples of the view's own
// (own[b][l]; else label l's whole model). With one band only the whole
// models. The whole models take the samples (their subsets are drawn in
// place).
struct ColourModels {
  std::vector<ColorGmm> whole;
  std::vector<std::vector<ColorGmm>> band;
  std::vector<std::vector<uint8_t>> own;
};

ColourModels FitColourModels(ColourSamples samples, const ColourBands& bands,
                             const LabelCostOptions& options) {
  const int num_labels = static_cast<int>(samples.colours.size());
  ColourModels models;
  models.band.assign(bands.count == 1 ? 0 : bands.count, std::vector<ColorGmm>(num_labels));
  models.own.assign(models.band.size(), std::vector<uint8_t>(num_labels, 0));
  std::mt19937_64 band_rng(options.seed + 1);
  for (int b = 0; b < static_cast<int>(models.band.size()); ++b)
    for (int l = 0; l < num_labels; ++l) {
      std::vector<cv::Vec3b> colours;
      int own = 0;
      for (size_t i = 0; i < samples.rows[l].size(); ++i)
        if (bands.Holds(b, samples.rows[l][i]))
          colours.push_back(samples.colours[l][i]), own += samples.rows[l][i] >= 0;
      if (own < options.min_band_samples) continue;
      models.band[b][l] = FitSubset(std::move(colours), options.max_samples_per_band,
                                    options.gmm_components, options.seed + l, &band_rng);
      models.own[b][l] = 1;
    }
  models.whole.resize(num_labels);
  std::mt19937_64 rng(options.seed);
  for (int l = 0; l < num_labels; ++l)
    models.whole[l] = FitSubset(std::move(samples.colours[l]), options.max_samples_per_label,
                                options.gmm_components, options.seed + l, &rng);
  for (std::vector<ColorGmm>& band : models.band)
    for (int l = 0; l < num_labels; ++l)
      if (band[l].Empty()) band[l] = models.whole[l];
  return models;
}

// −log P(c | l) for every label at a pixel of band b (above AppearanceCosts),
// up to a constant, into cost[l * stride]; `whole` is scratch space for
// num_labels values. An object's odds against the background are those of
// the band's models only where both have their own: a band model fits its
// few colours more tightly than a whole model, so a band's background
// weighed against an object's whole model (a person with too few pixels in
// the band) would win by the models' locality alone.
void PixelAppearance(const ColourModels& models, int b, const cv::Vec3b& c, float* cost,
                     size_t stride, double* whole) {
  const int num_labels = static_cast<int>(models.whole.size());
  constexpr float kNone = std::numeric_limits<float>::max() / 4;
  for (int l = 0; l < num_labels; ++l)
    if (!models.whole[l].Empty()) whole[l] = models.whole[l].LogLikelihood(c);
  if (models.band.empty() || models.whole[0].Empty()) {
    for (int l = 0; l < num_labels; ++l)
      cost[l * stride] = models.whole[l].Empty() ? kNone : static_cast<float>(-whole[l]);
    return;
  }
  const std::vector<ColorGmm>& local = models.band[b];
  const std::vector<uint8_t>& own = models.own[b];
  const double background = own[0] ? local[0].LogLikelihood(c) : whole[0];
  double odds = -std::numeric_limits<double>::infinity(), best_whole = odds;
  for (int l = 1; l < num_labels; ++l) {
    if (models.whole[l].Empty()) continue;
    odds = std::max(
        odds, own[0] && own[l] ? local[l].LogLikelihood(c) - background : whole[l] - whole[0]);
    best_whole = std::max(best_whole, whole[l]);
  }
  cost[0] = 0.f;
  for (int l = 1; l < num_labels; ++l)
    cost[l * stride] =
        models.whole[l].Empty() ? kNone : static_cast<float>(-(odds + whole[l] - best_whole));
}

}  // namespace

ColourHistograms ObjectColourHistograms(const std::vector<LabelledImage>& images, int num_labels) {
  ColourHistograms hist(num_labels);
  const int channels[] = {0, 1, 2}, bins[] = {8, 8, 8};
  const float range[] = {0, 256};
  const float* ranges[] = {range, range, range};
  for (const LabelledImage& li : images) {
    U4D_CHECK(li.image.type() == CV_8UC3 && li.labels.type() == CV_16UC1 &&
                  li.image.size() == li.labels.size(),
              "ObjectColourHistograms: image/labels must be BGR / CV_16U of one size");
    for (int l = 1; l < num_labels; ++l) {
      const cv::Mat mask = li.labels == l;
      if (cv::countNonZero(mask) == 0) continue;
      cv::calcHist(&li.image, 1, channels, mask, hist[l], 3, bins, ranges, true,
                   /*accumulate=*/!hist[l].empty());
    }
  }
  return hist;
}

namespace {

// The Bhattacharyya distance of two histograms (cv::compareHist), 1 where
// either is empty.
double Bhattacharyya(const cv::Mat& a, const cv::Mat& b) {
  return a.empty() || b.empty() ? 1.0 : cv::compareHist(a, b, cv::HISTCMP_BHATTACHARYYA);
}

}  // namespace

void DropSwappedSamples(const ColourHistograms& reference, std::vector<LabelledImage>* training) {
  const int n = static_cast<int>(reference.size());
  for (LabelledImage& li : *training) {
    if (li.other_view) continue;
    const ColourHistograms hist = ObjectColourHistograms({li}, n);
    cv::Mat drop = cv::Mat::zeros(li.labels.size(), CV_8U);
    for (int l = 1; l < n; ++l)
      for (int k = l + 1; k < n; ++k) {
        if (hist[l].empty() || hist[k].empty() || reference[l].empty() || reference[k].empty())
          continue;
        if (Bhattacharyya(hist[l], reference[k]) < Bhattacharyya(hist[l], reference[l]) &&
            Bhattacharyya(hist[k], reference[l]) < Bhattacharyya(hist[k], reference[k]))
          drop |= (li.labels == l) | (li.labels == k);
      }
    if (cv::countNonZero(drop) == 0) continue;
    li.labels = li.labels.clone();
    li.labels.setTo(kUnsampledLabel, drop);
  }
}

LabelCostVolume AppearanceCosts(const cv::Mat& image, const std::vector<LabelledImage>& training,
                                int num_labels,
                                const std::vector<std::vector<Eigen::Vector2d>>& markers,
                                const LabelCostOptions& options, const cv::Mat& where) {
  options.Check();
  U4D_CHECK(image.type() == CV_8UC3, "AppearanceCosts: image must be BGR 8-bit");
  U4D_CHECK(num_labels >= 1, "AppearanceCosts: need at least one label");
  U4D_CHECK(where.empty() || (where.size() == image.size() && where.type() == CV_8UC1),
            "AppearanceCosts: `where` must be CV_8U {}x{}", image.cols, image.rows);
  ColourSamples samples = CollectColourSamples(image, training, num_labels, markers, options);
  ColourBands bands;
  if (samples.bottom >= samples.top && options.colour_bands > 1) {
    bands.count = options.colour_bands;
    bands.top = samples.top;
    bands.height = static_cast<double>(samples.bottom - samples.top + 1) / bands.count;
  }
  const ColourModels models = FitColourModels(std::move(samples), bands, options);
  LabelCostVolume volume{image.cols, image.rows, num_labels, {}};
  const size_t n = static_cast<size_t>(image.cols) * image.rows;
  volume.cost.assign(n * num_labels, 0.f);
  tbb::parallel_for(0, image.rows, [&](int y) {
    const int b = bands.Of(y);
    std::vector<double> scratch(num_labels);
    for (int x = 0; x < image.cols; ++x) {
      if (!where.empty() && !where.at<uint8_t>(y, x)) continue;
      const size_t p = static_cast<size_t>(y) * image.cols + x;
      PixelAppearance(models, b, image.at<cv::Vec3b>(y, x), &volume.cost[p], n, scratch.data());
    }
  });
  NormaliseToBest(-std::log(options.min_probability), &volume);
  return volume;
}

LabelCostVolume SemanticCosts(const cv::Mat& initial_labels, int num_labels,
                              const LabelCostOptions& options,
                              const std::vector<double>& label_scores) {
  return SemanticCosts(std::vector<cv::Mat>{initial_labels}, num_labels, options, label_scores);
}

namespace {

// Label l's score (the background's and those past the list's end: 1).
std::vector<double> ScoresOfLabels(const std::vector<double>& label_scores, int num_labels) {
  std::vector<double> s(num_labels, 1.0);
  for (int l = 1; l < num_labels && l < static_cast<int>(label_scores.size()); ++l) {
    U4D_CHECK(label_scores[l] >= 0 && label_scores[l] <= 1,
              "SemanticCosts: label {}'s score must be in [0, 1], got {}", l, label_scores[l]);
    s[l] = label_scores[l];
  }
  return s;
}

}  // namespace

LabelCostVolume SemanticCosts(const std::vector<cv::Mat>& label_maps, int num_labels,
                              const LabelCostOptions& options,
                              const std::vector<double>& label_scores) {
  options.Check();
  U4D_CHECK(!label_maps.empty(), "SemanticCosts: need at least one label map");
  U4D_CHECK(num_labels >= 1, "SemanticCosts: need at least one label");
  const int w = label_maps[0].cols, h = label_maps[0].rows;
  for (const cv::Mat& m : label_maps)
    U4D_CHECK(m.type() == CV_16UC1 && m.cols == w && m.rows == h,
              "SemanticCosts: label maps must be CV_16U {}x{}", w, h);
  const std::vector<double> score = ScoresOfLabels(label_scores, num_labels);
  const size_t n = static_cast<size_t>(w) * h;
  LabelCostVolume volume{w, h, num_labels, {}};
  volume.cost.assign(n * num_labels, 0.f);
  // Signed distance to each label's region in each map: positive inside.
  std::vector<std::vector<cv::Mat>> signed_distance(label_maps.size(),
                                                    std::vector<cv::Mat>(num_labels));
  for (size_t i = 0; i < label_maps.size(); ++i)
    for (int l = 0; l < num_labels; ++l) {
      cv::Mat inside = label_maps[i] == l, outside = label_maps[i] != l, d_in, d_out;
      cv::distanceTransform(inside, d_in, cv::DIST_L2, 3);
      cv::distanceTransform(outside, d_out, cv::DIST_L2, 3);
      signed_distance[i][l] = d_in - d_out;
    }
  const double eps = options.min_probability;
  tbb::parallel_for(0, h, [&](int y) {
    std::vector<double> mask(num_labels), distances(label_maps.size());
    for (int x = 0; x < w; ++x) {
      double doubt = 0;  // the masks' weight their scores do not give them
      for (int l = 0; l < num_labels; ++l) {
        // Inside pixels are at distance >= 1 from the boundary, outside <= -1
        // (distanceTransform counts to the nearest other pixel). Several maps:
        // the median of their signed distances (the majority's boundary).
        for (size_t i = 0; i < label_maps.size(); ++i) {
          const double s = signed_distance[i][l].at<float>(y, x);
          distances[i] = s > 0 ? s - 0.5 : s + 0.5;
        }
        std::sort(distances.begin(), distances.end());
        const size_t m = distances.size();
        const double inside =
            m % 2 == 1 ? distances[m / 2] : 0.5 * (distances[m / 2 - 1] + distances[m / 2]);
        mask[l] = 1.0 / (1.0 + std::exp(-inside / options.mask_softness_px));
        doubt += (1 - score[l]) * mask[l];
      }
      const size_t p = static_cast<size_t>(y) * w + x;
      double sum = 0;
      for (int l = 0; l < num_labels; ++l) {
        mask[l] = eps + score[l] * mask[l] + doubt / num_labels;
        sum += mask[l];
      }
      for (int l = 0; l < num_labels; ++l)
        volume.cost[l * n + p] = static_cast<float>(-std::log(mask[l] / sum));
    }
  });
  NormaliseToBest(-std::log(eps), &volume);
  return volume;
}

std::vector<double> LabelScores(const cv::Mat& labels, const cv::Mat& scores, int num_labels) {
  std::vector<double> mean(std::max(num_labels, 1), 1.0);
  if (scores.empty()) return mean;
  U4D_CHECK(
      labels.type() == CV_16UC1 && scores.type() == CV_32FC1 && labels.size() == scores.size(),
      "LabelScores: labels must be CV_16U and scores CV_32F of the same size");
  std::vector<double> sum(mean.size(), 0);
  std::vector<int> count(mean.size(), 0);
  for (int y = 0; y < labels.rows; ++y) {
    const uint16_t* l = labels.ptr<uint16_t>(y);
    const float* s = scores.ptr<float>(y);
    for (int x = 0; x < labels.cols; ++x)
      if (l[x] > 0 && l[x] < num_labels) sum[l[x]] += s[x], ++count[l[x]];
  }
  for (size_t l = 1; l < mean.size(); ++l)
    if (count[l] > 0) mean[l] = std::clamp(sum[l] / count[l], 0.0, 1.0);
  return mean;
}

void RelaxSemanticCosts(const cv::Mat& initial_labels, const cv::Mat& support,
                        LabelCostVolume* semantic) {
  const int w = semantic->width, h = semantic->height;
  U4D_CHECK(initial_labels.type() == CV_16UC1 && support.type() == CV_16UC1 &&
                initial_labels.cols == w && initial_labels.rows == h &&
                support.size() == initial_labels.size(),
            "RelaxSemanticCosts: labels and support must be CV_16U {}x{}", w, h);
  const size_t n = static_cast<size_t>(w) * h;
  for (size_t p = 0; p < n; ++p) {
    const int o = support.ptr<uint16_t>()[p];
    const int initial = initial_labels.ptr<uint16_t>()[p];
    if (o == 0 || o >= semantic->num_labels || initial >= semantic->num_labels) continue;
    float& cost = semantic->cost[o * n + p];
    cost = std::min(cost, semantic->cost[initial * n + p]);
  }
}

void TrustConfirmedLabels(const cv::Mat& confirmed, const cv::Mat& alone,
                          const std::vector<bool>& held, LabelCostVolume* appearance) {
  const int w = appearance->width, h = appearance->height;
  U4D_CHECK(confirmed.type() == CV_16UC1 && confirmed.cols == w && confirmed.rows == h,
            "TrustConfirmedLabels: the confirmed labels must be CV_16U {}x{}", w, h);
  U4D_CHECK(alone.empty() || (alone.type() == CV_8UC1 && alone.size() == confirmed.size()),
            "TrustConfirmedLabels: `alone` must be empty or CV_8U {}x{}", w, h);
  const size_t n = static_cast<size_t>(w) * h;
  for (size_t p = 0; p < n; ++p) {
    const int o = confirmed.ptr<uint16_t>()[p];
    if (o == 0 || o >= appearance->num_labels) continue;
    float& cost = appearance->cost[o * n + p];
    const bool no_other_hull = !alone.empty() && alone.ptr<uint8_t>()[p];
    for (int l = 0; l < appearance->num_labels; ++l)
      if (l == 0 || (no_other_hull && l < static_cast<int>(held.size()) && held[l]))
        cost = std::min(cost, appearance->cost[l * n + p]);
  }
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
