// The label (instance) unary terms of the joint energy and the colour
// contrast weights (paper Sec. "Unary terms"; Appendix A for E_c).
//
// Labels: 0 is the background, k >= 1 the object ids (the same in every view).
//
// E_a(l) — appearance: −log P(I_p | l) under a colour GMM per label
//   (10 components, as the paper), learned from the initial masks of the
//   temporal neighbourhood ψ_T (frames t−1, t, t+1 of the view) plus the
//   sparse foreground markers (projected sparse 3D points of the object).
//   The models can be local in height (`colour_bands`): a person's shoes or
//   hands are a small share of their colours, and the floor beside them a
//   large share of the background's, so one model over the whole person
//   gives the shoes so little weight that E_a takes them even from true
//   masks. With B > 1 bands of equal height over the rows the view's objects
//   span (each fitted from the samples within one band height of its centre,
//   so neighbours overlap), a pixel's object-or-background odds are those of
//   its band's models: the best object's band likelihood against the
//   background's. Which object is decided by the objects' whole models,
//   which hold each person's every colour: where a detector merged two
//   people the merged pixels are a large share of one band of the one
//   person, and a small share of the whole. So for object l at colour c in
//   band b: −log( max_k P_b(c | k) · P(c | l) / max_k P(c | k) ); for the
//   background −log P_b(c | 0). A band with too few samples of a label's
//   own uses the label's whole model, and an object without its own band
//   model there is weighed against the background's whole model (a band
//   model fits its few colours more tightly, and would win by its locality
//   alone). A part the view's mask lacks would be a large share of its
//   band's background; the other views' hull support keeps it out of the
//   background's samples (joint/frame_setup.cc AddHullSupport).
// E_sem(l) — semantic: −log P_sem(l | p) where P_sem is a soft version of the
//   initial instance masks: a logistic function of the signed distance to each
//   label's mask boundary, floored at `min_probability` and normalised over
//   the labels. (Mask R-CNN-style detectors give hard masks; the softening
//   expresses that their boundaries are uncertain by a few pixels.) A
//   detector's score s_l for label l's mask is its probability: P_sem puts
//   s_l of the mask's weight on l and spreads the rest, 1 − s_l, evenly over
//   every label, so a doubtful detection (a false positive, two people
//   merged) constrains less. Scores of 1 give the hard masks' P_sem.
//
// Normalisation: both terms are negative log ratios to the best label at the
// pixel, divided by log(1 / min_probability) and clamped to [0, 1], so a
// label 1/min_probability times less likely than the best costs 1.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace u4d {

// A Gaussian mixture over BGR colours in [0, 255].
struct ColorGmm {
  std::vector<double> weights;
  std::vector<Eigen::Vector3d> means;
  std::vector<Eigen::Matrix3d> inv_covs;
  std::vector<double> log_norms;  // log(weight / sqrt((2π)^3 det Σ))
  double LogLikelihood(const cv::Vec3b& bgr) const;
  bool Empty() const { return weights.empty(); }
};

// EM fit (full covariances; cv::ml::EM's algorithm written out, label_costs.cc
// TrainGmm) with at most `components`; fewer when
// there are few samples (>= 8 samples per component). A tiny diagonal term
// keeps covariances invertible. Throws u4d::Error when `samples` is empty.
ColorGmm FitColorGmm(const std::vector<cv::Vec3b>& samples, int components, uint64_t seed);

struct LabelCostOptions {
  int gmm_components = 10;           // paper: GMMs with 10 components
  int max_samples_per_label = 4000;  // colour samples used to fit a GMM (random subset)
  int background_band_px = 25;  // background samples: within this distance of the ROI's objects
  // E_a's bands in height (above; 1 = one model per label, the paper's).
  // Four bands cut a standing person into head and shoulders, torso, thighs
  // and lower legs with feet: parts whose clothes differ (docs/joint.md).
  int colour_bands = 4;
  int max_samples_per_band = 1000;  // colour samples used to fit a band's GMM (random subset)
  // A band's model of a label needs this many of the view's own samples in
  // the band (else the label's whole model): ~20 per component of a 10-GMM.
  int min_band_samples = 200;
  // Colour samples only from pixels at least this far inside their label's
  // initial mask (the band where a detector's mask boundary errs: a dilated
  // mask's rim is background colour); 0 = every pixel, for masks the capture
  // trusts (a thin part is mostly rim: docs/joint.md).
  int appearance_inset_px = 2;
  double mask_softness_px = 2.0;  // logistic scale of P_sem across a mask boundary (pixels)
  double min_probability =
      0.01;  // floor of P_sem and of the likelihood ratio (sets the normalisation)
  // E_sem weighs each initial mask by its detector score (SemanticCosts'
  // `label_scores`); false: every mask is certain (score 1).
  bool detector_scores = true;
  uint64_t seed = 7;  // sampling and EM initialisation
  void Check() const;
};

// Per-pixel costs of every label, label-major: cost[l * W * H + pixel].
struct LabelCostVolume {
  int width = 0, height = 0, num_labels = 0;
  std::vector<float> cost;
  float At(int pixel, int label) const {
    return cost[static_cast<size_t>(label) * width * height + pixel];
  }
};

// One training image of the temporal neighbourhood: an image with its
// initial label map (CV_16U, label ids as above, 0 = background). Pixels
// labelled kUnsampledLabel (or any label >= the number of labels) give no
// colour sample: neither background nor an object.
inline constexpr uint16_t kUnsampledLabel = 65535;
struct LabelledImage {
  cv::Mat image;   // BGR 8-bit
  cv::Mat labels;  // CV_16U
  // Another view's image at t, lending colour samples of an object the
  // view's own labels lack (joint/frame_setup.h): E_a only, not E_sem. Only
  // its objects lend samples: its background (label 0) gives none.
  bool other_view = false;
};

// E_a's colour samples come from initial labels whose object ids were linked
// across views and frames (ψ_T's t−1 and t+1), and linking can swap two
// people in a view (a detector renumbers its instances per image). Mixed
// samples give both people both colours, and one then takes the other.
// ObjectColourHistograms: each object's colours over `images` (cv::calcHist,
// 8 bins per channel; an empty Mat for an object without pixels there).
// DropSwappedSamples: in each of `training`'s images (not another view's), two
// objects l and k whose pixels each look more like the other's `reference`
// than like their own (the Bhattacharyya distance, cv::compareHist) were
// swapped there: their pixels become kUnsampledLabel. Throws on a size or
// type mismatch.
using ColourHistograms = std::vector<cv::Mat>;
ColourHistograms ObjectColourHistograms(const std::vector<LabelledImage>& images, int num_labels);
void DropSwappedSamples(const ColourHistograms& reference, std::vector<LabelledImage>* training);

// E_a for labels 0..num_labels-1 on `image`. `markers[l]` are extra
// foreground pixels of label l in `image` (sparse markers; may be empty).
// Labels without any sample get cost 1 everywhere. `where` (CV_8U, the
// image's size; empty = every pixel) limits the pixels the colour models are
// evaluated at: elsewhere every label costs 0. The models are learnt from
// the whole of `training` either way. Throws on size or type mismatch.
LabelCostVolume AppearanceCosts(const cv::Mat& image, const std::vector<LabelledImage>& training,
                                int num_labels,
                                const std::vector<std::vector<Eigen::Vector2d>>& markers,
                                const LabelCostOptions& options = {},
                                const cv::Mat& where = cv::Mat());

// E_sem for labels 0..num_labels-1 from the initial label map (CV_16U).
// `label_scores[l]` is the detector's score of label l's mask, in [0, 1]
// (empty, or a label beyond its end: 1; the background's is always 1).
LabelCostVolume SemanticCosts(const cv::Mat& initial_labels, int num_labels,
                              const LabelCostOptions& options = {},
                              const std::vector<double>& label_scores = {});
// E_sem from several label maps of the same pixels (CV_16U, same size): the
// paper sums E_sem over the temporal neighbourhood ψ_T; here the maps (e.g.
// the initial masks of t−1, t, t+1 carried to t) are combined before the
// softening: each label's signed distance to its mask boundary is the median
// over the maps, so with three maps the boundary is the majority's and one
// map's error (a boundary dilated by a few pixels, a dropped forearm) is
// outvoted where the others agree. (Averaging the soft masks, or summing
// their −log, does not outvote it near the boundary: a pixel 1 px outside the
// truth is 4 px inside a mask dilated by 5 px, and that one confident map
// wins against two that are just outside.) One map gives the function above.
// Throws on an empty list, a size or type mismatch, or a score outside [0, 1].
LabelCostVolume SemanticCosts(const std::vector<cv::Mat>& label_maps, int num_labels,
                              const LabelCostOptions& options = {},
                              const std::vector<double>& label_scores = {});

// Each label's score in a view: the mean of `scores` (CV_32F, the detector's
// score at each pixel of its masks, 1 where it has none) over the label's
// pixels in `labels` (CV_16U, the same size). Labels without a pixel, and the
// background, get 1. Empty `scores`: every label 1. Throws on a size or type
// mismatch.
std::vector<double> LabelScores(const cv::Mat& labels, const cv::Mat& scores, int num_labels);

// E_sem where the other views contradict the detector: at each pixel whose
// `support` (CV_16U, hull_support.h: the view's background, or a person the
// object claims) names an object o in [1, num_labels), o's cost is lowered to
// that of the pixel's `initial_labels` label, so E_sem prefers neither and
// E_a, E_c, E_d (and E_p) decide. Throws on a size or type mismatch.
void RelaxSemanticCosts(const cv::Mat& initial_labels, const cv::Mat& support,
                        LabelCostVolume* semantic);

// E_a where the other views confirm the view's label (hull_support.h
// HullConfirmation): at each pixel of `confirmed` (CV_16U) naming an object o
// in [1, num_labels), o's cost is lowered to the background's, and where
// `alone` (CV_8U; empty = nowhere) says no other object's hull is on the ray,
// to the lowest of the background's and the `held` objects' (those the view
// holds, whose hulls were cast). The colour models then prefer none of them
// there and E_sem, E_c, E_d (and E_p) decide: a colour the background shares
// (a white shoe on white tiles, a sleeve in a shadow) or another person far
// from there shares (grey shoes) does not take a part every view agrees on.
// Where people overlap, and against an object the view does not hold
// (missed or merged with another here, its hull not cast), the colours still
// decide between the objects. Throws on a size or type mismatch.
void TrustConfirmedLabels(const cv::Mat& confirmed, const cv::Mat& alone,
                          const std::vector<bool>& held, LabelCostVolume* appearance);

// Colour-contrast weight of each neighbour pair for E_c:
// exp(−||I_p − I_q||² / (2β)) / |p − q|, β the mean of ||I_p − I_q||² over
// the pairs (as GrabCut). `pairs` as mrf::NeighbourPairs.
std::vector<float> ContrastWeights(const cv::Mat& image,
                                   const std::vector<std::pair<int, int>>& pairs);

// Semantic-contrast weight of each pair (the λ_cl part of E_c): the same
// form on the per-label semantic cost vectors instead of colours, so a label
// change is cheap where the initial segmentation changes.
std::vector<float> SemanticContrastWeights(const LabelCostVolume& semantic,
                                           const std::vector<std::pair<int, int>>& pairs);

}  // namespace u4d
