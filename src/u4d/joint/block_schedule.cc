#include "u4d/joint/block_schedule.h"

#include <algorithm>
#include <cstdlib>
#include <ctime>
#include <limits>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include "u4d/mrf/expansion.h"
#include "u4d/util/timer.h"

namespace u4d {

void PairCache::Fill(const JointEnergy& energy, const JointLabelling& labelling, Part part) {
  values_.assign(static_cast<size_t>(energy.num_pixels) * 4, 0.0);
  constexpr int kDx[4] = {1, -1, 0, 1}, kDy[4] = {0, 1, 1, 1};
  const int width = energy.width, height = energy.height;
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      const int p = y * width + x;
      for (int k = 0; k < 4; ++k) {
        const int qx = x + kDx[k], qy = y + kDy[k];
        if (qx < 0 || qx >= width || qy >= height) continue;
        const int q = qy * width + qx;
        values_[static_cast<size_t>(p) * 4 + k] =
            part == Part::kMotion
                ? energy.PairMotion(p, q, labelling.labels[p], labelling.labels[q],
                                    labelling.motion_vectors[p], labelling.motion_vectors[q])
                : energy.PairLabelDepth(p, q, labelling.labels[p], labelling.labels[q],
                                        labelling.depths[p], labelling.depths[q]);
      }
    }
  });
}

namespace {

// The label block: the energy as a function of l, d and m fixed.
struct LabelBlock : mrf::GridEnergy {
  const JointEnergy& energy;
  const JointLabelling& state;
  LabelBlock(const JointEnergy& e, const JointLabelling& labelling) : energy(e), state(labelling) {}
  double Unary(int p, int label) const override {
    return energy.LabelUnaryWithPose3d(p, label, state.depths[p], state.motion_vectors[p]);
  }
  double Pairwise(int p, int q, int lp, int lq) const override {
    return energy.Pair(p, q, lp, lq, state.depths[p], state.depths[q], state.motion_vectors[p],
                       state.motion_vectors[q]);
  }
};

// The label block with depth carried (JointViewOptions::label_moves_carry_depth):
// a pixel keeps its depth while it keeps its block-start label, and takes
// carried[l][p] (the depth of the nearest pixel that had label l at the block
// start) when it takes another label l, so a moved boundary continues the
// expanding region's surface (U where that depth is not allowed at the
// pixel). The depth is a function of the label, so this
// is an energy over labels alone; DepthOf gives the depth to store after the
// moves.
struct LabelDepthBlock : mrf::GridEnergy {
  const JointEnergy& energy;
  const JointLabelling& state;
  const std::vector<int>& start_labels;
  const std::vector<std::vector<int>>& carried;  // [label][pixel]
  LabelDepthBlock(const JointEnergy& e, const JointLabelling& labelling, const std::vector<int>& l0,
                  const std::vector<std::vector<int>>& c)
      : energy(e), state(labelling), start_labels(l0), carried(c) {}
  int DepthOf(int p, int label) const {
    if (label == start_labels[p]) return state.depths[p];
    // A depth the pixel may not take (depth_object_ranges: the label's
    // region does not hold the pixel) is not carried there: U.
    const int d = carried[label][p];
    return energy.DepthAllowed(p, d) ? d : energy.unknown;
  }
  double Unary(int p, int label) const override {
    const int depth = DepthOf(p, label);
    return energy.LabelUnary(p, label) + energy.DepthOnlyUnary(p, depth) +
           energy.Pose3d(p, label, depth, state.motion_vectors[p]);
  }
  double Pairwise(int p, int q, int lp, int lq) const override {
    return energy.Pair(p, q, lp, lq, DepthOf(p, lp), DepthOf(q, lq), state.motion_vectors[p],
                       state.motion_vectors[q]);
  }
};

// Per label l, the depth label of the nearest pixel labelled l in `s`
// (Euclidean distance, ties as OpenCV's distance transform breaks them); a
// label that no pixel has gets the unknown depth everywhere.
std::vector<std::vector<int>> NearestLabelDepths(const JointEnergy& energy,
                                                 const JointLabelling& labelling) {
  const int n = energy.num_pixels;
  std::vector<std::vector<int>> carried(energy.num_labels);
  for (int l = 0; l < energy.num_labels; ++l) {
    cv::Mat not_l(energy.height, energy.width, CV_8U);
    bool present = false;
    for (int p = 0; p < n; ++p) {
      not_l.ptr<uint8_t>()[p] = labelling.labels[p] == l ? 0 : 255;
      present |= labelling.labels[p] == l;
    }
    carried[l].assign(n, energy.unknown);
    if (!present) continue;
    cv::Mat distance, nearest;  // nearest: index of the zero pixel, 1-based
    cv::distanceTransform(not_l, distance, nearest, cv::DIST_L2, 3, cv::DIST_LABEL_PIXEL);
    std::vector<int> pixel_of(n + 1, -1);
    for (int p = 0; p < n; ++p)
      if (labelling.labels[p] == l) pixel_of[nearest.ptr<int>()[p]] = p;
    for (int p = 0; p < n; ++p) {
      const int source = pixel_of[nearest.ptr<int>()[p]];
      if (source >= 0) carried[l][p] = labelling.depths[source];
    }
  }
  return carried;
}

// Per pixel, the sum over its 8 neighbours q of weight(p, q) (each pair once
// per side; weight(p, q) is given with p < q).
template <typename Weight>
std::vector<double> NeighbourWeightSums(const JointEnergy& energy, const Weight& weight) {
  const int width = energy.width, height = energy.height;
  std::vector<double> sums(energy.num_pixels, 0.0);
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      const int p = y * width + x;
      double sum = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if ((dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= width || qy >= height) continue;
          const int q = qy * width + qx;
          sum += q > p ? weight(p, q) : weight(q, p);
        }
      sums[p] = sum;
    }
  });
  return sums;
}

// The depth block: the energy as a function of d, l and m fixed. `cache`
// holds kMotion at the current l and m.
struct DepthBlock : mrf::GridEnergy {
  const JointEnergy& energy;
  const JointLabelling& state;
  const PairCache& cache;
  // Per pixel, the weight of E_s over its pairs (λ_s λ_s^s per neighbour
  // with its label, both in the region of interest).
  std::vector<double> smooth_weight;
  DepthBlock(const JointEnergy& e, const JointLabelling& labelling, const PairCache& c)
      : energy(e), state(labelling), cache(c) {
    const double w = energy.terms.smooth ? energy.smoothness.spatial_weight : 0.0;
    smooth_weight = NeighbourWeightSums(energy, [&](int a, int b) {
      return state.labels[a] == state.labels[b] && energy.grid.IsActive(a) &&
                     energy.grid.IsActive(b)
                 ? w
                 : 0.0;
    });
  }
  double Unary(int p, int label) const override {
    return energy.DepthUnary(p, label, state.labels[p], state.motion_vectors[p]);
  }
  double Pairwise(int p, int q, int dp, int dq) const override {
    return energy.PairLabelDepth(p, q, state.labels[p], state.labels[q], dp, dq) +
           cache.At(p, q, energy.width);
  }
  // E_s is a weighted metric of the depth labels, the rest of the pair does
  // not depend on them.
  double PairwiseDecreaseBound(int p, int from, int to) const override {
    return smooth_weight[p] * energy.smoothness.Distance(from, to);
  }
  // The fine pass after a coarse one (JointViewOptions::depth_coarse_step):
  // a pixel with a depth may move by up to `band` labels or to U; one at U
  // may take any depth. band < 0: no restriction.
  int band = -1;
  bool MayTake(int p, int current, int proposal) const override {
    if (!energy.DepthAllowed(p, proposal)) return false;
    if (band < 0 || proposal == energy.unknown) return true;
    return current == energy.unknown || std::abs(current - proposal) <= band;
  }
};

// The motion block: the energy as a function of m, l and d fixed. `cache`
// holds kLabelDepth at the current l and d.
struct MotionBlock : mrf::GridEnergy {
  const JointEnergy& energy;
  const JointLabelling& state;
  const PairCache& cache;
  // Per pixel, the weight of E_r over its pairs whose E_r depends on the motions.
  std::vector<double> reg_weight;
  MotionBlock(const JointEnergy& e, const JointLabelling& labelling, const PairCache& c)
      : energy(e), state(labelling), cache(c) {
    reg_weight = NeighbourWeightSums(energy, [&](int a, int b) {
      return energy.MotionRegWeight(a, b, state.labels[a], state.labels[b]);
    });
  }
  double Unary(int p, int label) const override {
    return energy.MotionUnary(p, energy.motion.motions[label], energy.motion.At(p, label),
                              state.labels[p], state.depths[p]);
  }
  double Pairwise(int p, int q, int mp, int mq) const override {
    return cache.At(p, q, energy.width) + energy.PairMotion(p, q, state.labels[p], state.labels[q],
                                                            energy.motion.motions[mp],
                                                            energy.motion.motions[mq]);
  }
  // JointViewOptions::motion_candidates_per_pixel: per pixel, the k-th lowest unary
  // (a pixel may take a motion whose unary is at most that); empty = all.
  std::vector<float> candidate_cut;
  void LimitCandidates(int k) {
    const int num = energy.motion.NumLabels();
    if (k <= 0 || k >= num) return;
    candidate_cut.assign(energy.num_pixels, std::numeric_limits<float>::infinity());
    tbb::parallel_for(0, energy.num_pixels, [&](int p) {
      if (!energy.grid.IsActive(p)) return;
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
    return reg_weight[p] * energy.motion_reg.RhoDecreaseBound(energy.motion.motions[from],
                                                              energy.motion.motions[to]);
  }
};

std::vector<int> Iota(int count) {
  std::vector<int> values(count);
  for (int i = 0; i < count; ++i) values[i] = i;
  return values;
}

// Wall and CPU time of one block, summed per block kind over the rounds.
struct BlockTimes {
  double seconds[3] = {0, 0, 0}, cpu[3] = {0, 0, 0};
  Timer timer;
  std::clock_t cpu_start = std::clock();
  void Start() {
    timer = Timer();
    cpu_start = std::clock();
  }
  // Appends the block's energy to the trace and adds its time to kind `k`.
  void End(int k, const char* block, double energy, JointViewResult* result) {
    result->energy_trace.push_back({block, energy, timer.Seconds()});
    seconds[k] += result->energy_trace.back().seconds;
    cpu[k] += static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  }
};

void RunLabelBlock(const JointEnergy& energy, const JointViewOptions& options, int round,
                   const mrf::ExpansionOptions& expansion_options, JointLabelling* labelling) {
  const std::vector<int> candidates = Iota(energy.num_labels);
  if (options.label_moves_carry_depth && round > 0) {
    const std::vector<int> start_labels = labelling->labels;
    const std::vector<std::vector<int>> carried = NearestLabelDepths(energy, *labelling);
    const LabelDepthBlock block(energy, *labelling, start_labels, carried);
    mrf::AlphaExpansion(energy.grid, block, candidates, &labelling->labels, expansion_options);
    std::vector<int> depths(energy.num_pixels);
    for (int p = 0; p < energy.num_pixels; ++p) depths[p] = block.DepthOf(p, labelling->labels[p]);
    labelling->depths = std::move(depths);
  } else {
    mrf::AlphaExpansion(energy.grid, LabelBlock(energy, *labelling), candidates, &labelling->labels,
                        expansion_options);
  }
}

void RunDepthBlock(const JointEnergy& energy, const JointViewOptions& options, int round,
                   const mrf::ExpansionOptions& expansion_options, JointLabelling* labelling) {
  // The coarse depth pass: every depth_coarse_step-th depth, the farthest and U.
  std::vector<int> coarse;
  if (options.depth_coarse_step > 1) {
    for (int i = 0; i < energy.unknown; i += options.depth_coarse_step) coarse.push_back(i);
    if (coarse.back() != energy.unknown - 1) coarse.push_back(energy.unknown - 1);
    coarse.push_back(energy.unknown);
  }
  PairCache cache;
  cache.Fill(energy, *labelling, PairCache::Part::kMotion);
  DepthBlock block(energy, *labelling, cache);
  // The band of the later rounds (depth_refine_band) holds for every depth
  // pass of those rounds; a coarse-to-fine fine pass keeps the narrower one.
  const int refine_band =
      round > 0 && options.depth_refine_band > 0 ? options.depth_refine_band : -1;
  block.band = refine_band;
  if (!coarse.empty()) {
    mrf::AlphaExpansion(energy.grid, block, coarse, &labelling->depths, expansion_options);
    block.band = refine_band < 0 ? options.depth_coarse_step
                                 : std::min(refine_band, options.depth_coarse_step);
  }
  mrf::AlphaExpansion(energy.grid, block, Iota(energy.unknown + 1), &labelling->depths,
                      expansion_options);
}

void RunMotionBlock(const JointEnergy& energy, const JointViewOptions& options,
                    const mrf::ExpansionOptions& expansion_options, JointLabelling* labelling) {
  PairCache cache;
  cache.Fill(energy, *labelling, PairCache::Part::kLabelDepth);
  MotionBlock block(energy, *labelling, cache);
  block.LimitCandidates(options.motion_candidates_per_pixel);
  mrf::AlphaExpansion(energy.grid, block, Iota(energy.motion.NumLabels()), &labelling->motions,
                      expansion_options);
  energy.SetMotionsFromLabels(labelling);
}

}  // namespace

void RunBlockSchedule(const JointEnergy& energy, const JointViewOptions& options, bool has_next,
                      JointLabelling* labelling, JointViewResult* result) {
  mrf::ExpansionOptions expansion_options;
  expansion_options.max_sweeps = options.sweeps_per_block;
  expansion_options.algorithm = options.algorithm;
  BlockTimes times;
  for (int round = 0; round < options.rounds; ++round) {
    times.Start();
    RunLabelBlock(energy, options, round, expansion_options, labelling);
    times.End(0, "labels", energy.EnergyOf(*labelling), result);
    times.Start();
    RunDepthBlock(energy, options, round, expansion_options, labelling);
    times.End(1, "depth", energy.EnergyOf(*labelling), result);
    if (has_next && round < options.motion_rounds) {
      times.Start();
      RunMotionBlock(energy, options, expansion_options, labelling);
      times.End(2, "motion", energy.EnergyOf(*labelling), result);
    }
  }
  result->phases.push_back({"labels", times.seconds[0], times.cpu[0]});
  result->phases.push_back({"depth", times.seconds[1], times.cpu[1]});
  if (has_next) result->phases.push_back({"motion", times.seconds[2], times.cpu[2]});
}

}  // namespace u4d
