#include "u4d/baselines/grabcut_baseline.h"

#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d::baselines {
namespace {

// Likelihood of a BGR colour under a cv::grabCut GMM model (1 x 65 CV_64F:
// 5 weights, 5 means of 3, 5 covariances of 9; layout of OpenCV's grabcut.cpp).
double GmmLikelihood(const cv::Mat& model, const cv::Vec3b& colour) {
  constexpr int kComponents = 5;
  const double* coefs = model.ptr<double>(0);
  const double* means = coefs + kComponents;
  const double* covs = means + 3 * kComponents;
  const Eigen::Vector3d c(colour[0], colour[1], colour[2]);
  double sum = 0;
  for (int k = 0; k < kComponents; ++k) {
    if (coefs[k] <= 0) continue;
    const Eigen::Vector3d mu(means[3 * k], means[3 * k + 1], means[3 * k + 2]);
    const Eigen::Matrix3d cov =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(covs + 9 * k);
    const double det = cov.determinant();
    if (!(det > 0)) continue;
    const Eigen::Vector3d d = c - mu;
    const double mahal = d.dot(cov.inverse() * d);
    sum += coefs[k] / std::sqrt(det) * std::exp(-0.5 * mahal);
  }
  return sum;
}

struct Refined {
  int id = 0;
  cv::Rect box;
  cv::Mat fg;   // CV_8U in the box, 1 = foreground
  cv::Mat fgd;  // foreground GMM; empty when the initial mask was kept
};

}  // namespace

void GrabCutOptions::Check() const {
  U4D_CHECK(iterations >= 1, "GrabCutOptions.iterations must be >= 1, got {}", iterations);
  U4D_CHECK(band_px >= 1, "GrabCutOptions.band_px must be >= 1, got {}", band_px);
  U4D_CHECK(pad_px >= band_px, "GrabCutOptions.pad_px must be >= band_px ({}), got {}", band_px,
            pad_px);
}

cv::Mat GrabCutInstances(const cv::Mat& image, const cv::Mat& initial_ids,
                         const GrabCutOptions& options) {
  options.Check();
  U4D_CHECK(!image.empty() && image.type() == CV_8UC3,
            "GrabCutInstances: image must be a non-empty BGR 8-bit image, got type {} {}x{}",
            image.type(), image.cols, image.rows);
  U4D_CHECK(initial_ids.type() == CV_16UC1 && initial_ids.size() == image.size(),
            "GrabCutInstances: initial_ids must be CV_16UC1 {}x{}, got type {} {}x{}", image.cols,
            image.rows, initial_ids.type(), initial_ids.cols, initial_ids.rows);
  std::map<int, int> area;
  for (int y = 0; y < initial_ids.rows; ++y)
    for (int x = 0; x < initial_ids.cols; ++x) {
      const int id = initial_ids.at<uint16_t>(y, x);
      if (id != 0) ++area[id];
    }
  const cv::Rect full(0, 0, image.cols, image.rows);
  const cv::Mat band_kernel = cv::getStructuringElement(
      cv::MORPH_ELLIPSE, cv::Size(2 * options.band_px + 1, 2 * options.band_px + 1));
  std::vector<Refined> refined;
  for (const auto& [id, n] : area) {
    const cv::Mat mask = initial_ids == id;  // 255 inside
    cv::Rect box = cv::boundingRect(mask);
    box = cv::Rect(box.x - options.pad_px, box.y - options.pad_px, box.width + 2 * options.pad_px,
                   box.height + 2 * options.pad_px) &
          full;
    const cv::Mat m = mask(box), ids = initial_ids(box);
    cv::Mat band;
    cv::dilate(m, band, band_kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::Mat seed(box.size(), CV_8U, cv::Scalar(cv::GC_BGD));
    seed.setTo(cv::GC_PR_BGD, band);
    const cv::Mat others = (ids != id) & (ids != 0);
    seed.setTo(options.others_probable_background ? cv::GC_PR_BGD : cv::GC_BGD, others);
    seed.setTo(cv::GC_PR_FGD, m);
    Refined r;
    r.id = id;
    r.box = box;
    cv::Mat bgd, fgd;
    try {
      cv::grabCut(image(box), seed, cv::Rect(), bgd, fgd, options.iterations,
                  cv::GC_INIT_WITH_MASK);
      r.fg = (seed == cv::GC_FGD) | (seed == cv::GC_PR_FGD);
      r.fgd = fgd;
    } catch (const cv::Exception&) {
      r.fg.release();
    }
    if (r.fg.empty() || cv::countNonZero(r.fg) == 0) {
      r.fg = m.clone();
      r.fgd.release();
    }
    r.fg = r.fg / 255;
    refined.push_back(std::move(r));
  }

  // Resolve: the original owner, else the largest foreground likelihood.
  cv::Mat out(initial_ids.size(), CV_16UC1, cv::Scalar(0));
  cv::Mat best(initial_ids.size(), CV_64F, cv::Scalar(-1.0));
  for (const Refined& r : refined) {
    for (int y = 0; y < r.box.height; ++y)
      for (int x = 0; x < r.box.width; ++x) {
        if (!r.fg.at<uint8_t>(y, x)) continue;
        const int gx = x + r.box.x, gy = y + r.box.y;
        const int original = initial_ids.at<uint16_t>(gy, gx);
        double score;
        if (original == r.id) {
          score = 1e300;  // the original owner always wins
        } else if (!r.fgd.empty()) {
          score = GmmLikelihood(r.fgd, image.at<cv::Vec3b>(gy, gx));
        } else {
          score = 0;
        }
        if (score > best.at<double>(gy, gx)) {
          best.at<double>(gy, gx) = score;
          out.at<uint16_t>(gy, gx) = static_cast<uint16_t>(r.id);
        }
      }
  }
  return out;
}

}  // namespace u4d::baselines
