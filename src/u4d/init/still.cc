// Still parts of subjects who stay in place (init.h, step 5): GrabCut in
// the convex hull of the background's temporal envelope.
#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "u4d/init/init.h"
#include "u4d/init/init_internal.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

cv::Mat Disc(int r) {
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
}

// Gradient magnitude of the grey image (Sobel 3x3 after a light blur).
cv::Mat GradientMagnitude(const cv::Mat& bgr) {
  cv::Mat grey, gx, gy, mag;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::GaussianBlur(grey, grey, cv::Size(3, 3), 0.8);
  cv::Sobel(grey, gx, CV_32F, 1, 0, 3);
  cv::Sobel(grey, gy, CV_32F, 0, 1, 3);
  cv::magnitude(gx, gy, mag);
  return mag;
}

}  // namespace

cv::Mat RemoveGhosts(const cv::Mat& image_bgr, const cv::Mat& foreground,
                     const BackgroundModel& background, const InitOptions& options,
                     cv::Mat* ghosts) {
  options.Check();
  CheckImageAndForeground("RemoveGhosts", image_bgr, foreground);
  U4D_CHECK(!background.Empty() && background.lab.size() == image_bgr.size(),
            "RemoveGhosts: the background is {}x{}, the image {}x{}", background.Width(),
            background.Height(), image_bgr.cols, image_bgr.rows);
  cv::Mat labels;
  const int n = cv::connectedComponents(foreground, labels, 8, CV_32S);
  if (ghosts != nullptr) *ghosts = cv::Mat::zeros(foreground.size(), CV_8UC1);
  if (n <= 1) return foreground.clone();
  // The band just inside each component's outline (2 px per 360 px of height).
  const int r = std::max(2, (foreground.rows + 90) / 180);
  cv::Mat inner;
  cv::erode(foreground, inner, Disc(r));
  const cv::Mat band = foreground & ~inner;
  const cv::Mat gi = GradientMagnitude(image_bgr), gb = GradientMagnitude(background.bgr);
  std::vector<double> sum_i(n, 0.0), sum_b(n, 0.0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const uint8_t* m = band.ptr<uint8_t>(y);
    const float* a = gi.ptr<float>(y);
    const float* b = gb.ptr<float>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (!m[x] || l[x] <= 0) continue;
      sum_i[l[x]] += a[x];
      sum_b[l[x]] += b[x];
    }
  }
  std::vector<uint8_t> ghost(n, 0);
  for (int i = 1; i < n; ++i) ghost[i] = sum_i[i] < options.still.ghost_edge_ratio * sum_b[i];
  cv::Mat out = foreground.clone();
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x)
      if (l[x] > 0 && ghost[l[x]]) {
        o[x] = 0;
        if (ghosts != nullptr) ghosts->at<uint8_t>(y, x) = 255;
      }
  }
  return out;
}

cv::Mat FillStillSubjects(const cv::Mat& image_bgr, const cv::Mat& foreground,
                          const BackgroundModel& background, const InitOptions& options) {
  options.Check();
  CheckImageAndForeground("FillStillSubjects", image_bgr, foreground);
  if (options.still.still_grabcut_iterations <= 0 || background.envelope.empty())
    return foreground.clone();
  U4D_CHECK(background.envelope.size() == image_bgr.size() && background.envelope.type() == CV_8UC1,
            "FillStillSubjects: the background's envelope is {}x{}, the image {}x{}",
            background.envelope.cols, background.envelope.rows, image_bgr.cols, image_bgr.rows);
  if (cv::countNonZero(background.envelope) == 0 || cv::countNonZero(foreground) == 0)
    return foreground.clone();

  // Reduced resolution (GrabCut's cost grows with the pixels; thin limbs are
  // sure foreground at full resolution and are kept from `foreground`).
  const double s = std::min(1.0, static_cast<double>(options.still.still_max_side) /
                                     std::max(image_bgr.cols, image_bgr.rows));
  const cv::Size sz(std::max(1, static_cast<int>(std::lround(image_bgr.cols * s))),
                    std::max(1, static_cast<int>(std::lround(image_bgr.rows * s))));
  cv::Mat img, fg, env;
  cv::resize(image_bgr, img, sz, 0, 0, cv::INTER_AREA);
  cv::resize(foreground, fg, sz, 0, 0, cv::INTER_AREA);
  fg = fg >= 128;
  cv::resize(background.envelope, env, sz, 0, 0, cv::INTER_AREA);
  env = env > 0;

  // Hulls of the (dilated) envelope components that this frame's foreground touches.
  const int rd =
      std::max(1, static_cast<int>(std::lround(options.still.envelope_dilation * sz.height)));
  cv::dilate(env, env, Disc(rd));
  cv::Mat labels;
  const int n = cv::connectedComponents(env, labels, 8, CV_32S);
  std::vector<uint8_t> touched(n, 0);
  std::vector<std::vector<cv::Point>> points(n);
  for (int y = 0; y < sz.height; ++y) {
    const int* l = labels.ptr<int>(y);
    const uint8_t* f = fg.ptr<uint8_t>(y);
    for (int x = 0; x < sz.width; ++x) {
      if (l[x] <= 0) continue;
      points[l[x]].emplace_back(x, y);
      if (f[x]) touched[l[x]] = 1;
    }
  }
  cv::Mat hull = cv::Mat::zeros(sz, CV_8UC1);
  for (int i = 1; i < n; ++i) {
    if (!touched[i]) continue;
    std::vector<cv::Point> h;
    cv::convexHull(points[i], h);
    cv::fillConvexPoly(hull, h, cv::Scalar(255));
  }
  if (cv::countNonZero(hull) == 0) return foreground.clone();

  // Seeds: sure background beyond the ring, probable background in the ring,
  // probable foreground in the hulls, sure foreground where step 2 found it.
  const int rr =
      std::max(2, static_cast<int>(std::lround(options.still.envelope_ring * sz.height)));
  cv::Mat near;
  cv::dilate(hull, near, Disc(rr));
  cv::Mat gc(sz, CV_8UC1, cv::Scalar(cv::GC_BGD));
  gc.setTo(cv::GC_PR_BGD, near);
  gc.setTo(cv::GC_PR_FGD, hull);
  gc.setTo(cv::GC_FGD, fg);
  // GrabCut in a box around the ring with as much sure background again
  // (the colour model of the background is the subject's surroundings).
  cv::Rect roi = cv::boundingRect(near | fg);
  roi = cv::Rect(roi.x - roi.width / 2, roi.y - roi.height / 4, 2 * roi.width,
                 roi.height + roi.height / 2) &
        cv::Rect(0, 0, sz.width, sz.height);
  cv::Mat g = gc(roi).clone();
  const cv::Mat image_roi = img(roi);
  // Colour models (GrabCut's 5-component GMMs) from the sure pixels only:
  // the subject's moving parts and the surroundings beyond the ring. Learnt
  // from the whole mask, the foreground model would start from the hull,
  // which holds much background when the subject also walks. The sure
  // pixels are gathered into one row so that grabCut's initialisation sees
  // nothing else.
  std::vector<cv::Vec3b> colours;
  std::vector<uint8_t> labels_fb;
  int n_fg = 0, n_bg = 0;
  for (int y = 0; y < g.rows; ++y)
    for (int x = 0; x < g.cols; ++x) {
      const uint8_t l = g.at<uint8_t>(y, x);
      if (l != cv::GC_FGD && l != cv::GC_BGD) continue;
      colours.push_back(image_roi.at<cv::Vec3b>(y, x));
      labels_fb.push_back(l);
      (l == cv::GC_FGD ? n_fg : n_bg)++;
    }
  // k-means of 5 components needs a few samples of each.
  constexpr int kMinSamples = 50;
  if (n_fg < kMinSamples || n_bg < kMinSamples) return foreground.clone();
  cv::Mat learn_img(1, static_cast<int>(colours.size()), CV_8UC3, colours.data());
  cv::Mat learn_mask(1, static_cast<int>(labels_fb.size()), CV_8UC1, labels_fb.data());
  cv::Mat bgd_model, fgd_model;
  cv::Mat in_model;
  {
    const FixedGrabCutSeed seed;
    cv::grabCut(learn_img, learn_mask, cv::Rect(), bgd_model, fgd_model, 0, cv::GC_INIT_WITH_MASK);
    // One graph cut with these models, then GrabCut's alternation (models
    // re-learnt from the labels) for the remaining iterations.
    cv::grabCut(image_roi, g, cv::Rect(), bgd_model, fgd_model, 1, cv::GC_EVAL_FREEZE_MODEL);
    if (options.still.still_grabcut_iterations > 1)
      cv::grabCut(image_roi, g, cv::Rect(), bgd_model, fgd_model,
                  options.still.still_grabcut_iterations - 1, cv::GC_EVAL);
    if (options.still.still_require_model) {
      // The same cut on the background model, with the final colour models:
      // a subject can only be missing from step 2's foreground where the model
      // itself shows the subject. Where it shows the empty scene (a good
      // background, or a subject who walks) nothing is added.
      cv::Mat gm = gc(roi).clone();
      gm.setTo(cv::GC_PR_FGD, gm == cv::GC_FGD);
      cv::Mat model_bgr;
      cv::resize(background.bgr, model_bgr, sz, 0, 0, cv::INTER_AREA);
      cv::grabCut(model_bgr(roi), gm, cv::Rect(), bgd_model, fgd_model, 1,
                  cv::GC_EVAL_FREEZE_MODEL);
      in_model = gm == cv::GC_PR_FGD;
    }
  }
  cv::Mat added = cv::Mat::zeros(sz, CV_8UC1);
  cv::Mat cut = (g == cv::GC_FGD) | (g == cv::GC_PR_FGD);
  if (!in_model.empty()) cut &= in_model;
  added(roi).setTo(255, cut);
  added &= hull;
  cv::Mat up;
  cv::resize(added, up, foreground.size(), 0, 0, cv::INTER_LINEAR);
  return CleanMask(foreground | (up >= 128), options);
}

}  // namespace u4d
