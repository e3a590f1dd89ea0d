// s-t minimum cut / maximum flow on a capacitated graph, the inner solver of
// the alpha-expansion used for the global optimisation of paper Sec. 2.1
// ("Each iteration is solved by graph-cut using the min-cut/max-flow
// algorithm [Kolmogorov04]").
//
// Two interchangeable algorithms (both the Boykov-Kolmogorov augmenting-path
// method, "An experimental comparison of min-cut/max-flow algorithms for
// energy minimization in vision", PAMI 2004):
//  - kBoykovKolmogorov: U4D's own implementation (max_flow.cc) with source and
//    sink search trees, growth / augmentation / adoption stages, an active
//    FIFO and the timestamp + distance heuristic for adoption, over compact
//    CSR adjacency arrays. Written from the paper's description.
//  - kBoostBoykovKolmogorov: boost::boykov_kolmogorov_max_flow on a
//    boost::adjacency_list (a reference; slower, see docs/mrf.md).
//
// Graph: nodes 0..n-1 plus the implicit terminals s (source) and t (sink).
// Every node has a capacity from s and a capacity to t; every pairwise edge
// (i, j) has a capacity i->j and j->i. Capacities are finite and >= 0
// (doubles, no unit). The result is the maximum flow value = the capacity of
// the returned minimum cut; sink_side[i] = 1 when node i is on the sink side.
// A cut edge is s->i with i on the sink side, i->t with i on the source side,
// and i->j with i on the source and j on the sink side.
//
// Failure modes: an index out of range, a negative or non-finite capacity or
// an unknown algorithm name throw u4d::Error.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace u4d::mrf {

enum class MaxFlowAlgorithm {
  kBoykovKolmogorov,       // own implementation (default, fastest)
  kBoostBoykovKolmogorov,  // boost::boykov_kolmogorov_max_flow
};

// "bk" and "boost_bk".
std::string ToString(MaxFlowAlgorithm algorithm);
// Inverse of ToString; throws u4d::Error naming the valid names on an unknown one.
MaxFlowAlgorithm MaxFlowAlgorithmFromString(const std::string& name);

// A capacitated graph for s-t min cut (plain data).
struct FlowGraph {
  struct Edge {
    int i = 0, j = 0;
    double cap_ij = 0, cap_ji = 0;
  };

  explicit FlowGraph(int num_nodes = 0);

  int num_nodes = 0;
  std::vector<double> source_cap;  // num_nodes: capacity s -> node
  std::vector<double> sink_cap;    // num_nodes: capacity node -> t
  std::vector<Edge> edges;         // pairwise edges (multi-edges and zeros allowed)

  // Resets to `num_nodes` nodes with zero capacities and no edges, keeping the
  // allocated memory (for reuse across moves).
  void Reset(int num_nodes);
  int AddNode();  // returns the new node's index
  // Adds to the terminal capacities of `node` (accumulates). Throws on an index
  // out of range or a negative / non-finite capacity.
  void AddTerminalWeights(int node, double source_cap, double sink_cap);
  // Adds the edge i -> j (cap_ij) and j -> i (cap_ji). Throws as above.
  void AddEdge(int i, int j, double cap_ij, double cap_ji);
};

struct MinCut {
  double flow = 0;                 // maximum flow = capacity of the cut
  std::vector<uint8_t> sink_side;  // num_nodes: 1 = node on the sink side of the cut
};

// Capacity of the cut given by `sink_side` (for tests and checks).
double CutCapacity(const FlowGraph& graph, const std::vector<uint8_t>& sink_side);

// Max flow / min cut of `graph`. With the own BK, the sink side is the final
// sink search tree (nodes in neither tree are on the source side).
MinCut SolveMinCut(const FlowGraph& graph,
                   MaxFlowAlgorithm algorithm = MaxFlowAlgorithm::kBoykovKolmogorov);

// The same, keeping its working buffers between calls (one per thread), so
// repeated solves (one per expansion move) do not reallocate.
class MinCutSolver {
 public:
  MinCutSolver();
  ~MinCutSolver();
  MinCutSolver(const MinCutSolver&) = delete;
  MinCutSolver& operator=(const MinCutSolver&) = delete;

  void Solve(const FlowGraph& graph, MaxFlowAlgorithm algorithm, MinCut* cut);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace u4d::mrf
