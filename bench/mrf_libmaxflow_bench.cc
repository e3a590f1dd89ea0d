// Optional comparison with Boykov & Kolmogorov's own maxflow library
// (libmaxflow, GPL): built only with -DU4D_BENCH_LIBMAXFLOW=ON when the
// library is installed, into this separate executable; nothing else links it.
// Solves the same 480x270 stereo-like graphs as mrf_bench's BM_MaxFlow and
// prints the time of libmaxflow and of U4D's own BK, same run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <graph.h>  // libmaxflow: Graph<captype, tcaptype, flowtype>

#include "u4d/mrf/max_flow.h"
#include "u4d/util/timer.h"

namespace {

constexpr int kWidth = 480, kHeight = 270;

u4d::mrf::FlowGraph StereoGraph(int connectivity) {  // as in mrf_bench.cc
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  u4d::mrf::FlowGraph g(kWidth * kHeight);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const double d = std::clamp(
          10 + 6 * std::sin(x / 60.0) + 3 * std::cos(y / 45.0) + (x > 240 ? 10 : 0), 0.0, 31.0);
      const double c0 = std::min(std::abs(d - 12), 5.0) + 2 * u(rng);
      const double c1 = std::min(std::abs(d - 20), 5.0) + 2 * u(rng);
      g.AddTerminalWeights(y * kWidth + x, std::max(c1 - c0, 0.0), std::max(c0 - c1, 0.0));
    }
  }
  const int dx[] = {1, -1, 0, 1}, dy[] = {0, 1, 1, 1};
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      for (int k = 0; k < 4; ++k) {
        if (connectivity == 4 && (k == 1 || k == 3)) continue;
        const int qx = x + dx[k], qy = y + dy[k];
        if (qx < 0 || qx >= kWidth || qy >= kHeight) continue;
        const double w = (k == 1 || k == 3 ? 0.7 : 1.0) * (0.5 + 1.5 * u(rng));
        g.AddEdge(y * kWidth + x, qy * kWidth + qx, w, w);
      }
    }
  }
  return g;
}

}  // namespace

int main() {
  constexpr int kRepeats = 10;
  for (const int connectivity : {4, 8}) {
    const u4d::mrf::FlowGraph g = StereoGraph(connectivity);
    double lib_flow = 0, own_flow = 0;
    u4d::Timer timer;
    for (int r = 0; r < kRepeats; ++r) {
      using LibGraph = Graph<double, double, double>;
      LibGraph lib(g.num_nodes, static_cast<int>(g.edges.size()));
      lib.add_node(g.num_nodes);
      for (int i = 0; i < g.num_nodes; ++i) lib.add_tweights(i, g.source_cap[i], g.sink_cap[i]);
      for (const auto& e : g.edges) lib.add_edge(e.i, e.j, e.cap_ij, e.cap_ji);
      lib_flow = lib.maxflow();
    }
    const double lib_ms = 1e3 * timer.Seconds() / kRepeats;
    u4d::mrf::MinCutSolver solver;
    u4d::mrf::MinCut cut;
    timer.Restart();
    for (int r = 0; r < kRepeats; ++r) {
      solver.Solve(g, u4d::mrf::MaxFlowAlgorithm::kBoykovKolmogorov, &cut);
      own_flow = cut.flow;
    }
    const double own_ms = 1e3 * timer.Seconds() / kRepeats;
    std::printf("%d-conn 480x270: libmaxflow %.2f ms (flow %.4f), own bk %.2f ms (flow %.4f)\n",
                connectivity, lib_ms, lib_flow, own_ms, own_flow);
  }
  return 0;
}
