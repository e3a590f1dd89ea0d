#include "u4d/mrf/max_flow.h"

#include <algorithm>
#include <queue>
#include <random>

#include <gtest/gtest.h>

#include "u4d/util/testing.h"

namespace u4d::mrf {
namespace {

constexpr MaxFlowAlgorithm kAlgorithms[] = {MaxFlowAlgorithm::kBoykovKolmogorov,
                                            MaxFlowAlgorithm::kBoostBoykovKolmogorov};

// Reference: Edmonds-Karp on a dense capacity matrix (s = n, t = n + 1).
double EdmondsKarp(const FlowGraph& g) {
  const int n = g.num_nodes + 2, s = g.num_nodes, t = g.num_nodes + 1;
  std::vector<std::vector<double>> cap(n, std::vector<double>(n, 0.0));
  for (int i = 0; i < g.num_nodes; ++i) {
    cap[s][i] += g.source_cap[i];
    cap[i][t] += g.sink_cap[i];
  }
  for (const auto& e : g.edges) {
    if (e.i == e.j) continue;
    cap[e.i][e.j] += e.cap_ij;
    cap[e.j][e.i] += e.cap_ji;
  }
  double flow = 0;
  while (true) {
    std::vector<int> prev(n, -1);
    prev[s] = s;
    std::queue<int> queue;
    queue.push(s);
    while (!queue.empty() && prev[t] < 0) {
      const int u = queue.front();
      queue.pop();
      for (int v = 0; v < n; ++v) {
        if (prev[v] < 0 && cap[u][v] > 1e-12) {
          prev[v] = u;
          queue.push(v);
        }
      }
    }
    if (prev[t] < 0) return flow;
    double b = 1e300;
    for (int v = t; v != s; v = prev[v]) b = std::min(b, cap[prev[v]][v]);
    for (int v = t; v != s; v = prev[v]) {
      cap[prev[v]][v] -= b;
      cap[v][prev[v]] += b;
    }
    flow += b;
  }
}

// Reference: the minimum over all 2^n cuts.
double BruteForceMinCut(const FlowGraph& g) {
  double best = 1e300;
  std::vector<uint8_t> side(g.num_nodes);
  for (int mask = 0; mask < (1 << g.num_nodes); ++mask) {
    for (int i = 0; i < g.num_nodes; ++i) side[i] = (mask >> i) & 1;
    best = std::min(best, CutCapacity(g, side));
  }
  return best;
}

FlowGraph RandomGraph(std::mt19937& rng, int n, int num_edges, bool integer) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto cap = [&](double scale) {
    if (u(rng) < 0.3) return 0.0;  // many zeros: exercises saturated / free nodes
    return integer ? std::floor(u(rng) * scale) : u(rng) * scale;
  };
  FlowGraph g(n);
  for (int i = 0; i < n; ++i) g.AddTerminalWeights(i, cap(10), cap(10));
  std::uniform_int_distribution<int> node(0, n - 1);
  for (int e = 0; e < num_edges; ++e) g.AddEdge(node(rng), node(rng), cap(8), cap(8));
  return g;
}

TEST(MaxFlowTest, MatchesReferencesOnRandomSmallGraphs) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 600; ++trial) {
    const int n = 1 + trial % 10;
    const FlowGraph g = RandomGraph(rng, n, static_cast<int>(rng() % (3 * n + 1)), trial % 2 == 0);
    const double reference = EdmondsKarp(g);
    ASSERT_NEAR(reference, BruteForceMinCut(g), 1e-9);  // max-flow = min-cut (references agree)
    for (const MaxFlowAlgorithm algorithm : kAlgorithms) {
      const MinCut cut = SolveMinCut(g, algorithm);
      ASSERT_NEAR(cut.flow, reference, 1e-9) << ToString(algorithm) << " trial " << trial;
      ASSERT_EQ(cut.sink_side.size(), static_cast<size_t>(n));
      ASSERT_NEAR(CutCapacity(g, cut.sink_side), cut.flow, 1e-9)
          << ToString(algorithm) << " trial " << trial;
    }
  }
}

// Larger grids with many augmentations, orphans and adoptions: both BK
// implementations must agree with Edmonds-Karp and return a cut of that capacity.
TEST(MaxFlowTest, GridsAgreeWithEdmondsKarp) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 6; ++trial) {
    const int w = 12, h = 10;
    FlowGraph g(w * h);
    for (int i = 0; i < w * h; ++i) g.AddTerminalWeights(i, 5 * u(rng), 5 * u(rng));
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (x + 1 < w) g.AddEdge(y * w + x, y * w + x + 1, 3 * u(rng), 3 * u(rng));
        if (y + 1 < h) g.AddEdge(y * w + x, (y + 1) * w + x, 3 * u(rng), 3 * u(rng));
        if (trial % 2 && x + 1 < w && y + 1 < h) {
          g.AddEdge(y * w + x, (y + 1) * w + x + 1, u(rng), u(rng));
        }
      }
    }
    const double reference = EdmondsKarp(g);
    for (const MaxFlowAlgorithm algorithm : kAlgorithms) {
      const MinCut cut = SolveMinCut(g, algorithm);
      EXPECT_NEAR(cut.flow, reference, 1e-7 * reference) << ToString(algorithm);
      EXPECT_NEAR(CutCapacity(g, cut.sink_side), reference, 1e-7 * reference);
    }
  }
}

TEST(MaxFlowTest, SolverReuseGivesSameResults) {
  std::mt19937 rng(3);
  MinCutSolver solver;
  MinCut cut;
  for (int trial = 0; trial < 50; ++trial) {
    const FlowGraph g = RandomGraph(rng, 2 + trial % 7, 12, false);
    solver.Solve(g, MaxFlowAlgorithm::kBoykovKolmogorov, &cut);
    EXPECT_NEAR(cut.flow, EdmondsKarp(g), 1e-9);
  }
}

TEST(MaxFlowTest, EmptyAndTerminalOnlyGraphs) {
  EXPECT_EQ(SolveMinCut(FlowGraph(0)).flow, 0);
  FlowGraph g(2);
  g.AddTerminalWeights(0, 3, 1);
  g.AddTerminalWeights(0, 0, 1);  // accumulates: (3, 2)
  g.AddTerminalWeights(1, 1, 4);
  for (const MaxFlowAlgorithm algorithm : kAlgorithms) {
    const MinCut cut = SolveMinCut(g, algorithm);
    EXPECT_DOUBLE_EQ(cut.flow, 3.0);
    EXPECT_EQ(cut.sink_side[1], 1);
  }
  EXPECT_EQ(g.AddNode(), 2);
  EXPECT_EQ(g.num_nodes, 3);
}

TEST(MaxFlowTest, NamesAndBadInput) {
  for (const MaxFlowAlgorithm algorithm : kAlgorithms) {
    EXPECT_EQ(MaxFlowAlgorithmFromString(ToString(algorithm)), algorithm);
  }
  test_util::ExpectErrorMentions([] { MaxFlowAlgorithmFromString("push_relabel"); },
                                 {"push_relabel", "bk"});
  FlowGraph g(2);
  test_util::ExpectErrorMentions([&] { g.AddEdge(0, 2, 1, 1); }, {"AddEdge", "2"});
  test_util::ExpectErrorMentions([&] { g.AddEdge(0, 1, -1, 1); }, {"AddEdge", "-1"});
  test_util::ExpectErrorMentions([&] { g.AddTerminalWeights(0, 1, std::nan("")); },
                                 {"AddTerminalWeights"});
  g.edges.push_back({0, 5, 1, 1});  // bypassing AddEdge is caught by the solver
  test_util::ExpectErrorMentions([&] { SolveMinCut(g); }, {"edge (0, 5)"});
}

}  // namespace
}  // namespace u4d::mrf
