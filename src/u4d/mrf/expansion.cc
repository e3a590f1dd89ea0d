#include "u4d/mrf/expansion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "u4d/util/check.h"
#include "u4d/util/timer.h"

namespace u4d::mrf {

void GridGraph::Check() const {
  U4D_CHECK(width > 0 && height > 0, "GridGraph: width and height must be > 0, got {} x {}", width,
            height);
  U4D_CHECK(connectivity == 4 || connectivity == 8, "GridGraph.connectivity must be 4 or 8, got {}",
            connectivity);
  U4D_CHECK(active.empty() || active.size() == static_cast<size_t>(width) * height,
            "GridGraph.active must be empty or have width*height = {} entries, got {}",
            static_cast<size_t>(width) * height, active.size());
}

void ExpansionOptions::Check() const {
  U4D_CHECK(max_sweeps >= 1, "ExpansionOptions.max_sweeps must be >= 1, got {}", max_sweeps);
  U4D_CHECK(min_relative_decrease >= 0 && std::isfinite(min_relative_decrease),
            "ExpansionOptions.min_relative_decrease must be finite and >= 0, got {}",
            min_relative_decrease);
  U4D_CHECK(algorithm == MaxFlowAlgorithm::kBoykovKolmogorov ||
                algorithm == MaxFlowAlgorithm::kBoostBoykovKolmogorov,
            "ExpansionOptions.algorithm: unknown value {}", static_cast<int>(algorithm));
}

double GridEnergy::PairwiseDecreaseBound(int, int, int) const {
  return std::numeric_limits<double>::infinity();
}

bool GridEnergy::MayTake(int, int, int) const { return true; }

double TruncatedLinearDecreaseBound(double distance) { return std::min(distance, 1.0); }

double TruncatedQuadraticDecreaseBound(double distance) {
  return distance >= 1 ? 1.0 : 2 * distance - distance * distance;
}

namespace {

struct Offset {
  int dx, dy;
};
// Neighbours q > p of p (in increasing q), then all neighbours.
constexpr Offset kForward8[] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
constexpr Offset kAll8[] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}, {-1, 0}, {1, -1}, {0, -1}, {-1, -1}};
constexpr Offset kAll4[] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};

int NumForward(const GridGraph& g) { return g.connectivity == 8 ? 4 : 2; }
const Offset* Forward(const GridGraph& g) { return g.connectivity == 8 ? kForward8 : kAll4; }
int NumAll(const GridGraph& g) { return g.connectivity == 8 ? 8 : 4; }
const Offset* All(const GridGraph& g) { return g.connectivity == 8 ? kAll8 : kAll4; }

void CheckLabels(const GridGraph& grid, const std::vector<int>& labels, const char* what) {
  U4D_CHECK(labels.size() == static_cast<size_t>(grid.NumPixels()),
            "{}: expected width*height = {} labels, got {}", what, grid.NumPixels(), labels.size());
  for (size_t p = 0; p < labels.size(); ++p) {
    U4D_CHECK(labels[p] >= 0, "{}: label of pixel {} is negative ({})", what, p, labels[p]);
  }
}

// The rectangle [x0, x1] x [y0, y1] holding every active pixel (empty: x0 > x1).
struct ActiveBox {
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
};

ActiveBox FindActiveBox(const GridGraph& grid) {
  if (grid.active.empty()) return {0, grid.width - 1, 0, grid.height - 1};
  ActiveBox b{grid.width, -1, grid.height, -1};
  for (int y = 0; y < grid.height; ++y) {
    const uint8_t* row = grid.active.data() + static_cast<size_t>(y) * grid.width;
    for (int x = 0; x < grid.width; ++x)
      if (row[x]) {
        b.x0 = std::min(b.x0, x), b.x1 = std::max(b.x1, x);
        b.y0 = std::min(b.y0, y), b.y1 = std::max(b.y1, y);
      }
  }
  return b;
}

// Buffers reused across the moves of one AlphaExpansion.
struct Workspace {
  ActiveBox box;                 // the moves only visit pixels in and next to it
  std::vector<int> node_of;      // pixel -> graph node, -1 = fixed (all -1 between moves)
  std::vector<int> node_pixel;   // graph node -> pixel
  std::vector<double> unary;     // per node: E(x=1) - E(x=0) of its unary-like terms
  std::vector<uint8_t> changed;  // per pixel, all 0 between moves
  std::vector<int> changed_list;
  FlowGraph graph;
  MinCut cut;
  MinCutSolver solver;
  // AlphaExpansion only: the energy terms at the current labels, which every
  // move needs again (E(x = 0)); updated around the pixels an accepted move
  // changes. The energy is a function of (pixel, labels), so the values are
  // the ones the move would compute. Empty = not cached.
  std::vector<double> current_unary;  // per pixel: Unary(p, labels[p])
  std::vector<double> current_pair;   // per pixel and forward neighbour k: Pairwise(p, q, ...)

  bool Cached() const { return !current_unary.empty(); }
  void Cache(const GridGraph& grid, const GridEnergy& energy, const std::vector<int>& labels);
  void Update(const GridGraph& grid, const GridEnergy& energy, const std::vector<int>& labels,
              int p);
};

void Workspace::Cache(const GridGraph& grid, const GridEnergy& energy,
                      const std::vector<int>& labels) {
  const int w = grid.width, h = grid.height, num_fwd = NumForward(grid);
  const Offset* fwd = Forward(grid);
  current_unary.assign(static_cast<size_t>(w) * h, 0.0);
  current_pair.assign(static_cast<size_t>(w) * h * num_fwd, 0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int p = y * w + x;
      current_unary[p] = energy.Unary(p, labels[p]);
      for (int k = 0; k < num_fwd; ++k) {
        const int qx = x + fwd[k].dx, qy = y + fwd[k].dy;
        if (qx < 0 || qx >= w || qy >= h) continue;
        const int q = qy * w + qx;
        current_pair[static_cast<size_t>(p) * num_fwd + k] =
            energy.Pairwise(p, q, labels[p], labels[q]);
      }
    }
}

// Pixel p changed its label: its unary and the pairs it is part of.
void Workspace::Update(const GridGraph& grid, const GridEnergy& energy,
                       const std::vector<int>& labels, int p) {
  const int w = grid.width, h = grid.height, num_fwd = NumForward(grid);
  const Offset* fwd = Forward(grid);
  current_unary[p] = energy.Unary(p, labels[p]);
  const int x = p % w, y = p / w;
  for (int k = 0; k < num_fwd; ++k) {
    // p as the first pixel of the pair (q = p + offset) and as the second (o = p - offset).
    const int qx = x + fwd[k].dx, qy = y + fwd[k].dy;
    if (qx >= 0 && qx < w && qy < h) {
      const int q = qy * w + qx;
      current_pair[static_cast<size_t>(p) * num_fwd + k] =
          energy.Pairwise(p, q, labels[p], labels[q]);
    }
    const int ox = x - fwd[k].dx, oy = y - fwd[k].dy;
    if (ox >= 0 && ox < w && oy >= 0) {
      const int o = oy * w + ox;
      current_pair[static_cast<size_t>(o) * num_fwd + k] =
          energy.Pairwise(o, p, labels[o], labels[p]);
    }
  }
}

// One binary move: pixel p may switch from labels[p] to proposal(p).
template <typename Proposal>
MoveResult Move(const GridGraph& grid, const GridEnergy& energy, const Proposal& proposal,
                std::vector<int>& labels, double energy_before, MaxFlowAlgorithm algorithm,
                Workspace& ws) {
  const int w = grid.width, h = grid.height, n = w * h;
  MoveResult result;
  result.energy_before = result.energy_after = energy_before;

  // Nodes: active pixels whose label differs from the proposal. Only the box
  // of the active pixels is visited (in the same row-major order as the whole
  // grid, so the graph is the same).
  const ActiveBox& box = ws.box;
  if (box.x0 > box.x1) return result;
  ws.node_of.resize(n, -1);  // reset after each move at the nodes only (not a memset of n)
  ws.node_pixel.clear();
  ws.unary.clear();
  for (int y = box.y0; y <= box.y1; ++y)
    for (int p = y * w + box.x0; p <= y * w + box.x1; ++p) {
      if (!grid.IsActive(p)) continue;
      const int a = proposal(p);
      if (a == labels[p] || !energy.MayTake(p, labels[p], a)) continue;
      const double rise =
          energy.Unary(p, a) - (ws.Cached() ? ws.current_unary[p] : energy.Unary(p, labels[p]));
      // The proposal cannot pay off at p: p keeps its label in every minimiser.
      if (rise > 0 && rise > energy.PairwiseDecreaseBound(p, labels[p], a)) continue;
      ws.node_of[p] = static_cast<int>(ws.node_pixel.size());
      ws.node_pixel.push_back(p);
      ws.unary.push_back(rise);
    }
  const int num_nodes = static_cast<int>(ws.node_pixel.size());
  result.graph_nodes = num_nodes;
  if (num_nodes == 0) return result;
  // node_of is back to all -1 when this move returns, whichever way.
  struct ResetNodes {
    Workspace& ws;
    ~ResetNodes() {
      for (const int p : ws.node_pixel) ws.node_of[p] = -1;
    }
  } reset_nodes{ws};
  ws.graph.Reset(num_nodes);

  // Pairwise terms touching a node: p is in the box or one row above it or
  // one column beside it (forward neighbours have dy >= 0, |dx| <= 1).
  const Offset* fwd = Forward(grid);
  const int num_fwd = NumForward(grid);
  const int px0 = std::max(box.x0 - 1, 0), px1 = std::min(box.x1 + 1, w - 1);
  for (int y = std::max(box.y0 - 1, 0); y <= box.y1; ++y) {
    for (int x = px0; x <= px1; ++x) {
      const int p = y * w + x;
      const int np = ws.node_of[p];
      for (int k = 0; k < num_fwd; ++k) {
        const int qx = x + fwd[k].dx, qy = y + fwd[k].dy;
        if (qx < 0 || qx >= w || qy >= h) continue;
        const int q = qy * w + qx;
        const int nq = ws.node_of[q];
        if (np < 0 && nq < 0) continue;
        const int lp = labels[p], lq = labels[q];
        const double e00 = ws.Cached() ? ws.current_pair[static_cast<size_t>(p) * num_fwd + k]
                                       : energy.Pairwise(p, q, lp, lq);
        if (np >= 0 && nq >= 0) {
          const int ap = proposal(p), aq = proposal(q);
          double e01 = energy.Pairwise(p, q, lp, aq);
          double e10 = energy.Pairwise(p, q, ap, lq);
          const double e11 = energy.Pairwise(p, q, ap, aq);
          const double excess = e00 + e11 - e01 - e10;
          if (excess > 0) {  // not submodular: raise E01, E10 (upper bound, exact at x = 0)
            e01 += 0.5 * excess;
            e10 += 0.5 * excess;
            ++result.nonsubmodular_terms;
          }
          // E = e00 + (e10 - e00) x_p + (e11 - e10) x_q + (e01 + e10 - e00 - e11)(1 - x_p) x_q.
          ws.unary[np] += e10 - e00;
          ws.unary[nq] += e11 - e10;
          const double cap = e01 + e10 - e00 - e11;
          if (cap > 0) ws.graph.edges.push_back({np, nq, cap, 0.0});
        } else if (np >= 0) {
          ws.unary[np] += energy.Pairwise(p, q, proposal(p), lq) - e00;
        } else {
          ws.unary[nq] += energy.Pairwise(p, q, lp, proposal(q)) - e00;
        }
      }
    }
  }
  // x = 1 (sink side) costs source_cap; x = 0 costs sink_cap.
  for (int i = 0; i < num_nodes; ++i) {
    const double d = ws.unary[i];
    if (d > 0) {
      ws.graph.source_cap[i] = d;
    } else {
      ws.graph.sink_cap[i] = -d;
    }
  }
  ws.solver.Solve(ws.graph, algorithm, &ws.cut);

  // True energy change of the cut's labelling.
  ws.changed.resize(n, 0);
  ws.changed_list.clear();
  for (int i = 0; i < num_nodes; ++i) {
    if (ws.cut.sink_side[i]) {
      ws.changed[ws.node_pixel[i]] = 1;
      ws.changed_list.push_back(ws.node_pixel[i]);
    }
  }
  if (ws.changed_list.empty()) return result;
  auto new_label = [&](int q) { return ws.changed[q] ? proposal(q) : labels[q]; };
  const Offset* all = All(grid);
  const int num_all = NumAll(grid);
  double delta = 0;
  for (const int p : ws.changed_list) {
    const int lp = labels[p], ap = proposal(p);
    delta += energy.Unary(p, ap) - energy.Unary(p, lp);
    const int x = p % w, y = p / w;
    for (int k = 0; k < num_all; ++k) {
      const int qx = x + all[k].dx, qy = y + all[k].dy;
      if (qx < 0 || qx >= w || qy < 0 || qy >= h) continue;
      const int q = qy * w + qx;
      if (ws.changed[q] && q < p) continue;  // counted from q
      const int lq = labels[q], aq = new_label(q);
      delta += q > p ? energy.Pairwise(p, q, ap, aq) - energy.Pairwise(p, q, lp, lq)
                     : energy.Pairwise(q, p, aq, ap) - energy.Pairwise(q, p, lq, lp);
    }
  }
  if (delta < 0) {
    for (const int p : ws.changed_list) labels[p] = proposal(p);
    if (ws.Cached())
      for (const int p : ws.changed_list) ws.Update(grid, energy, labels, p);
    result.accepted = true;
    result.changed_pixels = static_cast<int>(ws.changed_list.size());
    result.energy_after = energy_before + delta;
  }
  for (const int p : ws.changed_list) ws.changed[p] = 0;
  return result;
}

}  // namespace

std::vector<std::pair<int, int>> NeighbourPairs(const GridGraph& grid) {
  grid.Check();
  std::vector<std::pair<int, int>> pairs;
  const int w = grid.width, h = grid.height;
  pairs.reserve(static_cast<size_t>(w) * h * NumForward(grid));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int k = 0; k < NumForward(grid); ++k) {
        const int qx = x + Forward(grid)[k].dx, qy = y + Forward(grid)[k].dy;
        if (qx < 0 || qx >= w || qy >= h) continue;
        pairs.emplace_back(y * w + x, qy * w + qx);
      }
    }
  }
  return pairs;
}

double Energy(const GridGraph& grid, const GridEnergy& energy, const std::vector<int>& labels) {
  grid.Check();
  CheckLabels(grid, labels, "Energy");
  const int w = grid.width, h = grid.height;
  const Offset* fwd = Forward(grid);
  double e = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int p = y * w + x;
      e += energy.Unary(p, labels[p]);
      for (int k = 0; k < NumForward(grid); ++k) {
        const int qx = x + fwd[k].dx, qy = y + fwd[k].dy;
        if (qx < 0 || qx >= w || qy >= h) continue;
        const int q = qy * w + qx;
        e += energy.Pairwise(p, q, labels[p], labels[q]);
      }
    }
  }
  return e;
}

MoveResult ExpansionMove(const GridGraph& grid, const GridEnergy& energy, int alpha,
                         std::vector<int>* labels, MaxFlowAlgorithm algorithm) {
  U4D_CHECK(labels != nullptr, "ExpansionMove: labels is null");
  U4D_CHECK(alpha >= 0, "ExpansionMove: alpha must be >= 0, got {}", alpha);
  const double e = Energy(grid, energy, *labels);  // checks grid and labels
  Workspace ws;
  ws.box = FindActiveBox(grid);
  MoveResult r = Move(
      grid, energy, [alpha](int) { return alpha; }, *labels, e, algorithm, ws);
  // Re-sum: energy_before + delta loses precision when kInfiniteCost terms are involved.
  if (r.accepted) r.energy_after = Energy(grid, energy, *labels);
  return r;
}

MoveResult FusionMove(const GridGraph& grid, const GridEnergy& energy,
                      const std::vector<int>& proposal, std::vector<int>* labels,
                      MaxFlowAlgorithm algorithm) {
  U4D_CHECK(labels != nullptr, "FusionMove: labels is null");
  const double e = Energy(grid, energy, *labels);
  CheckLabels(grid, proposal, "FusionMove proposal");
  Workspace ws;
  ws.box = FindActiveBox(grid);
  MoveResult r = Move(
      grid, energy, [&proposal](int p) { return proposal[p]; }, *labels, e, algorithm, ws);
  if (r.accepted) r.energy_after = Energy(grid, energy, *labels);  // re-sum, as above
  return r;
}

ExpansionSummary AlphaExpansion(const GridGraph& grid, const GridEnergy& energy,
                                const std::vector<int>& candidate_labels, std::vector<int>* labels,
                                const ExpansionOptions& options) {
  options.Check();
  U4D_CHECK(labels != nullptr, "AlphaExpansion: labels is null");
  for (const int alpha : candidate_labels) {
    U4D_CHECK(alpha >= 0, "AlphaExpansion: candidate label {} is negative", alpha);
  }
  Timer timer;
  ExpansionSummary summary;
  double e = Energy(grid, energy, *labels);  // checks grid and labels
  summary.initial_energy = summary.final_energy = e;
  if (candidate_labels.empty()) return summary;
  Workspace ws;
  ws.box = FindActiveBox(grid);
  ws.Cache(grid, energy, *labels);
  for (int sweep = 0; sweep < options.max_sweeps; ++sweep) {
    const double e_start = e;
    int accepted = 0;
    for (const int alpha : candidate_labels) {
      const MoveResult r = Move(
          grid, energy, [alpha](int) { return alpha; }, *labels, e, options.algorithm, ws);
      ++summary.moves;
      summary.graph_nodes += r.graph_nodes;
      if (r.accepted) {
        ++accepted;
        e = r.energy_after;
      }
    }
    e = Energy(grid, energy, *labels);  // re-sum, so rounding does not drift
    summary.sweeps = sweep + 1;
    summary.accepted_moves += accepted;
    summary.energy_after_sweep.push_back(e);
    if (accepted == 0) break;
    if (e_start - e < options.min_relative_decrease * std::abs(e_start)) break;
  }
  summary.final_energy = e;
  summary.seconds = timer.Seconds();
  return summary;
}

}  // namespace u4d::mrf
