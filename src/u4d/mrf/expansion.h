// Move-making minimisation of pixel-grid MRF energies: alpha-expansion and
// fusion moves, each solved exactly (or, for non-submodular terms, on a
// truncated upper bound) by one s-t min cut. Used for the global
// optimisation of the joint cost of paper Sec. 2.1, Eq. (costfunction):
// "alpha-expansion ... iterating through the set of labels ... [Boykov01].
// Each iteration is solved by graph-cut using the min-cut/max-flow algorithm
// [Kolmogorov04]. Convergence is achieved in 7-8 iterations."
//
// Energy: E(f) = sum_p Unary(p, f_p) + sum_{(p,q)} Pairwise(p, q, f_p, f_q)
// over the pixels p = y*width + x of a width x height grid and its 4- or
// 8-neighbour pairs (p < q). Labels are ints >= 0 whose meaning is the
// caller's (the joint solver alternates label, depth and motion blocks (joint/block_schedule.h)).
//
// A move is a binary problem: each optimised pixel keeps its label (x_p = 0)
// or takes a proposed one (x_p = 1: alpha for an expansion, proposal[p] for a
// fusion). Pairwise terms are turned into graph edges with the construction
// of Kolmogorov & Zabih (PAMI 2004). A term with E00 + E11 > E01 + E10 is not
// submodular and cannot be represented; it is truncated (Rother et al.,
// "Digital tapestry", CVPR 2005) by raising E01 and E10 by half the excess
// each. The binary energy the cut minimises is then an upper bound of the
// true move energy that is exact at the current labelling, so its minimiser
// cannot have a higher true energy. Independently of that, every move
// evaluates the TRUE energy change of the labelling it found and applies it
// only when the energy strictly decreases: the energy never increases.
//
// Active pixels: only pixels with grid.active[p] != 0 (all when `active` is
// empty) are optimised; the others keep their labels, and their pairwise
// terms with active neighbours act as unary terms on the active side.
// Pixels whose current label equals the proposal are not graph nodes either,
// nor are pixels the energy's PairwiseDecreaseBound shows cannot take the
// proposal in any minimiser of the move, or that its MayTake keeps from it
// (see there).
//
// Failure modes: labels of the wrong size or negative, a bad grid or bad
// options throw u4d::Error.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "u4d/mrf/max_flow.h"

namespace u4d::mrf {

// A forbidden label (unary cost). A large finite number, so energies stay
// finite and comparable; graph capacities built from it stay exact enough.
inline constexpr double kInfiniteCost = 1e12;

// A pixel grid; only `active` pixels are optimised.
struct GridGraph {
  int width = 0, height = 0;    // pixels, both > 0
  int connectivity = 8;         // 4 or 8 neighbours
  std::vector<uint8_t> active;  // width*height, nonzero = optimised; empty = all

  void Check() const;  // throws u4d::Error on a non-positive size, bad connectivity or active size
  int NumPixels() const { return width * height; }
  bool IsActive(int p) const { return active.empty() || active[p] != 0; }
};

// Neighbour pairs (p, q), p < q, each pair once, in row-major order of p
// (and increasing q for one p); pixel index = y*width + x.
std::vector<std::pair<int, int>> NeighbourPairs(const GridGraph& grid);

// The energy E(f) = sum_p Unary(p, f_p) + sum_{(p,q)} Pairwise(p, q, f_p, f_q).
// Both must be functions of their arguments only while a move or an
// AlphaExpansion runs: AlphaExpansion caches the terms at the current labels.
class GridEnergy {
 public:
  virtual ~GridEnergy() = default;
  // Cost of `label` at `pixel`; >= 0 is not required; may be kInfiniteCost.
  virtual double Unary(int pixel, int label) const = 0;
  // Cost of the neighbour pair p < q taking (label_p, label_q); finite, >= 0.
  virtual double Pairwise(int p, int q, int label_p, int label_q) const = 0;
  // An upper bound of how much the pairwise terms of `pixel` can decrease
  // when it switches from label `from` to label `to`, whatever labels its
  // neighbours hold: >= sum over neighbours q of max over y of
  // [Pairwise(pixel, q, from, y) - Pairwise(pixel, q, to, y)] (arguments in
  // the pair's order). A move leaves out of its graph a pixel whose unary
  // rises by more than this on taking the proposal: the pixel keeps its label
  // in every minimiser of the move, so the move's result is the same, and
  // the cut is smaller. For a pairwise term c_pq + w_pq * d(a, b) with d a
  // metric, w_pq * d(from, to) per neighbour is such a bound (triangle
  // inequality). The default, +infinity, leaves every pixel in the graph.
  // A bound below the true maximum is the caller's bug: moves still never
  // raise the energy, but may miss their best labelling.
  virtual double PairwiseDecreaseBound(int pixel, int from, int to) const;
  // Whether `pixel`, labelled `current`, may take `proposal` in a move
  // (default: always). A caller's restriction of the moves (for example to
  // labels near the current one, after a pass over a coarse label set): the
  // move is then solved exactly over the pixels allowed, the others keep
  // their labels, and the energy still never increases; what the restriction
  // costs in the final energy is the caller's to measure.
  virtual bool MayTake(int pixel, int current, int proposal) const;
};

// Bounds for GridEnergy::PairwiseDecreaseBound with robust pairwise terms
// rho(|a - b|) of a distance in units of the truncation (a >= 0 argument):
// max over y of rho(|x - y|) - rho(|z - y|) when |x - z| = distance.
//  - truncated linear rho(s) = min(s, 1), a metric: min(distance, 1);
//  - truncated quadratic rho(s) = min(s^2, 1): 2 d - d^2 for d < 1 (reached
//    where |z - y| = 1 - d), 1 from d >= 1.
double TruncatedLinearDecreaseBound(double distance);
double TruncatedQuadraticDecreaseBound(double distance);

// E(labels) over all pixels (active or not). Throws on a wrong labels size.
double Energy(const GridGraph& grid, const GridEnergy& energy, const std::vector<int>& labels);

struct MoveResult {
  double energy_before = 0, energy_after = 0;  // true energies; equal when not accepted
  bool accepted = false;                       // the labelling changed (energy decreased)
  int changed_pixels = 0;                      // pixels that took the proposal (0 if rejected)
  int graph_nodes = 0;                         // pixels in the move's graph
  int nonsubmodular_terms = 0;                 // pairwise terms truncated in this move
};

// One alpha-expansion move (Boykov, Veksler, Zabih, PAMI 2001): every active
// pixel keeps its label or switches to `alpha`, by one min cut. Labels of
// inactive pixels never change; the energy never increases.
MoveResult ExpansionMove(const GridGraph& grid, const GridEnergy& energy, int alpha,
                         std::vector<int>* labels,
                         MaxFlowAlgorithm algorithm = MaxFlowAlgorithm::kBoykovKolmogorov);

// Fusion move (Lempitsky et al., PAMI 2010): every active pixel keeps its
// label or takes proposal[p] (width*height labels >= 0); same guarantees.
MoveResult FusionMove(const GridGraph& grid, const GridEnergy& energy,
                      const std::vector<int>& proposal, std::vector<int>* labels,
                      MaxFlowAlgorithm algorithm = MaxFlowAlgorithm::kBoykovKolmogorov);

struct ExpansionOptions {
  int max_sweeps = 8;  // sweeps over all candidate labels (the paper converges in 7-8); >= 1
  // Stop when a sweep lowers the energy by less than this fraction of |E|; >= 0
  // (0: run until a sweep accepts no move or max_sweeps).
  double min_relative_decrease = 1e-4;
  MaxFlowAlgorithm algorithm = MaxFlowAlgorithm::kBoykovKolmogorov;  // min-cut solver

  void Check() const;  // throws u4d::Error on max_sweeps < 1 or a negative / NaN decrease
};

struct ExpansionSummary {
  double initial_energy = 0, final_energy = 0;
  int sweeps = 0, moves = 0, accepted_moves = 0;
  long long graph_nodes = 0;               // summed over the moves
  std::vector<double> energy_after_sweep;  // one per sweep
  double seconds = 0;                      // wall time
};

// Alpha-expansion over `candidate_labels` (in that order each sweep; each
// >= 0) starting from *labels. Stops after max_sweeps, after a sweep without
// an accepted move, or after a sweep whose relative decrease is below
// min_relative_decrease. The energy never increases from move to move.
ExpansionSummary AlphaExpansion(const GridGraph& grid, const GridEnergy& energy,
                                const std::vector<int>& candidate_labels, std::vector<int>* labels,
                                const ExpansionOptions& options = {});

}  // namespace u4d::mrf
