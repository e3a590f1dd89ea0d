// Own Boykov-Kolmogorov max-flow (see max_flow.h). Implemented from the
// description in Boykov & Kolmogorov, PAMI 2004, Sec. 3:
//  - two search trees S (rooted at the source) and T (rooted at the sink)
//    whose edges are non-saturated; every tree node stores its parent arc;
//  - growth: active nodes acquire free neighbours through residual arcs until
//    a tree touches the other one, which gives an s-t path;
//  - augmentation: push the bottleneck along the path; nodes whose parent arc
//    (or terminal arc) saturates become orphans;
//  - adoption: each orphan looks for a new valid parent in its tree (one whose
//    root is a terminal); preferring the one closest to the root (timestamp +
//    distance marks); failing that it becomes free, its children become
//    orphans and its tree neighbours with residual arcs to it become active.
// The graph is stored as CSR arrays: for node i the arcs first_[i] ..
// first_[i+1]-1, each with its head, its reverse ("sister") arc and its
// residual capacity. Terminal arcs are folded into one signed residual per
// node, tr_ > 0 meaning residual from s, tr_ < 0 residual to t.
#include "u4d/mrf/max_flow.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "u4d/util/check.h"

namespace u4d::mrf {

// Defined in boost_max_flow.cc.
double SolveBoostBoykovKolmogorov(const FlowGraph& graph, std::vector<uint8_t>* sink_side);

std::string ToString(MaxFlowAlgorithm algorithm) {
  switch (algorithm) {
    case MaxFlowAlgorithm::kBoykovKolmogorov:
      return "bk";
    case MaxFlowAlgorithm::kBoostBoykovKolmogorov:
      return "boost_bk";
  }
  return "unknown";
}

MaxFlowAlgorithm MaxFlowAlgorithmFromString(const std::string& name) {
  if (name == "bk") return MaxFlowAlgorithm::kBoykovKolmogorov;
  if (name == "boost_bk") return MaxFlowAlgorithm::kBoostBoykovKolmogorov;
  ThrowError(fmt::format("unknown max-flow algorithm '{}': expected 'bk' or 'boost_bk'", name));
}

FlowGraph::FlowGraph(int n) { Reset(n); }

void FlowGraph::Reset(int n) {
  U4D_CHECK(n >= 0, "FlowGraph: the number of nodes must be >= 0, got {}", n);
  num_nodes = n;
  source_cap.assign(n, 0.0);
  sink_cap.assign(n, 0.0);
  edges.clear();
}

int FlowGraph::AddNode() {
  source_cap.push_back(0.0);
  sink_cap.push_back(0.0);
  return num_nodes++;
}

namespace {
bool ValidCap(double c) { return std::isfinite(c) && c >= 0; }
}  // namespace

void FlowGraph::AddTerminalWeights(int node, double source, double sink) {
  U4D_CHECK(node >= 0 && node < num_nodes, "FlowGraph::AddTerminalWeights: node {} not in [0, {})",
            node, num_nodes);
  U4D_CHECK(ValidCap(source) && ValidCap(sink),
            "FlowGraph::AddTerminalWeights: capacities must be finite and >= 0, got {} and {}",
            source, sink);
  source_cap[node] += source;
  sink_cap[node] += sink;
}

void FlowGraph::AddEdge(int i, int j, double cap_ij, double cap_ji) {
  U4D_CHECK(i >= 0 && i < num_nodes && j >= 0 && j < num_nodes,
            "FlowGraph::AddEdge: nodes ({}, {}) not in [0, {})", i, j, num_nodes);
  U4D_CHECK(ValidCap(cap_ij) && ValidCap(cap_ji),
            "FlowGraph::AddEdge: capacities must be finite and >= 0, got {} and {}", cap_ij,
            cap_ji);
  edges.push_back({i, j, cap_ij, cap_ji});
}

double CutCapacity(const FlowGraph& g, const std::vector<uint8_t>& sink_side) {
  U4D_CHECK(static_cast<int>(sink_side.size()) == g.num_nodes,
            "CutCapacity: sink_side has {} entries, the graph {} nodes", sink_side.size(),
            g.num_nodes);
  double c = 0;
  for (int i = 0; i < g.num_nodes; ++i) c += sink_side[i] ? g.source_cap[i] : g.sink_cap[i];
  for (const FlowGraph::Edge& e : g.edges) {
    if (!sink_side[e.i] && sink_side[e.j]) c += e.cap_ij;
    if (sink_side[e.i] && !sink_side[e.j]) c += e.cap_ji;
  }
  return c;
}

namespace {

void CheckGraph(const FlowGraph& g) {
  U4D_CHECK(g.num_nodes >= 0 && static_cast<int>(g.source_cap.size()) == g.num_nodes &&
                static_cast<int>(g.sink_cap.size()) == g.num_nodes,
            "FlowGraph: num_nodes = {} but {} source and {} sink capacities", g.num_nodes,
            g.source_cap.size(), g.sink_cap.size());
  for (int i = 0; i < g.num_nodes; ++i) {
    U4D_CHECK(ValidCap(g.source_cap[i]) && ValidCap(g.sink_cap[i]),
              "FlowGraph: terminal capacities of node {} must be finite and >= 0, got {} and {}", i,
              g.source_cap[i], g.sink_cap[i]);
  }
  for (const FlowGraph::Edge& e : g.edges) {
    U4D_CHECK(e.i >= 0 && e.i < g.num_nodes && e.j >= 0 && e.j < g.num_nodes,
              "FlowGraph: edge ({}, {}) not in [0, {})", e.i, e.j, g.num_nodes);
    U4D_CHECK(ValidCap(e.cap_ij) && ValidCap(e.cap_ji),
              "FlowGraph: edge ({}, {}) capacities must be finite and >= 0, got {} and {}", e.i,
              e.j, e.cap_ij, e.cap_ji);
  }
}

constexpr int kTerminal = -1;  // parent_ of a tree root (attached to s or t directly)
constexpr int kOrphan = -2;
constexpr int kNoParent = -3;  // free node
constexpr uint8_t kFree = 0, kSource = 1, kSink = 2;
constexpr int kInfiniteDist = std::numeric_limits<int>::max();

class BoykovKolmogorov {
 public:
  double Solve(const FlowGraph& g, std::vector<uint8_t>* sink_side) {
    Build(g);
    double flow = Init(g);
    int current = -1;
    while (true) {
      int i = current;
      current = -1;
      if (i < 0 || tree_[i] == kFree) {
        i = NextActive();
        if (i < 0) break;
      }
      // Growth from i.
      int from = -1, to = -1, middle = -1;  // middle arc: from (S side) -> to (T side)
      const int end = first_[i + 1];
      if (tree_[i] == kSource) {
        for (int a = first_[i]; a < end; ++a) {
          if (rcap_[a] <= 0) continue;
          const int j = head_[a];
          if (tree_[j] == kFree) {
            tree_[j] = kSource;
            parent_[j] = sister_[a];
            ts_[j] = ts_[i];
            dist_[j] = dist_[i] + 1;
            SetActive(j);
          } else if (tree_[j] == kSink) {
            from = i, to = j, middle = a;
            break;
          } else if (ts_[j] <= ts_[i] && dist_[j] > dist_[i]) {
            parent_[j] = sister_[a];
            ts_[j] = ts_[i];
            dist_[j] = dist_[i] + 1;
          }
        }
      } else {
        for (int a = first_[i]; a < end; ++a) {
          const int b = sister_[a];  // arc j -> i
          if (rcap_[b] <= 0) continue;
          const int j = head_[a];
          if (tree_[j] == kFree) {
            tree_[j] = kSink;
            parent_[j] = b;
            ts_[j] = ts_[i];
            dist_[j] = dist_[i] + 1;
            SetActive(j);
          } else if (tree_[j] == kSource) {
            from = j, to = i, middle = b;
            break;
          } else if (ts_[j] <= ts_[i] && dist_[j] > dist_[i]) {
            parent_[j] = b;
            ts_[j] = ts_[i];
            dist_[j] = dist_[i] + 1;
          }
        }
      }
      if (middle < 0) continue;  // i is exhausted: it leaves the active set
      ++time_;
      flow += Augment(from, to, middle);
      Adopt();
      if (tree_[i] != kFree) current = i;  // i may still reach the other tree
    }
    sink_side->assign(n_, 0);
    for (int i = 0; i < n_; ++i) (*sink_side)[i] = tree_[i] == kSink ? 1 : 0;
    return flow;
  }

 private:
  void Build(const FlowGraph& g) {
    n_ = g.num_nodes;
    first_.assign(n_ + 1, 0);
    for (const FlowGraph::Edge& e : g.edges) {
      if (e.i == e.j || (e.cap_ij <= 0 && e.cap_ji <= 0)) continue;
      ++first_[e.i + 1];
      ++first_[e.j + 1];
    }
    for (int i = 0; i < n_; ++i) first_[i + 1] += first_[i];
    const int num_arcs = first_[n_];
    head_.resize(num_arcs);
    sister_.resize(num_arcs);
    rcap_.resize(num_arcs);
    fill_.assign(first_.begin(), first_.end() - 1);
    for (const FlowGraph::Edge& e : g.edges) {
      if (e.i == e.j || (e.cap_ij <= 0 && e.cap_ji <= 0)) continue;
      const int a = fill_[e.i]++, b = fill_[e.j]++;
      head_[a] = e.j, sister_[a] = b, rcap_[a] = e.cap_ij;
      head_[b] = e.i, sister_[b] = a, rcap_[b] = e.cap_ji;
    }
  }

  double Init(const FlowGraph& g) {
    tr_.resize(n_);
    parent_.assign(n_, kNoParent);
    tree_.assign(n_, kFree);
    ts_.assign(n_, 0);
    dist_.assign(n_, 0);
    in_active_.assign(n_, 0);
    active_.clear();
    active_head_ = 0;
    orphans_.clear();
    time_ = 0;
    double flow = 0;
    for (int i = 0; i < n_; ++i) {
      const double s = g.source_cap[i], t = g.sink_cap[i];
      flow += std::min(s, t);
      tr_[i] = s - t;
      if (tr_[i] != 0) {
        tree_[i] = tr_[i] > 0 ? kSource : kSink;
        parent_[i] = kTerminal;
        dist_[i] = 1;
        SetActive(i);
      }
    }
    return flow;
  }

  void SetActive(int i) {
    if (in_active_[i]) return;
    in_active_[i] = 1;
    active_.push_back(i);
  }

  // The next active node still in a tree, or -1 when none is left.
  int NextActive() {
    while (active_head_ < active_.size()) {
      const int i = active_[active_head_++];
      in_active_[i] = 0;
      if (tree_[i] != kFree) return i;
    }
    active_.clear();
    active_head_ = 0;
    return -1;
  }

  void MakeOrphan(int i) {
    parent_[i] = kOrphan;
    orphans_.push_back(i);
  }

  // Pushes the bottleneck along s -> ... -> from -> to -> ... -> t.
  double Augment(int from, int to, int middle) {
    double b = rcap_[middle];
    int u = from;
    for (; parent_[u] != kTerminal; u = head_[parent_[u]])
      b = std::min(b, rcap_[sister_[parent_[u]]]);
    b = std::min(b, tr_[u]);
    int v = to;
    for (; parent_[v] != kTerminal; v = head_[parent_[v]]) b = std::min(b, rcap_[parent_[v]]);
    b = std::min(b, -tr_[v]);
    U4D_ASSERT(b > 0);

    rcap_[middle] -= b;
    rcap_[sister_[middle]] += b;
    for (u = from; parent_[u] != kTerminal;) {
      const int up = parent_[u];  // u -> parent
      const int down = sister_[up];
      rcap_[down] -= b;
      rcap_[up] += b;
      const int next = head_[up];
      if (rcap_[down] <= 0) MakeOrphan(u);
      u = next;
    }
    tr_[u] -= b;
    if (tr_[u] <= 0) MakeOrphan(u);
    for (v = to; parent_[v] != kTerminal;) {
      const int up = parent_[v];
      rcap_[up] -= b;
      rcap_[sister_[up]] += b;
      const int next = head_[up];
      if (rcap_[up] <= 0) MakeOrphan(v);
      v = next;
    }
    tr_[v] += b;
    if (tr_[v] >= 0) MakeOrphan(v);
    return b;
  }

  // True when arc a (out of node u, into head j of the same tree) can be the
  // parent arc of u: it carries residual flow in the tree's direction.
  bool ResidualTowardsTree(uint8_t tree, int a) const {
    return tree == kSource ? rcap_[sister_[a]] > 0 : rcap_[a] > 0;
  }

  void Adopt() {
    for (size_t k = 0; k < orphans_.size(); ++k) {
      const int u = orphans_[k];
      const uint8_t tree = tree_[u];
      int best_arc = -1;
      int best_dist = kInfiniteDist;
      const int end = first_[u + 1];
      for (int a = first_[u]; a < end; ++a) {
        const int j = head_[a];
        if (tree_[j] != tree || !ResidualTowardsTree(tree, a)) continue;
        // Does j's parent chain reach the terminal? Count its length.
        int d = 0;
        int w = j;
        while (true) {
          if (ts_[w] == time_) {
            d += dist_[w];
            break;
          }
          ++d;
          if (parent_[w] == kTerminal) {
            ts_[w] = time_;
            dist_[w] = 1;
            break;
          }
          if (parent_[w] == kOrphan) {
            d = kInfiniteDist;
            break;
          }
          w = head_[parent_[w]];
        }
        if (d == kInfiniteDist) continue;
        if (d < best_dist) best_arc = a, best_dist = d;
        for (w = j; ts_[w] != time_; w = head_[parent_[w]]) {
          ts_[w] = time_;
          dist_[w] = d--;
        }
      }
      if (best_arc >= 0) {
        parent_[u] = best_arc;
        ts_[u] = time_;
        dist_[u] = best_dist + 1;
        continue;
      }
      // No valid parent: u becomes free.
      for (int a = first_[u]; a < end; ++a) {
        const int j = head_[a];
        if (tree_[j] != tree) continue;
        if (ResidualTowardsTree(tree, a)) SetActive(j);
        const int pj = parent_[j];
        if (pj >= 0 && head_[pj] == u) MakeOrphan(j);
      }
      tree_[u] = kFree;
      parent_[u] = kNoParent;
    }
    orphans_.clear();
  }

  int n_ = 0;
  std::vector<int> first_, fill_, head_, sister_;
  std::vector<double> rcap_, tr_;
  std::vector<int> parent_, ts_, dist_;
  std::vector<uint8_t> tree_, in_active_;
  std::vector<int> active_;
  size_t active_head_ = 0;
  std::vector<int> orphans_;
  int time_ = 0;
};

}  // namespace

struct MinCutSolver::Impl {
  BoykovKolmogorov bk;
};

MinCutSolver::MinCutSolver() : impl_(std::make_unique<Impl>()) {}
MinCutSolver::~MinCutSolver() = default;

void MinCutSolver::Solve(const FlowGraph& graph, MaxFlowAlgorithm algorithm, MinCut* cut) {
  CheckGraph(graph);
  switch (algorithm) {
    case MaxFlowAlgorithm::kBoykovKolmogorov:
      cut->flow = impl_->bk.Solve(graph, &cut->sink_side);
      return;
    case MaxFlowAlgorithm::kBoostBoykovKolmogorov:
      cut->flow = SolveBoostBoykovKolmogorov(graph, &cut->sink_side);
      return;
  }
  ThrowError(fmt::format("SolveMinCut: unknown algorithm {}", static_cast<int>(algorithm)));
}

MinCut SolveMinCut(const FlowGraph& graph, MaxFlowAlgorithm algorithm) {
  MinCutSolver solver;
  MinCut cut;
  solver.Solve(graph, algorithm, &cut);
  return cut;
}

}  // namespace u4d::mrf
