// Throughput of the mrf module (docs/mrf.md): s-t max-flow on a 480x270
// grid with stereo-like terminal weights (own Boykov-Kolmogorov vs
// boost::boykov_kolmogorov_max_flow, same run), one alpha-expansion move and
// a full alpha-expansion on a 480x270, 32-label Potts problem.
//   build-mrf/bench/mrf_bench
#include <algorithm>
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "mrf_bench_graph.h"
#include "u4d/mrf/expansion.h"
#include "u4d/mrf/max_flow.h"

namespace u4d::mrf {
namespace {

using bench::kHeight;
using bench::kLabels;
using bench::kWidth;
using bench::StereoGraph;
using bench::TrueDisparity;

void BM_MaxFlow(benchmark::State& state) {
  const auto algorithm = static_cast<MaxFlowAlgorithm>(state.range(0));
  const FlowGraph graph = StereoGraph(static_cast<int>(state.range(1)));
  MinCutSolver solver;
  MinCut cut;
  for (auto _ : state) {
    solver.Solve(graph, algorithm, &cut);
    benchmark::DoNotOptimize(
        cut.sink_side.data());  // (DoNotOptimize on a double corrupts it with GCC)
  }
  state.SetLabel(ToString(algorithm) + " " + std::to_string(state.range(1)) + "-conn");
  state.counters["flow"] = cut.flow;
  state.SetItemsProcessed(state.iterations() * graph.num_nodes);
}
BENCHMARK(BM_MaxFlow)
    ->ArgsProduct({{static_cast<int>(MaxFlowAlgorithm::kBoykovKolmogorov),
                    static_cast<int>(MaxFlowAlgorithm::kBoostBoykovKolmogorov)},
                   {4, 8}})
    ->Unit(benchmark::kMillisecond);

// 32-label stereo-like Potts energy: truncated linear matching cost + noise.
class PottsEnergy : public GridEnergy {
 public:
  PottsEnergy() : unary_(static_cast<size_t>(kWidth) * kHeight * kLabels) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const double d = TrueDisparity(x, y);
        for (int l = 0; l < kLabels; ++l) {
          unary_[(y * kWidth + x) * kLabels + l] =
              static_cast<float>(std::min(std::abs(l - d), 4.0)) + 3 * u(rng);
        }
      }
    }
  }
  double Unary(int p, int l) const override { return unary_[p * kLabels + l]; }
  double Pairwise(int, int, int lp, int lq) const override { return lp == lq ? 0.0 : 1.5; }

  std::vector<int> WinnerTakesAll() const {
    std::vector<int> labels(kWidth * kHeight);
    for (int p = 0; p < kWidth * kHeight; ++p) {
      const float* c = &unary_[p * kLabels];
      labels[p] = static_cast<int>(std::min_element(c, c + kLabels) - c);
    }
    return labels;
  }

 private:
  std::vector<float> unary_;
};

GridGraph Grid(int connectivity) {
  GridGraph grid;
  grid.width = kWidth;
  grid.height = kHeight;
  grid.connectivity = connectivity;
  return grid;
}

void BM_ExpansionMove(benchmark::State& state) {
  const auto algorithm = static_cast<MaxFlowAlgorithm>(state.range(0));
  const GridGraph grid = Grid(8);
  const PottsEnergy energy;
  const std::vector<int> initial = energy.WinnerTakesAll();
  std::vector<int> labels;
  int alpha = 0;
  long changed = 0;
  for (auto _ : state) {
    state.PauseTiming();
    labels = initial;
    alpha = (alpha + 7) % kLabels;
    state.ResumeTiming();
    changed += ExpansionMove(grid, energy, alpha, &labels, algorithm).changed_pixels;
  }
  state.SetLabel(ToString(algorithm) + " 8-conn, 32 labels");
  state.counters["changed_px"] = static_cast<double>(changed) / state.iterations();
  state.SetItemsProcessed(state.iterations() * grid.NumPixels());
}
BENCHMARK(BM_ExpansionMove)
    ->Arg(static_cast<int>(MaxFlowAlgorithm::kBoykovKolmogorov))
    ->Arg(static_cast<int>(MaxFlowAlgorithm::kBoostBoykovKolmogorov))
    ->Unit(benchmark::kMillisecond);

void BM_AlphaExpansion(benchmark::State& state) {
  const auto algorithm = static_cast<MaxFlowAlgorithm>(state.range(0));
  const GridGraph grid = Grid(8);
  const PottsEnergy energy;
  const std::vector<int> initial = energy.WinnerTakesAll();
  std::vector<int> candidates(kLabels);
  for (int l = 0; l < kLabels; ++l) candidates[l] = l;
  ExpansionOptions options;
  options.algorithm = algorithm;
  ExpansionSummary summary;
  for (auto _ : state) {
    std::vector<int> labels = initial;
    summary = AlphaExpansion(grid, energy, candidates, &labels, options);
    benchmark::DoNotOptimize(labels.data());
  }
  int correct = 0;  // labels within 1 of the true disparity, last run
  std::vector<int> labels = initial;
  AlphaExpansion(grid, energy, candidates, &labels, options);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      correct += std::abs(labels[y * kWidth + x] - TrueDisparity(x, y)) <= 1.0;
  int wta_correct = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      wta_correct += std::abs(initial[y * kWidth + x] - TrueDisparity(x, y)) <= 1.0;
  state.SetLabel(ToString(algorithm) + " 8-conn, 32 labels");
  state.counters["sweeps"] = summary.sweeps;
  state.counters["E0"] = summary.initial_energy;
  state.counters["E"] = summary.final_energy;
  state.counters["acc_wta"] = static_cast<double>(wta_correct) / grid.NumPixels();
  state.counters["acc"] = static_cast<double>(correct) / grid.NumPixels();
}
BENCHMARK(BM_AlphaExpansion)
    ->Arg(static_cast<int>(MaxFlowAlgorithm::kBoykovKolmogorov))
    ->Arg(static_cast<int>(MaxFlowAlgorithm::kBoostBoykovKolmogorov))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace u4d::mrf

BENCHMARK_MAIN();
