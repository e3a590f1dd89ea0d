// MaxFlowAlgorithm::kBoostBoykovKolmogorov: boost::boykov_kolmogorov_max_flow
// on a boost::adjacency_list with the source and sink as two extra vertices.
// GCC 12 reports false maybe-uninitialized warnings inside Boost.Graph 1.74.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>

#include "u4d/mrf/max_flow.h"

namespace u4d::mrf {

namespace {

using Traits = boost::adjacency_list_traits<boost::vecS, boost::vecS, boost::directedS>;
using BoostGraph = boost::adjacency_list<
    boost::vecS, boost::vecS, boost::directedS,
    boost::property<boost::vertex_index_t, long,
                    boost::property<boost::vertex_color_t, boost::default_color_type,
                                    boost::property<boost::vertex_distance_t, long,
                                                    boost::property<boost::vertex_predecessor_t,
                                                                    Traits::edge_descriptor>>>>,
    boost::property<
        boost::edge_capacity_t, double,
        boost::property<boost::edge_residual_capacity_t, double,
                        boost::property<boost::edge_reverse_t, Traits::edge_descriptor>>>>;

void AddArcPair(BoostGraph& g, int u, int v, double cap_uv, double cap_vu) {
  auto capacity = boost::get(boost::edge_capacity, g);
  auto reverse = boost::get(boost::edge_reverse, g);
  const auto a = boost::add_edge(u, v, g).first;
  const auto b = boost::add_edge(v, u, g).first;
  capacity[a] = cap_uv;
  capacity[b] = cap_vu;
  reverse[a] = b;
  reverse[b] = a;
}

}  // namespace

double SolveBoostBoykovKolmogorov(const FlowGraph& graph, std::vector<uint8_t>* sink_side) {
  const int n = graph.num_nodes;
  const int s = n, t = n + 1;
  BoostGraph g(n + 2);
  for (int i = 0; i < n; ++i) {
    if (graph.source_cap[i] > 0) AddArcPair(g, s, i, graph.source_cap[i], 0);
    if (graph.sink_cap[i] > 0) AddArcPair(g, i, t, graph.sink_cap[i], 0);
  }
  for (const FlowGraph::Edge& e : graph.edges) {
    if (e.i == e.j || (e.cap_ij <= 0 && e.cap_ji <= 0)) continue;
    AddArcPair(g, e.i, e.j, e.cap_ij, e.cap_ji);
  }
  const double flow = boost::boykov_kolmogorov_max_flow(g, s, t);
  // Black: source tree, white: sink tree, grey: free (put on the source side).
  auto color = boost::get(boost::vertex_color, g);
  sink_side->assign(n, 0);
  for (int i = 0; i < n; ++i) {
    (*sink_side)[i] = color[i] == boost::white_color ? 1 : 0;
  }
  return flow;
}

}  // namespace u4d::mrf
