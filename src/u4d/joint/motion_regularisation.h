// E_r(l, m), the motion regularisation of the joint energy (paper Sec. 2.1.4,
// "Motion regularisation term"), per 8-neighbour pair (p, q) of the region of interest:
//
//   λ_r E_r = w_pq ρ_m(m_p − m_q)
//   ρ_m(Δm) = min(||Δm||², τ_m²) / τ_m²   (quadratic, the paper's squared difference)
//           = min(||Δm||, τ_m) / τ_m      (linear: a metric, every expansion move submodular)
//   w_pq    = (w_p + w_q) / 2 · c_pq      (c_pq, the colour contrast of E_c, when edge-aware)
//   w_p     = λ_r (1 + λ_r^L e_r^L(p) + λ_r^A e_r^A(p))
//   e_r^X(p) = mean − min of E_X over p's 3x3 window at the initial labels (X = L: E_sem,
//              A: E_a), fixed for the whole optimisation so the energy is one function.
//
// At a label boundary (l_p ≠ l_q) the pair costs what MotionRegBoundary says (joint_view.h,
// the header comment, explains the default).
#pragma once

#include <algorithm>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/joint/label_costs.h"
#include "u4d/joint/parameters.h"

namespace u4d {

// How E_r treats a neighbour pair with different instance labels (see the
// joint_view.h header comment and docs/joint.md, "Choices where the paper is
// not explicit").
enum class MotionRegBoundary {
  kFree,           // the paper read literally: [l_p = l_q] w ρ(Δm); a label cut removes E_r
  kDiscontinuity,  // a label boundary is a motion discontinuity: it pays the truncated
                   // maximum w (so a cut never lowers E_r); same label: w ρ(Δm)
  kIgnoreLabels,   // (default) w ρ(Δm) for every pair: E_r does not depend on the labels
};

struct MotionRegTerm {
  double truncation_px = 4;  // τ_m, pixels
  bool quadratic = true;     // ρ_m quadratic (true) or linear (false)
  bool edge_aware = true;    // w_pq multiplied by c_pq
  MotionRegBoundary boundary = MotionRegBoundary::kIgnoreLabels;

  // ρ_m(m_p − m_q), in [0, 1].
  double Rho(const Eigen::Vector2f& mp, const Eigen::Vector2f& mq) const {
    const double tau = truncation_px;
    if (quadratic) return std::min((mp - mq).squaredNorm() / (tau * tau), 1.0);
    return std::min(static_cast<double>((mp - mq).norm()), tau) / tau;
  }
  // max over y of Rho(from, y) − Rho(to, y) (mrf::GridEnergy::PairwiseDecreaseBound).
  double RhoDecreaseBound(const Eigen::Vector2f& from, const Eigen::Vector2f& to) const;
  // w_pq from the pixels' weights w_p, w_q and the pair's colour contrast c_pq
  // (read only when edge_aware).
  double PairWeight(float weight_p, float weight_q, float colour_contrast) const {
    double wr = 0.5 * (weight_p + weight_q);
    if (edge_aware) wr *= colour_contrast;
    return wr;
  }
  // λ_r E_r of one pair with weight w_pq, labels l_p, l_q and motions m_p, m_q.
  double Cost(double pair_weight, int label_p, int label_q, const Eigen::Vector2f& mp,
              const Eigen::Vector2f& mq) const {
    switch (boundary) {
      case MotionRegBoundary::kFree:
        return label_p == label_q ? pair_weight * Rho(mp, mq) : 0.0;
      case MotionRegBoundary::kDiscontinuity:
        return pair_weight * (label_p == label_q ? Rho(mp, mq) : 1.0);
      case MotionRegBoundary::kIgnoreLabels:
        return pair_weight * Rho(mp, mq);
    }
    return 0.0;
  }
  // The part of Cost that multiplies Rho at these labels: w_pq, or 0 where the
  // pair's cost does not depend on the motions (a label boundary unless kIgnoreLabels).
  double MotionDependentWeight(double pair_weight, int label_p, int label_q) const {
    if (boundary != MotionRegBoundary::kIgnoreLabels && label_p != label_q) return 0;
    return pair_weight;
  }
};

// e_r^X(p): mean minus min of a label cost over p's 3x3 window (clipped at the
// border), each pixel's cost at its label in `labels` (CV_16U).
std::vector<float> WindowSpread(const LabelCostVolume& volume, const cv::Mat& labels);

// w_p = λ_r (1 + λ_r^L e_r^L(p) + λ_r^A e_r^A(p)) per pixel, e_r^L from `semantic`
// (E_sem) and e_r^A from `appearance` (E_a) at `labels`.
std::vector<float> MotionRegPixelWeights(const LabelCostVolume& semantic,
                                         const LabelCostVolume& appearance, const cv::Mat& labels,
                                         const JointWeights& weights);

}  // namespace u4d
