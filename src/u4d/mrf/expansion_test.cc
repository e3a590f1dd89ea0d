#include "u4d/mrf/expansion.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "u4d/util/testing.h"

namespace u4d::mrf {
namespace {

// Unary table (pixel x label) and pairwise = weight(p, q) * table(lp, lq),
// the table being arbitrary (non-metric, asymmetric) unless set otherwise.
class TableEnergy : public GridEnergy {
 public:
  TableEnergy(int num_pixels, int num_labels)
      : num_labels_(num_labels),
        unary_(static_cast<size_t>(num_pixels) * num_labels, 0.0),
        pair_weight_(static_cast<size_t>(num_pixels) * 8, 1.0),
        table_(static_cast<size_t>(num_labels) * num_labels, 0.0) {}

  double Unary(int p, int l) const override { return unary_[p * num_labels_ + l]; }
  double Pairwise(int p, int q, int lp, int lq) const override {
    return Weight(p, q) * table_[lp * num_labels_ + lq];
  }
  double& unary(int p, int l) { return unary_[p * num_labels_ + l]; }
  double& table(int a, int b) { return table_[a * num_labels_ + b]; }
  double Table(int a, int b) const { return table_[a * num_labels_ + b]; }
  // A per-pair weight, hashed from (p, q) into a pixel-indexed slot.
  double Weight(int p, int q) const {
    return pair_weight_[(p * 8 + (q - p) % 8 + 8) % pair_weight_.size()];
  }
  std::vector<double>& pair_weights() { return pair_weight_; }

  void Potts() {
    for (int a = 0; a < num_labels_; ++a)
      for (int b = 0; b < num_labels_; ++b) table(a, b) = a == b ? 0.0 : 1.0;
  }

 private:
  int num_labels_;
  std::vector<double> unary_, pair_weight_, table_;
};

GridGraph MakeGrid(int width, int height, int connectivity) {
  GridGraph grid;
  grid.width = width;
  grid.height = height;
  grid.connectivity = connectivity;
  return grid;
}

constexpr MaxFlowAlgorithm kAlgorithms[] = {MaxFlowAlgorithm::kBoykovKolmogorov,
                                            MaxFlowAlgorithm::kBoostBoykovKolmogorov};

// Minimum energy over all num_labels^n labellings.
double BruteForceMinimum(const GridGraph& grid, const GridEnergy& energy, int num_labels) {
  const int n = grid.NumPixels();
  std::vector<int> labels(n, 0);
  double best = 1e300;
  while (true) {
    best = std::min(best, Energy(grid, energy, labels));
    int k = 0;
    while (k < n && ++labels[k] == num_labels) labels[k++] = 0;
    if (k == n) return best;
  }
}

TEST(ExpansionTest, NeverIncreasesEnergyOnNonMetricEnergies) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int nonsubmodular = 0, accepted = 0;
  for (int trial = 0; trial < 40; ++trial) {
    GridGraph grid = MakeGrid(7, 6, trial % 2 ? 8 : 4);
    const int num_labels = 5;
    TableEnergy energy(grid.NumPixels(), num_labels);
    for (int p = 0; p < grid.NumPixels(); ++p) {
      for (int l = 0; l < num_labels; ++l) {
        energy.unary(p, l) = u(rng) < 0.05 ? kInfiniteCost : 3 * u(rng) - 1;
      }
    }
    for (int a = 0; a < num_labels; ++a)
      for (int b = 0; b < num_labels; ++b) energy.table(a, b) = 2 * u(rng);  // non-metric
    for (double& wgt : energy.pair_weights()) wgt = u(rng);
    std::vector<int> labels(grid.NumPixels());
    for (int& l : labels) l = static_cast<int>(rng() % num_labels);
    const MaxFlowAlgorithm algorithm = kAlgorithms[trial % 2];
    for (int move = 0; move < 30; ++move) {
      MoveResult r;
      if (move % 3 == 2) {
        std::vector<int> proposal(grid.NumPixels());
        for (int& l : proposal) l = static_cast<int>(rng() % num_labels);
        r = FusionMove(grid, energy, proposal, &labels, algorithm);
      } else {
        r = ExpansionMove(grid, energy, static_cast<int>(rng() % num_labels), &labels, algorithm);
      }
      ASSERT_LE(r.energy_after, r.energy_before);
      // The reported energy is the true energy of the new labelling.
      ASSERT_NEAR(r.energy_after, Energy(grid, energy, labels),
                  1e-6 * (1 + std::abs(r.energy_after)));
      nonsubmodular += r.nonsubmodular_terms;
      accepted += r.accepted;
    }
    std::vector<int> candidates(num_labels);
    for (int l = 0; l < num_labels; ++l) candidates[l] = l;
    ExpansionOptions options;
    options.algorithm = algorithm;
    const ExpansionSummary s = AlphaExpansion(grid, energy, candidates, &labels, options);
    EXPECT_LE(s.final_energy, s.initial_energy);
    double previous = s.initial_energy;
    for (const double e : s.energy_after_sweep) {
      EXPECT_LE(e, previous);
      previous = e;
    }
    EXPECT_NEAR(s.final_energy, Energy(grid, energy, labels),
                1e-6 * (1 + std::abs(s.final_energy)));
  }
  EXPECT_GT(nonsubmodular, 0);  // the truncation was exercised
  EXPECT_GT(accepted, 0);
}

// A binary submodular energy: a single expansion from the all-0 (all-1)
// labelling is the full binary problem, solved exactly by one min cut.
TEST(ExpansionTest, BinarySubmodularReachesGlobalOptimum) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    GridGraph grid = MakeGrid(3, 3, trial % 2 ? 8 : 4);
    TableEnergy energy(grid.NumPixels(), 2);
    for (int p = 0; p < grid.NumPixels(); ++p) {
      energy.unary(p, 0) = 2 * u(rng) - 1;
      energy.unary(p, 1) = 2 * u(rng) - 1;
    }
    energy.table(0, 0) = u(rng);
    energy.table(1, 1) = u(rng);
    energy.table(0, 1) = u(rng);
    // E01 + E10 >= E00 + E11 (submodular), not necessarily symmetric.
    energy.table(1, 0) = energy.table(0, 0) + energy.table(1, 1) - energy.table(0, 1) + u(rng);
    energy.table(1, 0) = std::max(energy.table(1, 0), 0.0);
    for (double& wgt : energy.pair_weights()) wgt = 2 * u(rng);
    const double optimum = BruteForceMinimum(grid, energy, 2);
    for (const int start : {0, 1}) {
      std::vector<int> labels(grid.NumPixels(), start);
      const MoveResult r = ExpansionMove(grid, energy, 1 - start, &labels, kAlgorithms[trial % 2]);
      EXPECT_EQ(r.nonsubmodular_terms, 0);
      EXPECT_NEAR(Energy(grid, energy, labels), optimum, 1e-9) << "trial " << trial;
    }
  }
}

// Boykov et al. 2001, Thm. 6.1: a local minimum of expansion moves is within
// 2c of the optimum, c = 1 for Potts (non-negative data terms).
TEST(ExpansionTest, PottsWithinFactorTwoOfOptimum) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int strictly_worse = 0;
  for (int trial = 0; trial < 12; ++trial) {
    GridGraph grid = MakeGrid(3, 3, trial % 2 ? 8 : 4);
    const int num_labels = 3;
    TableEnergy energy(grid.NumPixels(), num_labels);
    for (int p = 0; p < grid.NumPixels(); ++p)
      for (int l = 0; l < num_labels; ++l) energy.unary(p, l) = 2 * u(rng);
    energy.Potts();
    for (double& wgt : energy.pair_weights()) wgt = 1.5 * u(rng);
    const double optimum = BruteForceMinimum(grid, energy, num_labels);
    std::vector<int> labels(grid.NumPixels());
    for (int& l : labels) l = static_cast<int>(rng() % num_labels);
    ExpansionOptions options;
    options.max_sweeps = 50;
    options.min_relative_decrease = 0;  // to a local minimum of expansion moves
    options.algorithm = kAlgorithms[trial % 2];
    const ExpansionSummary s = AlphaExpansion(grid, energy, {0, 1, 2}, &labels, options);
    EXPECT_LT(s.sweeps, 50);  // converged
    EXPECT_LE(s.final_energy, 2 * optimum + 1e-9);
    EXPECT_GE(s.final_energy, optimum - 1e-9);
    strictly_worse += s.final_energy > optimum + 1e-9;
  }
  RecordProperty("runs_above_optimum", strictly_worse);
}

// Ground truth denoising: a piecewise-constant image of 4 labels (background
// and 3 rectangles), 30% of the pixels replaced by another random label. Data
// term 1 for disagreeing with the observation, Potts 0.3 per 8-neighbour
// pair. An isolated wrong pixel costs 1 to fix in data but saves ~0.3 * 5
// in smoothness (70% of its 8 neighbours are clean, few share its wrong
// label), so the MAP is the clean image except near rectangle corners:
// expansion should recover >= 97% of the true labels.
TEST(ExpansionTest, DenoisesPiecewiseConstantImage) {
  const int w = 64, h = 48, num_labels = 4;
  std::vector<int> truth(w * h, 0);
  auto fill = [&](int x0, int y0, int x1, int y1, int l) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) truth[y * w + x] = l;
  };
  fill(5, 5, 30, 25, 1);
  fill(35, 8, 58, 40, 2);
  fill(10, 30, 28, 44, 3);
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<int> observed = truth;
  int corrupted = 0;
  for (int& l : observed) {
    if (u(rng) < 0.3) {
      l = (l + 1 + static_cast<int>(rng() % (num_labels - 1))) % num_labels;
      ++corrupted;
    }
  }
  GridGraph grid = MakeGrid(w, h, 8);
  TableEnergy energy(w * h, num_labels);
  for (int p = 0; p < w * h; ++p)
    for (int l = 0; l < num_labels; ++l) energy.unary(p, l) = l == observed[p] ? 0.0 : 1.0;
  energy.Potts();
  for (double& wgt : energy.pair_weights()) wgt = 0.3;
  for (const MaxFlowAlgorithm algorithm : kAlgorithms) {
    std::vector<int> labels = observed;
    ExpansionOptions options;
    options.algorithm = algorithm;
    const ExpansionSummary s = AlphaExpansion(grid, energy, {0, 1, 2, 3}, &labels, options);
    int correct = 0;
    for (int p = 0; p < w * h; ++p) correct += labels[p] == truth[p];
    const double accuracy = static_cast<double>(correct) / (w * h);
    EXPECT_GE(accuracy, 0.97) << ToString(algorithm) << ", corrupted " << corrupted;
    EXPECT_LT(s.final_energy, s.initial_energy);
    EXPECT_LE(Energy(grid, energy, labels), Energy(grid, energy, truth) + 1e-9)
        << "expansion found an energy above the clean image's";
    RecordProperty("accuracy_" + ToString(algorithm), std::to_string(accuracy));
  }
}

TEST(ExpansionTest, InactivePixelsAreUntouched) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  GridGraph grid = MakeGrid(9, 7, 8);
  const int num_labels = 4;
  grid.active.resize(grid.NumPixels());
  for (uint8_t& a : grid.active) a = u(rng) < 0.5;
  TableEnergy energy(grid.NumPixels(), num_labels);
  // Unaries strongly favour label 3 everywhere: active pixels move to it.
  for (int p = 0; p < grid.NumPixels(); ++p)
    for (int l = 0; l < num_labels; ++l) energy.unary(p, l) = l == 3 ? 0.0 : 5 + u(rng);
  energy.Potts();
  std::vector<int> labels(grid.NumPixels());
  for (int& l : labels) l = static_cast<int>(rng() % 3);
  const std::vector<int> initial = labels;
  const ExpansionSummary s = AlphaExpansion(grid, energy, {0, 1, 2, 3}, &labels);
  std::vector<int> proposal(grid.NumPixels(), 0);
  FusionMove(grid, energy, proposal, &labels);
  int moved = 0;
  for (int p = 0; p < grid.NumPixels(); ++p) {
    if (!grid.active[p]) {
      EXPECT_EQ(labels[p], initial[p]) << "inactive pixel " << p;
    } else {
      EXPECT_EQ(labels[p], 3) << "active pixel " << p;
      moved += labels[p] != initial[p];
    }
  }
  EXPECT_GT(moved, 0);
  EXPECT_LT(s.final_energy, s.initial_energy);
}

// TableEnergy with a symmetric metric table that declares the metric bound:
// per neighbour, weight(p, q) * table(from, to) (triangle inequality).
class MetricEnergy : public TableEnergy {
 public:
  MetricEnergy(const GridGraph& grid, int num_labels)
      : TableEnergy(grid.NumPixels(), num_labels), grid_(grid) {}
  double PairwiseDecreaseBound(int p, int from, int to) const override {
    ++bound_calls;
    double sum = 0;
    for (const auto& [a, b] : NeighbourPairs(grid_))
      if (a == p || b == p) sum += Weight(a, b);
    return sum * Table(from, to);
  }
  mutable int bound_calls = 0;

 private:
  GridGraph grid_;
};

// The same energy without the bound (every pixel a graph node).
class UnboundedEnergy : public GridEnergy {
 public:
  explicit UnboundedEnergy(const GridEnergy& e) : e_(e) {}
  double Unary(int p, int l) const override { return e_.Unary(p, l); }
  double Pairwise(int p, int q, int lp, int lq) const override { return e_.Pairwise(p, q, lp, lq); }

 private:
  const GridEnergy& e_;
};

// Leaving out the pixels the bound shows cannot take the proposal changes
// no move's result: alpha-expansion on a weighted truncated-linear energy
// ends at the same labelling and energy, with fewer graph nodes.
TEST(ExpansionTest, PairwiseDecreaseBoundKeepsEveryMoveAndShrinksTheGraph) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int num_labels = 12;
  long long nodes_bounded = 0, nodes_unbounded = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const GridGraph grid = MakeGrid(14, 11, trial % 2 ? 8 : 4);
    MetricEnergy energy(grid, num_labels);
    for (int a = 0; a < num_labels; ++a)
      for (int b = 0; b < num_labels; ++b) energy.table(a, b) = std::min(std::abs(a - b), 3) / 3.0;
    for (double& wgt : energy.pair_weights()) wgt = 0.3 * u(rng);
    // Piecewise-constant truth with noise: most labels are far too costly at most pixels.
    for (int p = 0; p < grid.NumPixels(); ++p) {
      const int truth = (p % grid.width) * num_labels / grid.width;
      for (int l = 0; l < num_labels; ++l)
        energy.unary(p, l) = 0.5 * std::abs(l - truth) + 0.8 * u(rng);
    }
    std::vector<int> start(grid.NumPixels());
    for (int& l : start) l = static_cast<int>(rng() % num_labels);
    std::vector<int> candidates(num_labels);
    for (int l = 0; l < num_labels; ++l) candidates[l] = l;
    ExpansionOptions options;
    options.algorithm = kAlgorithms[trial % 2];
    std::vector<int> bounded = start, unbounded = start;
    const ExpansionSummary a = AlphaExpansion(grid, energy, candidates, &bounded, options);
    const ExpansionSummary b =
        AlphaExpansion(grid, UnboundedEnergy(energy), candidates, &unbounded, options);
    EXPECT_GT(energy.bound_calls, 0);
    EXPECT_NEAR(a.final_energy, b.final_energy, 1e-9 * (1 + std::abs(b.final_energy)));
    EXPECT_EQ(bounded, unbounded);
    EXPECT_EQ(a.sweeps, b.sweeps);
    nodes_bounded += a.graph_nodes;
    nodes_unbounded += b.graph_nodes;
  }
  EXPECT_LT(nodes_bounded, nodes_unbounded / 2);
}

// max over y of rho(|x - y|) - rho(|z - y|) against a dense search over y
// on the line through x and z (where the maximum lies), and never above the
// bound at random points of the plane.
TEST(ExpansionTest, TruncatedDecreaseBoundsAreTight) {
  const auto linear = [](double s) { return std::min(s, 1.0); };
  const auto quadratic = [](double s) { return std::min(s * s, 1.0); };
  for (const double d : {0.0, 0.1, 0.35, 0.5, 0.9, 1.0, 1.7}) {
    double max_linear = -1, max_quadratic = -1;
    for (int i = -4000; i <= 4000; ++i) {
      const double y = i * 1e-3;  // x = 0, z = d on the line
      max_linear = std::max(max_linear, linear(std::abs(y)) - linear(std::abs(d - y)));
      max_quadratic = std::max(max_quadratic, quadratic(std::abs(y)) - quadratic(std::abs(d - y)));
    }
    EXPECT_NEAR(max_linear, TruncatedLinearDecreaseBound(d), 2e-3) << d;
    EXPECT_NEAR(max_quadratic, TruncatedQuadraticDecreaseBound(d), 2e-3) << d;
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int i = 0; i < 20000; ++i) {
    const double x0 = u(rng), x1 = u(rng), z0 = u(rng), z1 = u(rng), y0 = u(rng), y1 = u(rng);
    const double d = std::hypot(x0 - z0, x1 - z1);
    const double sx = std::hypot(x0 - y0, x1 - y1), sz = std::hypot(z0 - y0, z1 - y1);
    ASSERT_LE(linear(sx) - linear(sz), TruncatedLinearDecreaseBound(d) + 1e-12);
    ASSERT_LE(quadratic(sx) - quadratic(sz), TruncatedQuadraticDecreaseBound(d) + 1e-12);
  }
}

// TableEnergy whose moves may only change labels by up to `band`, and only
// at pixels with x >= min_x.
class RestrictedEnergy : public TableEnergy {
 public:
  RestrictedEnergy(int width, int height, int num_labels)
      : TableEnergy(width * height, num_labels), width_(width) {}
  bool MayTake(int p, int current, int proposal) const override {
    return p % width_ >= min_x && std::abs(current - proposal) <= band;
  }
  int band = 1000, min_x = 0;

 private:
  int width_;
};

// MayTake keeps pixels out of the moves: pixels it bars keep their labels
// (the same result as making them inactive), and a banded move cannot jump.
TEST(ExpansionTest, MayTakeRestrictsTheMoves) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int w = 12, h = 9, num_labels = 6;
  const GridGraph grid = MakeGrid(w, h, 8);
  RestrictedEnergy energy(w, h, num_labels);
  for (int a = 0; a < num_labels; ++a)
    for (int b = 0; b < num_labels; ++b) energy.table(a, b) = std::min(std::abs(a - b), 2) * 0.5;
  for (double& wgt : energy.pair_weights()) wgt = 0.4 * u(rng);
  for (int p = 0; p < grid.NumPixels(); ++p)
    for (int l = 0; l < num_labels; ++l) energy.unary(p, l) = 3 * u(rng);
  std::vector<int> candidates(num_labels);
  for (int l = 0; l < num_labels; ++l) candidates[l] = l;
  const std::vector<int> start(grid.NumPixels(), 0);

  // Barred columns = inactive columns.
  energy.min_x = 5;
  std::vector<int> barred = start;
  const ExpansionSummary a = AlphaExpansion(grid, energy, candidates, &barred);
  energy.min_x = 0;
  GridGraph half = grid;
  half.active.assign(grid.NumPixels(), 0);
  for (int p = 0; p < grid.NumPixels(); ++p) half.active[p] = p % w >= 5;
  std::vector<int> inactive = start;
  const ExpansionSummary b = AlphaExpansion(half, energy, candidates, &inactive);
  EXPECT_EQ(barred, inactive);
  EXPECT_NEAR(a.final_energy, b.final_energy, 1e-9);
  EXPECT_LT(a.final_energy, a.initial_energy);
  for (int p = 0; p < grid.NumPixels(); ++p) {
    if (p % w < 5) {
      EXPECT_EQ(barred[p], 0);
    }
  }

  // A band of 1 from all-0: a move to label 3 changes nothing, one to 1 does.
  energy.band = 1;
  std::vector<int> labels = start;
  EXPECT_EQ(ExpansionMove(grid, energy, 3, &labels).changed_pixels, 0);
  EXPECT_EQ(labels, start);
  for (int p = 0; p < grid.NumPixels(); ++p) energy.unary(p, 1) = 0;  // label 1 pays everywhere
  const MoveResult r = ExpansionMove(grid, energy, 1, &labels);
  EXPECT_TRUE(r.accepted);
  EXPECT_LT(r.energy_after, r.energy_before);
  EXPECT_EQ(r.changed_pixels, grid.NumPixels());
}

TEST(ExpansionTest, NeighbourPairsOrderAndCount) {
  GridGraph grid = MakeGrid(4, 3, 8);
  const auto pairs8 = NeighbourPairs(grid);
  // Horizontal 3*3, vertical 4*2, two diagonals 3*2 each.
  EXPECT_EQ(pairs8.size(), 9u + 8u + 6u + 6u);
  EXPECT_TRUE(std::is_sorted(pairs8.begin(), pairs8.end()));
  for (const auto& [p, q] : pairs8) EXPECT_LT(p, q);
  grid.connectivity = 4;
  EXPECT_EQ(NeighbourPairs(grid).size(), 17u);
}

TEST(ExpansionTest, ChecksRejectBadInput) {
  ExpansionOptions options;
  options.max_sweeps = 0;
  test_util::ExpectErrorMentions([&] { options.Check(); }, {"max_sweeps"});
  options = {};
  options.min_relative_decrease = -1;
  test_util::ExpectErrorMentions([&] { options.Check(); }, {"min_relative_decrease"});
  options.min_relative_decrease = std::nan("");
  test_util::ExpectErrorMentions([&] { options.Check(); }, {"min_relative_decrease"});

  GridGraph grid = MakeGrid(3, 2, 6);
  test_util::ExpectErrorMentions([&] { grid.Check(); }, {"connectivity", "6"});
  grid.connectivity = 4;
  grid.active.assign(5, 1);
  test_util::ExpectErrorMentions([&] { grid.Check(); }, {"active", "6", "5"});
  grid.active.clear();
  grid.width = 0;
  test_util::ExpectErrorMentions([&] { grid.Check(); }, {"width"});
  grid.width = 3;

  TableEnergy energy(6, 2);
  std::vector<int> labels(5, 0);
  test_util::ExpectErrorMentions([&] { ExpansionMove(grid, energy, 1, &labels); }, {"labels", "5"});
  labels.assign(6, 0);
  labels[2] = -1;
  test_util::ExpectErrorMentions(
      [&] {
        AlphaExpansion(grid, energy, {0, 1}, &labels);
      },
      {"negative"});
  labels[2] = 0;
  test_util::ExpectErrorMentions(
      [&] {
        AlphaExpansion(grid, energy, {0, -1}, &labels);
      },
      {"candidate label"});
}

}  // namespace
}  // namespace u4d::mrf
