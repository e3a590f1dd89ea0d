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

#include "mrf_bench_graph.h"
#include "u4d/mrf/max_flow.h"
#include "u4d/util/timer.h"

namespace {

using u4d::mrf::bench::kHeight;
using u4d::mrf::bench::kWidth;
using u4d::mrf::bench::StereoGraph;

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
