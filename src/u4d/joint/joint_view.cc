#include "u4d/joint/joint_view.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <ctime>
#include <limits>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/optflow.hpp>
#include <opencv2/video/tracking.hpp>

#include "u4d/mrf/expansion.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

namespace u4d {
namespace {

// Index of the forward neighbour direction q - p (p < q, 8-connected):
// (1,0) -> 0, (-1,1) -> 1, (0,1) -> 2, (1,1) -> 3.
inline int Direction(int p, int q, int width) {
  const int d = q - p;
  if (d == 1) return 0;
  if (d == width - 1) return 1;
  if (d == width) return 2;
  return 3;
}

// All precomputed terms of one view's energy and the current labelling.
struct Problem {
  const JointViewOptions* o = nullptr;
  int width = 0, height = 0, n = 0;
  int num_labels = 1;
  const Camera* camera_t = nullptr;
  const Camera* camera_t1 = nullptr;
  mrf::GridGraph grid;
  std::vector<std::pair<int, int>> pairs;  // mrf::NeighbourPairs(grid)

  std::vector<float> label_unary;              // [p * num_labels + l], weighted
  std::array<std::vector<float>, 4> contrast;  // λ_c E_c per forward direction
  std::vector<float> reg_weight;               // λ_r w_r(p)
  std::array<std::vector<float>, 4> reg_edge;  // colour contrast weight per forward direction
  DepthCostVolume depth;                       // E_d
  int unknown = 0;                             // the label U (= number of depths)
  // Per pixel, the depth labels it may take besides U (depth_object_ranges):
  // [depth_lo, depth_hi]; empty = every depth.
  std::vector<int16_t> depth_lo, depth_hi;
  bool DepthAllowed(int p, int label) const {
    return label == unknown || depth_lo.empty() || (label >= depth_lo[p] && label <= depth_hi[p]);
  }
  std::vector<int> previous_depth_label;  // temporal E_s; -1 = none
  MotionCostVolume motion;                // E_f
  float flow_scale = 1;                   // normalises E_f to [0, 1]
  PosePriorMap pose;
  bool use_pose = false;
  double pose_2d_share = 0, pose_3d_share = 0;  // λ_p λ_2d / (λ_2d + λ_3d), ...
  std::vector<Eigen::Vector3d> rays;            // world direction per pixel with z = 1 in camera
  Eigen::Vector3d centre;

  std::vector<int> l, d, m;  // the labelling
  // The motion as vectors (pixels) and its raw E_f (incl. e_F^S): equal to
  // motions[m] and the volume's cost in the discrete blocks (SyncMotion),
  // sub-pixel after the fusion stage.
  std::vector<Eigen::Vector2f> mv;
  std::vector<float> fcost;
  void SyncMotion() {
    mv.resize(n);
    fcost.resize(n);
    for (int p = 0; p < n; ++p) {
      mv[p] = motion.motions[m[p]];
      fcost[p] = motion.At(p, m[p]);
    }
  }

  const JointWeights& w() const { return o->weights; }
  const JointTerms& t() const { return o->terms; }

  Eigen::Vector3d Point(int p, int depth_label) const {
    return centre + depth.depths[depth_label] * rays[p];
  }
  Eigen::Vector2d Moved(int p, const Eigen::Vector2f& mp) const {
    return Eigen::Vector2d(p % width + mp.x(), p / width + mp.y());
  }
  double DepthPair(int dp, int dq) const {
    if (dp == unknown || dq == unknown) return dp == dq ? 0.0 : 1.0;
    return std::min<double>(std::abs(dp - dq), o->depth_truncation) / o->depth_truncation;
  }
  // E_p's 3D part (couples d and m, and l with PosePriorOptions::shape_own_label_only: the
  // capsules constrain only the points labelled as their person). It is one term of the
  // energy; each block's unary below includes it once.
  double Pose3d(int p, int ll, int dl, const Eigen::Vector2f& mp) const {
    if (!use_pose || dl == unknown) return 0;
    if (o->pose.shape_own_label_only && pose.object.ptr<uint16_t>()[p] != ll) return 0;
    return pose_3d_share *
           u4d::Pose3dCost(pose, p, Point(p, dl), Moved(p, mp), *camera_t1, o->pose);
  }
  // The unaries without E_p's 3D part.
  double DepthOnlyUnary(int p, int dl) const {
    double e = 0;
    if (t().depth) e += w().depth * (dl == unknown ? depth.unknown_cost : depth.At(p, dl));
    if (t().smooth && !previous_depth_label.empty() && previous_depth_label[p] >= 0)
      e += w().smooth * w().smooth_temporal * DepthPair(dl, previous_depth_label[p]);
    return e;
  }
  double MotionOnlyUnary(int p, const Eigen::Vector2f& mp, float f) const {
    double e = 0;
    if (f >= kForbiddenMotion) return mrf::kInfiniteCost;
    if (t().flow) e += w().flow * f * flow_scale;
    if (use_pose) e += pose_2d_share * PoseMotion2dCost(pose, p, mp, o->pose);
    return e;
  }
  // The energy as a function of one factor at p (the others at the current labelling).
  double DepthUnary(int p, int dl, const Eigen::Vector2f& mp) const {
    return DepthOnlyUnary(p, dl) + Pose3d(p, l[p], dl, mp);
  }
  // Motion mp with raw E_f cost f (volume or FlowFieldCosts, incl. e_F^S).
  double MotionUnary(int p, const Eigen::Vector2f& mp, float f, int dl) const {
    const double e = MotionOnlyUnary(p, mp, f);
    return e >= mrf::kInfiniteCost ? e : e + Pose3d(p, l[p], dl, mp);
  }
  double MotionUnary(int p, int ml, int dl) const {
    return MotionUnary(p, motion.motions[ml], motion.At(p, ml), dl);
  }
  double LabelUnary(int p, int ll) const {
    return label_unary[static_cast<size_t>(p) * num_labels + ll];
  }
  double LabelBlockUnary(int p, int ll) const {
    return LabelUnary(p, ll) + (o->pose.shape_own_label_only ? Pose3d(p, ll, d[p], mv[p]) : 0.0);
  }
  // The pairwise terms with the motions given as vectors (pixels): the label
  // and depth part (E_c, E_s) plus E_r, in this order (the blocks cache the
  // part their factor does not change, which gives the same sums). Pixels
  // outside the region of interest are background with no depth or motion
  // estimated: a pair with one of them has E_c only (E_s against their
  // placeholder depth U would cost the most at every region border, and
  // made the border ring switch to a person label where contrast is low).
  double PairV(int p, int q, int lp, int lq, int dp, int dq, const Eigen::Vector2f& mp,
               const Eigen::Vector2f& mq) const {
    return PairLabelDepth(p, q, lp, lq, dp, dq) + PairMotion(p, q, lp, lq, mp, mq);
  }
  double PairLabelDepth(int p, int q, int lp, int lq, int dp, int dq) const {
    double e = 0;
    if (lp != lq) {
      if (t().contrast) e += contrast[Direction(p, q, width)][p];
    } else if (t().smooth && grid.IsActive(p) && grid.IsActive(q)) {
      e += w().smooth * w().smooth_spatial * DepthPair(dp, dq);
    }
    return e;
  }
  double PairMotion(int p, int q, int lp, int lq, const Eigen::Vector2f& mp,
                    const Eigen::Vector2f& mq) const {
    double e = 0;
    if (t().motion_reg && grid.IsActive(p) && grid.IsActive(q)) {
      const double wr = RegPairWeight(p, q);
      switch (o->motion_reg_boundary) {
        case MotionRegBoundary::kFree:
          if (lp == lq) e += wr * MotionRho(mp, mq);
          break;
        case MotionRegBoundary::kDiscontinuity:
          e += wr * (lp == lq ? MotionRho(mp, mq) : 1.0);
          break;
        case MotionRegBoundary::kIgnoreLabels:
          e += wr * MotionRho(mp, mq);
          break;
      }
    }
    return e;
  }
  // E_r's robust function of a motion difference, in [0, 1].
  double MotionRho(const Eigen::Vector2f& mp, const Eigen::Vector2f& mq) const {
    const double tau = o->motion_truncation_px;
    if (o->motion_reg_quadratic) return std::min((mp - mq).squaredNorm() / (tau * tau), 1.0);
    return std::min(static_cast<double>((mp - mq).norm()), tau) / tau;
  }
  // The weight of E_r's pair p < q at the current labels where it depends on
  // the motions (0 where it does not): PairMotion = weight * MotionRho + a
  // part independent of the motions.
  double MotionRegWeight(int p, int q) const {
    if (!t().motion_reg || !grid.IsActive(p) || !grid.IsActive(q)) return 0;
    if (o->motion_reg_boundary != MotionRegBoundary::kIgnoreLabels && l[p] != l[q]) return 0;
    return RegPairWeight(p, q);
  }
  // λ_r w_r of the pair p < q: the mean of its pixels' weights, edge-aware
  // when motion_reg_edge_aware.
  double RegPairWeight(int p, int q) const {
    double wr = 0.5 * (reg_weight[p] + reg_weight[q]);
    if (o->motion_reg_edge_aware) wr *= reg_edge[Direction(p, q, width)][p];
    return wr;
  }
  // max over y of MotionRho(from, y) - MotionRho(to, y).
  double MotionRhoDecreaseBound(const Eigen::Vector2f& from, const Eigen::Vector2f& to) const {
    const double distance = (from - to).norm() / o->motion_truncation_px;
    return o->motion_reg_quadratic ? mrf::TruncatedQuadraticDecreaseBound(distance)
                                   : mrf::TruncatedLinearDecreaseBound(distance);
  }
  double Energy() const;

  // Per forward pair (index 4 p + Direction(p, q)): the part of PairV that the
  // depth block (E_r at the current l, mv) or the motion and fusion blocks
  // (E_c + E_s at the current l, d) do not change, computed once per block.
  std::vector<double> pair_cache;
  enum class CachedPart { kMotion, kLabelDepth };
  void FillPairCache(CachedPart part) {
    pair_cache.assign(static_cast<size_t>(n) * 4, 0.0);
    constexpr int kDx[4] = {1, -1, 0, 1}, kDy[4] = {0, 1, 1, 1};
    tbb::parallel_for(0, height, [&](int y) {
      for (int x = 0; x < width; ++x) {
        const int p = y * width + x;
        for (int k = 0; k < 4; ++k) {
          const int qx = x + kDx[k], qy = y + kDy[k];
          if (qx < 0 || qx >= width || qy >= height) continue;
          const int q = qy * width + qx;
          pair_cache[static_cast<size_t>(p) * 4 + k] =
              part == CachedPart::kMotion ? PairMotion(p, q, l[p], l[q], mv[p], mv[q])
                                          : PairLabelDepth(p, q, l[p], l[q], d[p], d[q]);
        }
      }
    });
  }
  double Cached(int p, int q) const {
    return pair_cache[static_cast<size_t>(p) * 4 + Direction(p, q, width)];
  }
};

double Problem::Energy() const {
  double e = 0;
  for (int p = 0; p < n; ++p) {
    if (!grid.IsActive(p)) continue;
    e += LabelUnary(p, l[p]) + DepthOnlyUnary(p, d[p]) + MotionOnlyUnary(p, mv[p], fcost[p]) +
         Pose3d(p, l[p], d[p], mv[p]);
  }
  for (const auto& [p, q] : pairs)
    if (grid.IsActive(p) || grid.IsActive(q))
      e += PairV(p, q, l[p], l[q], d[p], d[q], mv[p], mv[q]);
  return e;
}

// The energy as a function of one factor, the others fixed.
struct LabelBlock : mrf::GridEnergy {
  const Problem& pr;
  explicit LabelBlock(const Problem& p) : pr(p) {}
  double Unary(int p, int label) const override { return pr.LabelBlockUnary(p, label); }
  double Pairwise(int p, int q, int lp, int lq) const override {
    return pr.PairV(p, q, lp, lq, pr.d[p], pr.d[q], pr.mv[p], pr.mv[q]);
  }
};
// The label block with depth carried (JointViewOptions::label_moves_carry_depth):
// a pixel keeps its depth while it keeps its block-start label, and takes
// carried[l][p] (the depth of the nearest pixel that had label l at the block
// start) when it takes another label l, so a moved boundary continues the
// expanding region's surface. The depth is a function of the label, so this
// is an energy over labels alone; DepthOf gives the depth to store after the
// moves.
struct LabelDepthBlock : mrf::GridEnergy {
  const Problem& pr;
  const std::vector<int>& start_labels;
  const std::vector<std::vector<int>>& carried;  // [label][pixel]
  LabelDepthBlock(const Problem& p, const std::vector<int>& l0,
                  const std::vector<std::vector<int>>& c)
      : pr(p), start_labels(l0), carried(c) {}
  int DepthOf(int p, int label) const {
    return label == start_labels[p] ? pr.d[p] : carried[label][p];
  }
  double Unary(int p, int label) const override {
    const int dl = DepthOf(p, label);
    return pr.LabelUnary(p, label) + pr.DepthOnlyUnary(p, dl) + pr.Pose3d(p, label, dl, pr.mv[p]);
  }
  double Pairwise(int p, int q, int lp, int lq) const override {
    return pr.PairV(p, q, lp, lq, DepthOf(p, lp), DepthOf(q, lq), pr.mv[p], pr.mv[q]);
  }
};
// Per label l, the depth label of the nearest pixel labelled l in pr.l
// (Euclidean distance, ties as OpenCV's distance transform breaks them); a
// label that no pixel has gets the unknown depth everywhere.
std::vector<std::vector<int>> NearestLabelDepths(const Problem& pr, int num_labels) {
  std::vector<std::vector<int>> carried(num_labels);
  for (int l = 0; l < num_labels; ++l) {
    cv::Mat not_l(pr.height, pr.width, CV_8U);
    bool present = false;
    for (int p = 0; p < pr.n; ++p) {
      not_l.ptr<uint8_t>()[p] = pr.l[p] == l ? 0 : 255;
      present |= pr.l[p] == l;
    }
    carried[l].assign(pr.n, pr.unknown);
    if (!present) continue;
    cv::Mat distance, nearest;  // nearest: index of the zero pixel, 1-based
    cv::distanceTransform(not_l, distance, nearest, cv::DIST_L2, 3, cv::DIST_LABEL_PIXEL);
    std::vector<int> pixel_of(pr.n + 1, -1);
    for (int p = 0; p < pr.n; ++p)
      if (pr.l[p] == l) pixel_of[nearest.ptr<int>()[p]] = p;
    for (int p = 0; p < pr.n; ++p) {
      const int source = pixel_of[nearest.ptr<int>()[p]];
      if (source >= 0) carried[l][p] = pr.d[source];
    }
  }
  return carried;
}
// The label unaries and E_c alone (the appearance refits, before d and m exist).
struct LabelOnlyEnergy : mrf::GridEnergy {
  const Problem& pr;
  explicit LabelOnlyEnergy(const Problem& p) : pr(p) {}
  double Unary(int p, int label) const override { return pr.LabelUnary(p, label); }
  double Pairwise(int p, int q, int lp, int lq) const override {
    return lp != lq && pr.t().contrast ? pr.contrast[Direction(p, q, pr.width)][p] : 0.0;
  }
};
// Per pixel, the sum over its 8 neighbours q of weight(p, q) (each pair once
// per side; weight(p, q) is given with p < q).
template <typename Weight>
std::vector<double> NeighbourWeightSums(const Problem& pr, const Weight& weight) {
  std::vector<double> sums(pr.n, 0.0);
  tbb::parallel_for(0, pr.height, [&](int y) {
    for (int x = 0; x < pr.width; ++x) {
      const int p = y * pr.width + x;
      double s = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if ((dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= pr.width || qy >= pr.height)
            continue;
          const int q = qy * pr.width + qx;
          s += q > p ? weight(p, q) : weight(q, p);
        }
      sums[p] = s;
    }
  });
  return sums;
}

// Needs pr.FillPairCache(kMotion) at the current l and mv.
struct DepthBlock : mrf::GridEnergy {
  const Problem& pr;
  // Per pixel, the weight of E_s over its pairs (λ_s λ_spatial per neighbour
  // with its label, both in the region of interest).
  std::vector<double> smooth_weight;
  explicit DepthBlock(const Problem& p) : pr(p) {
    const double w = pr.t().smooth ? pr.w().smooth * pr.w().smooth_spatial : 0.0;
    smooth_weight = NeighbourWeightSums(pr, [&](int a, int b) {
      return pr.l[a] == pr.l[b] && pr.grid.IsActive(a) && pr.grid.IsActive(b) ? w : 0.0;
    });
  }
  double Unary(int p, int label) const override { return pr.DepthUnary(p, label, pr.mv[p]); }
  double Pairwise(int p, int q, int dp, int dq) const override {
    return pr.PairLabelDepth(p, q, pr.l[p], pr.l[q], dp, dq) + pr.Cached(p, q);
  }
  // E_s is a weighted metric of the depth labels (DepthPair), the rest of
  // the pair does not depend on them.
  double PairwiseDecreaseBound(int p, int from, int to) const override {
    return smooth_weight[p] * pr.DepthPair(from, to);
  }
  // The fine pass after a coarse one (JointViewOptions::depth_coarse_step):
  // a pixel with a depth may move by up to `band` labels or to U; one at U
  // may take any depth. band < 0: no restriction.
  int band = -1;
  bool MayTake(int p, int current, int proposal) const override {
    if (!pr.DepthAllowed(p, proposal)) return false;
    if (band < 0 || proposal == pr.unknown) return true;
    return current == pr.unknown || std::abs(current - proposal) <= band;
  }
};
// Needs pr.FillPairCache(kLabelDepth) at the current l and d.
struct MotionBlock : mrf::GridEnergy {
  const Problem& pr;
  // Per pixel, the weight of E_r over its pairs whose E_r depends on the motions.
  std::vector<double> reg_weight;
  explicit MotionBlock(const Problem& p) : pr(p) {
    reg_weight = NeighbourWeightSums(pr, [&](int a, int b) { return pr.MotionRegWeight(a, b); });
  }
  double Unary(int p, int label) const override { return pr.MotionUnary(p, label, pr.d[p]); }
  double Pairwise(int p, int q, int mp, int mq) const override {
    return pr.Cached(p, q) +
           pr.PairMotion(p, q, pr.l[p], pr.l[q], pr.motion.motions[mp], pr.motion.motions[mq]);
  }
  // JointViewOptions::motion_candidates_per_pixel: per pixel, the k-th lowest unary
  // (a pixel may take a motion whose unary is at most that); empty = all.
  std::vector<float> candidate_cut;
  void LimitCandidates(int k) {
    const int num = pr.motion.NumLabels();
    if (k <= 0 || k >= num) return;
    candidate_cut.assign(pr.n, std::numeric_limits<float>::infinity());
    tbb::parallel_for(0, pr.n, [&](int p) {
      if (!pr.grid.IsActive(p)) return;
      std::vector<float> u(num);
      for (int i = 0; i < num; ++i) u[i] = static_cast<float>(Unary(p, i));
      std::nth_element(u.begin(), u.begin() + (k - 1), u.end());
      candidate_cut[p] = u[k - 1];
    });
  }
  bool MayTake(int p, int, int proposal) const override {
    return candidate_cut.empty() || static_cast<float>(Unary(p, proposal)) <= candidate_cut[p];
  }
  double PairwiseDecreaseBound(int p, int from, int to) const override {
    return reg_weight[p] *
           pr.MotionRhoDecreaseBound(pr.motion.motions[from], pr.motion.motions[to]);
  }
};
// Fusion of the current motion (binary label 0) with a proposal (label 1):
// the full energy as a function of the per-pixel choice, l and d fixed.
struct FusionBlock : mrf::GridEnergy {
  const Problem& pr;
  const std::vector<Eigen::Vector2f>& pm;  // proposal motion
  const std::vector<float>& pf;            // its raw E_f cost
  FusionBlock(const Problem& p, const std::vector<Eigen::Vector2f>& m, const std::vector<float>& f)
      : pr(p), pm(m), pf(f) {}
  const Eigen::Vector2f& M(int p, int k) const { return k == 0 ? pr.mv[p] : pm[p]; }
  double Unary(int p, int k) const override {
    return pr.MotionUnary(p, M(p, k), k == 0 ? pr.fcost[p] : pf[p], pr.d[p]);
  }
  double Pairwise(int p, int q, int kp, int kq) const override {  // needs kLabelDepth cached
    return pr.Cached(p, q) + pr.PairMotion(p, q, pr.l[p], pr.l[q], M(p, kp), M(q, kq));
  }
};

cv::Mat Grey(const cv::Mat& bgr) {
  cv::Mat g;
  cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY);
  return g;
}

// `mask` (CV_8U) grown by a disc of radius `margin` pixels (0: unchanged).
cv::Mat GrowRegion(const cv::Mat& mask, int margin) {
  if (margin <= 0) return mask;
  cv::Mat grown;
  cv::dilate(
      mask, grown,
      cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * margin + 1, 2 * margin + 1)));
  return grown;
}

cv::Mat RegionOfInterest(const JointViewInput& in, int margin) {
  const cv::Size size = in.initial_labels.size();
  cv::Mat roi = in.initial_labels > 0;
  for (const JointObject& obj : in.objects) {
    if (obj.region.empty()) continue;
    U4D_CHECK(obj.region.size() == size && obj.region.type() == CV_8UC1,
              "SolveJointView: region of object {} must be CV_8U {}x{}", obj.id, size.width,
              size.height);
    roi |= obj.region > 0;
  }
  return GrowRegion(roi, margin);
}

// e_r^X(p): mean minus min of a label cost over the 3x3 window, at the labels.
std::vector<float> WindowSpread(const LabelCostVolume& volume, const cv::Mat& labels) {
  const int w = volume.width, h = volume.height;
  std::vector<float> spread(static_cast<size_t>(w) * h, 0.f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double sum = 0, lo = 1e30;
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const double c = volume.At(qy * w + qx, labels.at<uint16_t>(qy, qx));
          sum += c;
          lo = std::min(lo, c);
          ++count;
        }
      spread[static_cast<size_t>(y) * w + x] = static_cast<float>(sum / count - lo);
    }
  return spread;
}

// The label maps E_sem combines (JointViewOptions::semantic_temporal): the
// initial labels of t and every other labelled image of ψ_T (t−1, t+1)
// carried to t by dense flow (OpenCV DIS, medium preset) from the reference
// image to that image: map(p) = labels(p + f(p)), nearest, clamped at the border.
std::vector<cv::Mat> SemanticLabelMaps(const JointViewInput& in) {
  std::vector<cv::Mat> maps = {in.initial_labels};
  const cv::Mat& ref = in.images_t[in.ref_view];
  cv::Mat ref_grey;
  for (const LabelledImage& li : in.appearance_training) {
    if (li.labels.data == in.initial_labels.data || li.image.data == ref.data) continue;
    if (li.image.size() != ref.size() || li.labels.size() != ref.size() ||
        li.labels.type() != CV_16UC1)
      continue;
    if (ref_grey.empty()) cv::cvtColor(ref, ref_grey, cv::COLOR_BGR2GRAY);
    cv::Mat grey, flow;
    cv::cvtColor(li.image, grey, cv::COLOR_BGR2GRAY);
    cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM)->calc(ref_grey, grey, flow);
    cv::Mat map_x(ref.size(), CV_32F), map_y(ref.size(), CV_32F);
    for (int y = 0; y < ref.rows; ++y)
      for (int x = 0; x < ref.cols; ++x) {
        const cv::Vec2f f = flow.at<cv::Vec2f>(y, x);
        map_x.at<float>(y, x) = x + f[0];
        map_y.at<float>(y, x) = y + f[1];
      }
    cv::Mat carried;
    cv::remap(li.labels, carried, map_x, map_y, cv::INTER_NEAREST, cv::BORDER_REPLICATE);
    maps.push_back(carried);
  }
  return maps;
}

void CheckInput(const JointViewInput& in) {
  const int v = in.ref_view;
  const int nv = static_cast<int>(in.cameras_t.size());
  U4D_CHECK(nv >= 2, "SolveJointView: need at least two views, got {}", nv);
  U4D_CHECK(v >= 0 && v < nv, "SolveJointView: ref_view {} out of range [0, {})", v, nv);
  U4D_CHECK(static_cast<int>(in.images_t.size()) == nv,
            "SolveJointView: {} images at t for {} cameras", in.images_t.size(), nv);
  U4D_CHECK(in.images_t1.empty() || (static_cast<int>(in.images_t1.size()) == nv &&
                                     static_cast<int>(in.cameras_t1.size()) == nv),
            "SolveJointView: images and cameras at t+1 must cover all {} views", nv);
  const Camera& cam = in.cameras_t[v];
  U4D_CHECK(in.initial_labels.type() == CV_16UC1 && in.initial_labels.cols == cam.width &&
                in.initial_labels.rows == cam.height,
            "SolveJointView: initial labels must be CV_16U {}x{}", cam.width, cam.height);
  U4D_CHECK(in.num_labels >= 1, "SolveJointView: num_labels must be >= 1");
  double max_label = 0;
  cv::minMaxLoc(in.initial_labels, nullptr, &max_label);
  U4D_CHECK(max_label < in.num_labels, "SolveJointView: initial label {} >= num_labels {}",
            max_label, in.num_labels);
  for (const JointObject& obj : in.objects)
    U4D_CHECK(obj.id >= 1 && obj.id < in.num_labels, "SolveJointView: object id {} out of [1, {})",
              obj.id, in.num_labels);
  U4D_CHECK(in.previous_depth.empty() || (in.previous_depth.type() == CV_32FC1 &&
                                          in.previous_depth.size() == in.initial_labels.size()),
            "SolveJointView: previous depth must be CV_32F of the view's size");
}

}  // namespace

void JointViewOptions::Check() const {
  weights.Check();
  labels.Check();
  depth.Check();
  motion_labels.Check();
  flow.Check();
  pose.Check();
  U4D_CHECK(rounds >= 1, "JointViewOptions.rounds must be >= 1, got {}", rounds);
  U4D_CHECK(sweeps_per_block >= 1, "JointViewOptions.sweeps_per_block must be >= 1");
  U4D_CHECK(motion_rounds >= 1, "JointViewOptions.motion_rounds must be >= 1, got {}",
            motion_rounds);
  U4D_CHECK(depth_truncation > 0, "JointViewOptions.depth_truncation must be > 0");
  U4D_CHECK(depth_coarse_step >= 0, "JointViewOptions.depth_coarse_step must be >= 0, got {}",
            depth_coarse_step);
  U4D_CHECK(depth_refine_band >= 0, "JointViewOptions.depth_refine_band must be >= 0, got {}",
            depth_refine_band);
  U4D_CHECK(motion_truncation_px > 0, "JointViewOptions.motion_truncation_px must be > 0");
  U4D_CHECK(motion_candidates_per_pixel >= 0,
            "JointViewOptions.motion_candidates_per_pixel must be >= 0, got {}",
            motion_candidates_per_pixel);
  U4D_CHECK(roi_margin_px >= 0, "JointViewOptions.roi_margin_px must be >= 0");
  U4D_CHECK(appearance_refits >= 0, "JointViewOptions.appearance_refits must be >= 0, got {}",
            appearance_refits);
  fusion.Check();
}

void FlowFusionOptions::Check() const {
  U4D_CHECK(rounds >= 1, "FlowFusionOptions.rounds must be >= 1, got {}", rounds);
}

std::vector<cv::Mat> FlowFusionProposals(const cv::Mat& grey_t, const cv::Mat& grey_t1,
                                         const FlowFusionOptions& options) {
  U4D_CHECK(grey_t.type() == CV_8UC1 && grey_t1.type() == CV_8UC1 &&
                grey_t.size() == grey_t1.size() && !grey_t.empty(),
            "FlowFusionProposals: need two 8-bit grey images of one size (got {}x{} type {} and "
            "{}x{} type {})",
            grey_t.cols, grey_t.rows, grey_t.type(), grey_t1.cols, grey_t1.rows, grey_t1.type());
  std::vector<cv::Mat> proposals;
  if (options.deepflow) {
    cv::Mat f;
    cv::optflow::createOptFlow_DeepFlow()->calc(grey_t, grey_t1, f);
    proposals.push_back(f);
  }
  if (options.dis_fine) {
    cv::Mat f;
    const cv::Ptr<cv::DISOpticalFlow> dis =
        cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
    dis->setFinestScale(0);
    dis->setVariationalRefinementIterations(10);
    dis->calc(grey_t, grey_t1, f);
    proposals.push_back(f);
  }
  if (options.dis) {
    cv::Mat f;
    cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM)->calc(grey_t, grey_t1, f);
    proposals.push_back(f);
  }
  if (proposals.size() == 2) proposals.push_back(0.5 * (proposals[0] + proposals[1]));
  return proposals;
}

JointViewResult SolveJointView(const JointViewInput& in, const JointViewOptions& o) {
  o.Check();
  CheckInput(in);
  Timer timer;
  JointViewResult result;
  Timer phase_timer;
  std::clock_t phase_cpu = std::clock();
  auto end_phase = [&](const char* name) {
    const std::clock_t now = std::clock();
    result.phases.push_back(
        {name, phase_timer.Seconds(), static_cast<double>(now - phase_cpu) / CLOCKS_PER_SEC});
    phase_timer = Timer();
    phase_cpu = now;
  };
  const int v = in.ref_view;
  const Camera& cam = in.cameras_t[v];
  const bool has_next = !in.images_t1.empty();

  Problem pr;
  pr.o = &o;
  pr.width = cam.width;
  pr.height = cam.height;
  pr.n = cam.width * cam.height;
  pr.num_labels = in.num_labels;
  pr.camera_t = &cam;
  pr.camera_t1 = has_next ? &in.cameras_t1[v] : &cam;
  const cv::Mat roi = RegionOfInterest(in, o.roi_margin_px);
  pr.grid.width = pr.width;
  pr.grid.height = pr.height;
  pr.grid.connectivity = 8;
  pr.grid.active.assign(roi.datastart, roi.dataend);

  // Rays: the world point at depth z is centre + z * rays[p].
  pr.centre = cam.Center();
  pr.rays.resize(pr.n);
  for (int p = 0; p < pr.n; ++p)
    pr.rays[p] = cam.Unproject(Eigen::Vector2d(p % pr.width, p / pr.width), 1.0) - pr.centre;

  // ---- Label unaries: E_a, E_sem, E_p (2D label part).
  std::vector<LabelledImage> training = in.appearance_training;
  if (training.empty()) training.push_back({in.images_t[v], in.initial_labels});
  // E_a is read in the region (unaries) and one pixel around it (the 3x3
  // windows of WindowSpread for E_r's weights): evaluated there only.
  cv::Mat appearance_where;
  cv::dilate(roi, appearance_where, cv::Mat::ones(3, 3, CV_8U));
  LabelCostVolume appearance = AppearanceCosts(in.images_t[v], training, in.num_labels, in.markers,
                                               o.labels, appearance_where);
  const LabelCostVolume semantic =
      SemanticCosts(o.semantic_temporal ? SemanticLabelMaps(in) : std::vector{in.initial_labels},
                    in.num_labels, o.labels);
  pr.use_pose = o.terms.pose && !in.people.empty();
  const double pose_norm = o.weights.pose_2d + o.weights.pose_3d;
  if (pr.use_pose && pose_norm > 0) {
    pr.pose = RenderPosePrior(cam, *pr.camera_t1, in.images_t[v], in.people, o.pose);
    pr.pose_2d_share = o.weights.pose * o.weights.pose_2d / pose_norm;
    pr.pose_3d_share = o.weights.pose * o.weights.pose_3d / pose_norm;
  } else {
    pr.use_pose = false;
  }
  const auto fill_label_unary = [&](const LabelCostVolume& appearance) {
    pr.label_unary.assign(static_cast<size_t>(pr.n) * in.num_labels, 0.f);
    tbb::parallel_for(0, pr.n, [&](int p) {
      for (int l = 0; l < in.num_labels; ++l) {
        double e = 0;
        if (o.terms.appearance) e += o.weights.appearance * appearance.At(p, l);
        if (o.terms.semantic) e += o.weights.semantic * semantic.At(p, l);
        if (pr.use_pose) e += pr.pose_2d_share * PoseLabelCost(pr.pose, p, l);
        pr.label_unary[static_cast<size_t>(p) * in.num_labels + l] = static_cast<float>(e);
      }
    });
  };
  fill_label_unary(appearance);
  end_phase("label unaries");

  // ---- Pairwise weights: E_c and the E_r weights.
  pr.pairs = mrf::NeighbourPairs(pr.grid);
  const std::vector<std::pair<int, int>>& pairs = pr.pairs;
  const std::vector<float> colour = ContrastWeights(
      in.images_t[v].isContinuous() ? in.images_t[v] : in.images_t[v].clone(), pairs);
  const std::vector<float> sem_contrast = SemanticContrastWeights(semantic, pairs);
  for (auto& c : pr.contrast) c.assign(pr.n, 0.f);
  if (o.motion_reg_edge_aware)
    for (auto& c : pr.reg_edge) c.assign(pr.n, 0.f);
  const double cw = o.weights.contrast_colour + o.weights.contrast_label;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const auto [p, q] = pairs[i];
    const double e =
        cw > 0
            ? (o.weights.contrast_colour * colour[i] + o.weights.contrast_label * sem_contrast[i]) /
                  cw
            : 0.0;
    pr.contrast[Direction(p, q, pr.width)][p] = static_cast<float>(o.weights.contrast * e);
    if (o.motion_reg_edge_aware) pr.reg_edge[Direction(p, q, pr.width)][p] = colour[i];
  }
  // Appearance refits (GrabCut's iteration, before the energy is fixed): the
  // label-only energy (label unaries + E_c) is minimised, frame t's colour
  // models are re-learnt from that labelling, and the unaries recomputed.
  if (o.terms.appearance && o.appearance_refits > 0 && !training.empty()) {
    std::vector<int> candidates(in.num_labels);
    for (int i = 0; i < in.num_labels; ++i) candidates[i] = i;
    mrf::ExpansionOptions eo;
    eo.max_sweeps = o.sweeps_per_block;
    eo.algorithm = o.algorithm;
    // Frame t's entry of ψ_T (the one holding this view's image); added when
    // the caller's list lacks it.
    size_t frame_t = 0;
    while (frame_t < training.size() && training[frame_t].image.data != in.images_t[v].data)
      ++frame_t;
    if (frame_t == training.size()) training.push_back({in.images_t[v], in.initial_labels});
    for (int it = 0; it < o.appearance_refits; ++it) {
      std::vector<int> labels(pr.n);
      for (int p = 0; p < pr.n; ++p) labels[p] = in.initial_labels.ptr<uint16_t>()[p];
      mrf::AlphaExpansion(pr.grid, LabelOnlyEnergy(pr), candidates, &labels, eo);
      cv::Mat refined(pr.height, pr.width, CV_16U);
      for (int p = 0; p < pr.n; ++p) refined.ptr<uint16_t>()[p] = static_cast<uint16_t>(labels[p]);
      training[frame_t].labels = refined;
      appearance = AppearanceCosts(in.images_t[v], training, in.num_labels, in.markers, o.labels,
                                   appearance_where);
      fill_label_unary(appearance);
    }
    end_phase("appearance refits");
  }
  {
    const std::vector<float> spread_l = WindowSpread(semantic, in.initial_labels);
    const std::vector<float> spread_a = WindowSpread(appearance, in.initial_labels);
    pr.reg_weight.resize(pr.n);
    for (int p = 0; p < pr.n; ++p)
      pr.reg_weight[p] = static_cast<float>(o.weights.motion_reg *
                                            (1.0 + o.weights.motion_reg_label * spread_l[p] +
                                             o.weights.motion_reg_app * spread_a[p]));
  }
  end_phase("pairwise weights");

  // ---- Depth labels and E_d over the objects' depth range.
  double near = 1e30, far = 0;
  for (const JointObject& obj : in.objects)
    if (obj.depth_near > 0 && obj.depth_far > obj.depth_near) {
      near = std::min(near, obj.depth_near);
      far = std::max(far, obj.depth_far);
    }
  U4D_CHECK(far > near, "SolveJointView: view {} has no object with a depth range", v);
  pr.depth = ComputeDepthCostVolume(in.cameras_t, in.images_t, v, roi, near, far, o.depth);
  pr.unknown = pr.depth.NumLabels();
  if (o.depth_object_ranges) {
    // A pixel may take the depths of the objects whose region (grown like the
    // ROI) holds it; one in no object's region keeps every depth.
    pr.depth_lo.assign(pr.n, std::numeric_limits<int16_t>::max());
    pr.depth_hi.assign(pr.n, -1);
    for (const JointObject& obj : in.objects) {
      if (!(obj.depth_near > 0 && obj.depth_far > obj.depth_near)) continue;
      int lo = pr.unknown, hi = -1;
      for (int i = 0; i < pr.unknown; ++i)
        if (pr.depth.depths[i] >= obj.depth_near && pr.depth.depths[i] <= obj.depth_far)
          lo = std::min(lo, i), hi = std::max(hi, i);
      if (hi < 0) continue;
      cv::Mat own = in.initial_labels == obj.id;
      if (!obj.region.empty()) own |= obj.region > 0;
      const cv::Mat grown = GrowRegion(own, o.roi_margin_px);  // as the ROI
      for (int p = 0; p < pr.n; ++p)
        if (grown.data[p]) {
          pr.depth_lo[p] = static_cast<int16_t>(std::min<int>(pr.depth_lo[p], lo));
          pr.depth_hi[p] = static_cast<int16_t>(std::max<int>(pr.depth_hi[p], hi));
        }
    }
    for (int p = 0; p < pr.n; ++p)
      if (pr.depth_hi[p] < 0)
        pr.depth_lo[p] = 0, pr.depth_hi[p] = static_cast<int16_t>(pr.unknown - 1);
  }
  if (!in.previous_depth.empty()) {
    pr.previous_depth_label.assign(pr.n, -1);
    const std::vector<float>& z = pr.depth.depths;
    for (int p = 0; p < pr.n; ++p) {
      const float zp = in.previous_depth.ptr<float>()[p];
      if (!(zp > 0)) continue;
      // Nearest label in inverse depth.
      int best = 0;
      for (int i = 1; i < pr.unknown; ++i)
        if (std::abs(1 / z[i] - 1 / zp) < std::abs(1 / z[best] - 1 / zp)) best = i;
      pr.previous_depth_label[p] = best;
    }
  }
  end_phase("depth volume");

  // ---- Motion labels and E_f (cross-view part with the plane-sweep depth).
  std::vector<SparseMotion> sparse = in.sparse;
  if (pr.use_pose) {  // the paper adds the projected joints to the sparse tracks
    for (const PriorBone& bone : pr.pose.bones) {
      if (!bone.has_motion) continue;
      const Eigen::Vector2d a = cam.Project(bone.a), a1 = pr.camera_t1->Project(bone.a1);
      if (a.allFinite() && a1.allFinite() && cam.InImage(a))
        sparse.push_back({a, a1 - a, bone.object_id});
    }
  }
  const cv::Mat wta_depth = WinnerTakeAllDepth(pr.depth, roi);
  FlowCostInput flow_in;
  if (has_next) {
    flow_in.ref_view = v;
    flow_in.cameras_t = in.cameras_t;
    flow_in.cameras_t1 = in.cameras_t1;
    flow_in.images_t = in.images_t;
    flow_in.images_t1 = in.images_t1;
    flow_in.depth_t = wta_depth;
    flow_in.sparse = sparse;
    flow_in.roi = roi;
    pr.motion = ComputeFlowCostVolume(flow_in, BuildMotionLabels(sparse, o.motion_labels),
                                      o.motion_labels, o.flow);
    const int parts = (o.flow.temporal ? 1 : 0) + (o.flow.cross_view ? 1 : 0);
    pr.flow_scale = parts > 0 ? static_cast<float>(1.0 / (parts * o.flow.truncation)) : 1.f;
  } else {  // last frame: no motion to estimate
    pr.motion.width = pr.width;
    pr.motion.height = pr.height;
    pr.motion.motions = {Eigen::Vector2f::Zero()};
    pr.motion.slots = MakeRoiSlots(roi, pr.width, pr.height);
    pr.motion.cost.assign(pr.motion.slots.count, 0.f);
  }
  end_phase("flow volume");
  const int num_motions = pr.motion.NumLabels();
  int zero_motion = 0;
  for (int i = 0; i < num_motions; ++i)
    if (pr.motion.motions[i].isZero()) zero_motion = i;

  // ---- Initial labelling: initial masks, then the best depth, then the best motion.
  pr.l.resize(pr.n);
  for (int p = 0; p < pr.n; ++p) pr.l[p] = in.initial_labels.ptr<uint16_t>()[p];
  pr.d.assign(pr.n, pr.unknown);
  pr.m.assign(pr.n, zero_motion);
  tbb::parallel_for(0, pr.n, [&](int p) {
    if (!pr.grid.IsActive(p)) return;
    double best = 1e300;
    for (int i = 0; i <= pr.unknown; ++i) {
      if (!pr.DepthAllowed(p, i)) continue;
      const double e = pr.DepthUnary(p, i, pr.motion.motions[zero_motion]);
      if (e < best) best = e, pr.d[p] = i;
    }
    best = 1e300;
    for (int i = 0; i < num_motions; ++i) {
      const double e = pr.MotionUnary(p, i, pr.d[p]);
      if (e < best) best = e, pr.m[p] = i;
    }
  });
  pr.SyncMotion();
  end_phase("initial labelling");

  result.roi = roi;
  result.plane_sweep_depth = wta_depth;
  result.num_depth_labels = pr.unknown + 1;
  result.num_motion_labels = num_motions;
  result.energy_trace.push_back({"init", pr.Energy(), timer.Seconds()});

  mrf::ExpansionOptions eo;
  eo.max_sweeps = o.sweeps_per_block;
  eo.algorithm = o.algorithm;
  std::vector<int> label_candidates(in.num_labels), depth_candidates(pr.unknown + 1),
      motion_candidates(num_motions);
  for (int i = 0; i < in.num_labels; ++i) label_candidates[i] = i;
  for (int i = 0; i <= pr.unknown; ++i) depth_candidates[i] = i;
  for (int i = 0; i < num_motions; ++i) motion_candidates[i] = i;
  // The coarse depth pass: every depth_coarse_step-th depth, the farthest and U.
  std::vector<int> depth_coarse;
  if (o.depth_coarse_step > 1) {
    for (int i = 0; i < pr.unknown; i += o.depth_coarse_step) depth_coarse.push_back(i);
    if (depth_coarse.back() != pr.unknown - 1) depth_coarse.push_back(pr.unknown - 1);
    depth_coarse.push_back(pr.unknown);
  }
  double block_seconds[3] = {0, 0, 0}, block_cpu[3] = {0, 0, 0};
  auto cpu_since = [](std::clock_t start) {
    return static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
  };
  for (int round = 0; round < o.rounds; ++round) {
    Timer block_timer;
    std::clock_t block_start = std::clock();
    if (o.label_moves_carry_depth && round > 0) {
      const std::vector<int> start_labels = pr.l;
      const std::vector<std::vector<int>> carried = NearestLabelDepths(pr, in.num_labels);
      const LabelDepthBlock block(pr, start_labels, carried);
      mrf::AlphaExpansion(pr.grid, block, label_candidates, &pr.l, eo);
      std::vector<int> depth(pr.n);
      for (int p = 0; p < pr.n; ++p) depth[p] = block.DepthOf(p, pr.l[p]);
      pr.d = std::move(depth);
    } else {
      mrf::AlphaExpansion(pr.grid, LabelBlock(pr), label_candidates, &pr.l, eo);
    }
    result.energy_trace.push_back({"labels", pr.Energy(), block_timer.Seconds()});
    block_seconds[0] += result.energy_trace.back().seconds;
    block_cpu[0] += cpu_since(block_start);
    block_timer = Timer();
    block_start = std::clock();
    pr.FillPairCache(Problem::CachedPart::kMotion);
    DepthBlock depth_block(pr);
    // The band of the later rounds (depth_refine_band) holds for every depth
    // pass of those rounds; a coarse-to-fine fine pass keeps the narrower one.
    const int refine_band = round > 0 && o.depth_refine_band > 0 ? o.depth_refine_band : -1;
    depth_block.band = refine_band;
    if (!depth_coarse.empty()) {
      mrf::AlphaExpansion(pr.grid, depth_block, depth_coarse, &pr.d, eo);
      depth_block.band =
          refine_band < 0 ? o.depth_coarse_step : std::min(refine_band, o.depth_coarse_step);
    }
    mrf::AlphaExpansion(pr.grid, depth_block, depth_candidates, &pr.d, eo);
    result.energy_trace.push_back({"depth", pr.Energy(), block_timer.Seconds()});
    block_seconds[1] += result.energy_trace.back().seconds;
    block_cpu[1] += cpu_since(block_start);
    if (has_next && round < o.motion_rounds) {
      block_timer = Timer();
      block_start = std::clock();
      pr.FillPairCache(Problem::CachedPart::kLabelDepth);
      MotionBlock motion_block(pr);
      motion_block.LimitCandidates(o.motion_candidates_per_pixel);
      mrf::AlphaExpansion(pr.grid, motion_block, motion_candidates, &pr.m, eo);
      pr.SyncMotion();
      result.energy_trace.push_back({"motion", pr.Energy(), block_timer.Seconds()});
      block_seconds[2] += result.energy_trace.back().seconds;
      block_cpu[2] += cpu_since(block_start);
    }
  }

  result.phases.push_back({"labels", block_seconds[0], block_cpu[0]});
  result.phases.push_back({"depth", block_seconds[1], block_cpu[1]});
  if (has_next) result.phases.push_back({"motion", block_seconds[2], block_cpu[2]});
  phase_timer = Timer();
  phase_cpu = std::clock();

  // ---- Flow fusion: continuous proposals fused under the full energy (l, d fixed).
  if (has_next && o.fusion.enabled && o.terms.flow) {
    Timer block_timer;
    pr.FillPairCache(Problem::CachedPart::kLabelDepth);  // FusionBlock
    const MotionLabelGrid index(pr.motion.motions);
    // Proposals that do not depend on the state.
    const std::vector<cv::Mat> external =
        FlowFusionProposals(Grey(in.images_t[v]), Grey(in.images_t1[v]), o.fusion);
    end_phase("fusion proposals");
    auto current_field = [&] {
      cv::Mat f(pr.height, pr.width, CV_32FC2);
      for (int p = 0; p < pr.n; ++p) f.ptr<cv::Vec2f>()[p] = cv::Vec2f(pr.mv[p].x(), pr.mv[p].y());
      return f;
    };
    auto fuse = [&](const cv::Mat& proposal_field) {
      std::vector<Eigen::Vector2f> pm(pr.n);
      std::vector<float> pf(pr.n);
      cv::Mat field = proposal_field.clone();  // a non-finite proposal keeps the current motion
      for (int p = 0; p < pr.n; ++p) {
        cv::Vec2f& f = field.ptr<cv::Vec2f>()[p];
        if (!std::isfinite(f[0]) || !std::isfinite(f[1])) f = cv::Vec2f(pr.mv[p].x(), pr.mv[p].y());
      }
      const cv::Mat costs = FlowFieldCosts(flow_in, field, o.flow);
      for (int p = 0; p < pr.n; ++p) {
        const cv::Vec2f f = field.ptr<cv::Vec2f>()[p];
        pm[p] = Eigen::Vector2f(f[0], f[1]);
        if (!pr.grid.IsActive(p) || !pm[p].allFinite()) {
          pm[p] = pr.mv[p];
          pf[p] = pr.fcost[p];
          continue;
        }
        // e_F^S of a sub-pixel motion: that of its nearest integer offset in M.
        const int k = index.Nearest(pm[p]);
        pf[p] = costs.ptr<float>()[p] +
                ((k < 0 || pr.motion.At(p, k) >= kForbiddenMotion) ? kForbiddenMotion : 0.f);
      }
      std::vector<int> choice(pr.n, 0);
      const std::vector<int> proposal(pr.n, 1);
      mrf::FusionMove(pr.grid, FusionBlock(pr, pm, pf), proposal, &choice, o.algorithm);
      for (int p = 0; p < pr.n; ++p)
        if (choice[p] == 1) pr.mv[p] = pm[p], pr.fcost[p] = pf[p];
    };
    for (int round = 0; round < o.fusion.rounds; ++round) {
      if (round == 0 && o.fusion.refined) {
        std::vector<int> labels(pr.m);
        for (int p = 0; p < pr.n; ++p)
          if (!pr.grid.IsActive(p)) labels[p] = -1;
        fuse(RefineFlowLabels(pr.motion, labels));
      }
      for (const cv::Mat& f : external) fuse(f);
      if (o.fusion.smoothed) {
        cv::Mat smooth;
        cv::GaussianBlur(current_field(), smooth, cv::Size(5, 5), 1.0);
        fuse(smooth);
      }
    }
    result.energy_trace.push_back({"fusion", pr.Energy(), block_timer.Seconds()});
    end_phase("fusion moves");
  }

  // ---- Outputs: labels, sub-sample depth on object pixels, sub-pixel flow.
  result.labels = cv::Mat(pr.height, pr.width, CV_16U);
  std::vector<int> depth_labels(pr.n);
  for (int p = 0; p < pr.n; ++p) {
    result.labels.ptr<uint16_t>()[p] = static_cast<uint16_t>(pr.l[p]);
    depth_labels[p] = (pr.l[p] == 0 || pr.d[p] == pr.unknown) ? -1 : pr.d[p];
  }
  result.depth = RefineDepthLabels(pr.depth, depth_labels);
  if (has_next) {
    result.flow = cv::Mat::zeros(pr.height, pr.width, CV_32FC2);
    for (int p = 0; p < pr.n; ++p)
      if (pr.grid.IsActive(p))
        result.flow.ptr<cv::Vec2f>()[p] = cv::Vec2f(pr.mv[p].x(), pr.mv[p].y());
  } else {
    result.flow = cv::Mat::zeros(pr.height, pr.width, CV_32FC2);
  }
  result.seconds = timer.Seconds();
  return result;
}

}  // namespace u4d
