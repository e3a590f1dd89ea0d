// Optical flow on real(istic) frames with ground truth: the MPI Sintel cases
// in $U4D_DATA_DIR/sintel_flow (default /work/shared/data; clean/easy,
// clean/medium, final/hard: frames 0001..0004, gt/frame_0002.flo = the
// forward flow 0002 -> 0003, gt/invalid/frame_0002.png and
// gt/occlusions/frame_0002.png, nonzero = invalid / occluded).
//
// Methods (all from frame 0002 to 0003):
//   deepflow, dis, farneback   baselines/flow_baselines.h (OpenCV)
//   ours-fusion                the joint method's flow fusion stage
//                              (joint_view.h FlowFusionOptions) on a single
//                              view: fusion moves (mrf::FusionMove) of the
//                              current field with the default proposals
//                              (joint_view.h FlowFusionProposals: DIS at its
//                              finest scale, DIS medium, their mean) and the
//                              current field smoothed (σ = 1 px, 5x5), 2
//                              rounds, under λ_f E_f + E_r with the
//                              paper's weights (PaperWeights indoor, 1 view),
//                              the default FlowCostOptions / τ_m and the
//                              edge-aware weight c_pq of E_r, starting from the
//                              zero field (the joint method starts it
//                              at its discrete solution, which needs
//                              sparse tracks; see below).
//   ours-fusion-df             the same fusion started at the DeepFlow field
//                              (so it can only lower E_f^T + E_r from
//                              DeepFlow's): does the energy improve on its
//                              best proposal?
// What is NOT ours here: Sintel is monocular, so E_f is its temporal term
// e_F^T alone (no e_F^V: there are no other views; no e_F^S: no sparse
// multi-view tracks), there are no instance labels, depths or poses (E_r's
// pair weight has no semantic / appearance spread, E_p is absent), and the
// discrete motion block is skipped (its label set M is built around sparse
// track displacements, which need the multi-view pipeline): the field enters
// the fusion at zero instead of at the discrete solution. The row measures
// the fusion of the proposals under E_f^T + E_r, not the full joint flow.
//
// EPE (px) over the GT-valid pixels ("all") and the valid non-occluded ones
// ("noc"), share within 1 / 3 px (all), wall time, and the time relative to
// DeepFlow in the same run (ours includes computing its proposals; -df also
// DeepFlow's start).
//   build/bench/sintel_bench [case ...] [--json FILE]   (case = clean/easy etc.)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench_table.h"
#include "u4d/baselines/flow_baselines.h"
#include "u4d/eval/dense_metrics.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/joint/flow_cost.h"
#include "u4d/joint/joint_view.h"
#include "u4d/joint/label_costs.h"
#include "u4d/joint/parameters.h"
#include "u4d/mrf/expansion.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

namespace fs = std::filesystem;
using namespace u4d;

namespace {

int Direction(int p, int q, int width) {  // 0: right, 1: down-left, 2: down, 3: down-right
  const int d = q - p;
  if (d == 1) return 0;
  if (d == width - 1) return 1;
  if (d == width) return 2;
  return 3;
}

// λ_f E_f^T(m) + E_r(m) as a function of the per-pixel choice between the
// current field (0) and a proposal (1).
struct FusionEnergy : mrf::GridEnergy {
  const std::vector<Eigen::Vector2f>&cur, &prop;
  const std::vector<float>&cur_cost, &prop_cost;
  const std::vector<std::vector<float>>& edge;  // [direction][p] λ_r c_pq
  double flow_weight, tau2;
  int width;
  FusionEnergy(const std::vector<Eigen::Vector2f>& c, const std::vector<Eigen::Vector2f>& p,
               const std::vector<float>& cc, const std::vector<float>& pc,
               const std::vector<std::vector<float>>& e, double fw, double tau, int w)
      : cur(c),
        prop(p),
        cur_cost(cc),
        prop_cost(pc),
        edge(e),
        flow_weight(fw),
        tau2(tau * tau),
        width(w) {}
  double Unary(int p, int k) const override {
    return flow_weight * (k == 0 ? cur_cost[p] : prop_cost[p]);
  }
  double Pairwise(int p, int q, int kp, int kq) const override {
    const Eigen::Vector2f& a = kp == 0 ? cur[p] : prop[p];
    const Eigen::Vector2f& b = kq == 0 ? cur[q] : prop[q];
    return edge[Direction(p, q, width)][p] * std::min((a - b).squaredNorm() / tau2, 1.0);
  }
};

// `initial`: the field the fusion starts from (CV_32FC2; empty = zero).
cv::Mat OursFusion(const cv::Mat& a, const cv::Mat& b, const std::vector<cv::Mat>& external,
                   const cv::Mat& initial) {
  const int w = a.cols, h = a.rows, n = w * h;
  const JointWeights jw = PaperWeights(SceneType::kIndoor, 1);
  const JointViewOptions jo;
  FlowCostOptions fo;
  fo.cross_view = false;
  fo.sparse = false;
  Camera cam;
  cam.width = w;
  cam.height = h;
  cam.K << w, 0, (w - 1) / 2.0, 0, w, (h - 1) / 2.0, 0, 0, 1;
  FlowCostInput in;
  in.cameras_t = in.cameras_t1 = {cam};
  in.images_t = {a};
  in.images_t1 = {b};
  mrf::GridGraph grid;
  grid.width = w;
  grid.height = h;
  const auto pairs = mrf::NeighbourPairs(grid);
  const std::vector<float> colour = ContrastWeights(a.isContinuous() ? a : a.clone(), pairs);
  std::vector<std::vector<float>> edge(4, std::vector<float>(n, 0.f));
  for (size_t i = 0; i < pairs.size(); ++i)
    edge[Direction(pairs[i].first, pairs[i].second, w)][pairs[i].first] =
        static_cast<float>(jw.motion_reg * colour[i]);
  const double flow_weight = jw.flow / fo.truncation;  // flow_scale with e_F^T alone

  std::vector<Eigen::Vector2f> cur(n, Eigen::Vector2f::Zero()), prop(n);
  for (int p = 0; p < n && !initial.empty(); ++p) {
    const cv::Vec2f f = initial.ptr<cv::Vec2f>()[p];
    if (std::isfinite(f[0]) && std::isfinite(f[1])) cur[p] = Eigen::Vector2f(f[0], f[1]);
  }
  auto field_of = [&](const std::vector<Eigen::Vector2f>& m) {
    cv::Mat f(h, w, CV_32FC2);
    for (int p = 0; p < n; ++p) f.ptr<cv::Vec2f>()[p] = cv::Vec2f(m[p].x(), m[p].y());
    return f;
  };
  auto costs_of = [&](const cv::Mat& field) {
    const cv::Mat c = FlowFieldCosts(in, field, fo);
    return std::vector<float>(c.ptr<float>(), c.ptr<float>() + n);
  };
  std::vector<float> cur_cost = costs_of(field_of(cur));
  auto fuse = [&](const cv::Mat& proposal) {
    cv::Mat field = proposal.clone();
    for (int p = 0; p < n; ++p) {
      cv::Vec2f& f = field.ptr<cv::Vec2f>()[p];
      if (!std::isfinite(f[0]) || !std::isfinite(f[1])) f = cv::Vec2f(cur[p].x(), cur[p].y());
      prop[p] = Eigen::Vector2f(f[0], f[1]);
    }
    const std::vector<float> prop_cost = costs_of(field);
    std::vector<int> choice(n, 0);
    const std::vector<int> all(n, 1);
    mrf::FusionMove(
        grid,
        FusionEnergy(cur, prop, cur_cost, prop_cost, edge, flow_weight, jo.motion_truncation_px, w),
        all, &choice, jo.algorithm);
    for (int p = 0; p < n; ++p)
      if (choice[p] == 1) cur[p] = prop[p], cur_cost[p] = prop_cost[p];
  };
  for (int round = 0; round < jo.fusion.rounds; ++round) {
    for (const cv::Mat& f : external) fuse(f);
    cv::Mat smooth;
    cv::GaussianBlur(field_of(cur), smooth, cv::Size(5, 5), 1.0);
    fuse(smooth);
  }
  return field_of(cur);
}

using bench::Cell;

}  // namespace

int main(int argc, char** argv) try {
  bench::BenchTables tables("sintel_bench", bench::TakeJsonFlag(&argc, argv));
  const char* env = std::getenv("U4D_DATA_DIR");
  const fs::path root =
      (env != nullptr && *env ? fs::path(env) : fs::path("/work/shared/data")) / "sintel_flow";
  std::vector<std::string> cases = {"clean/easy", "clean/medium", "final/hard"};
  if (argc > 1) cases.assign(argv + 1, argv + argc);
  const std::vector<std::string> methods = {"deepflow", "dis", "farneback", "ours-fusion",
                                            "ours-fusion-df"};
  std::printf("MPI Sintel (%s), forward flow frame_0002 -> frame_0003\n", root.string().c_str());
  std::printf(
      "ours-fusion: the joint method's flow fusion on ONE view (E_f^T + E_r, the default\n"
      "proposals DIS fine, DIS medium, mean, smoothed; no e_F^V / e_F^S / labels / depth /\n"
      "pose: Sintel is monocular), from the zero field; ours-fusion-df: the same, started\n"
      "at DeepFlow; their times include their proposals (and -df's DeepFlow).\n\n");
  bench::Table& per_case = tables.Start(
      "Per case",
      {"case", "method", "EPE all", "EPE noc", "within 1 px", "within 3 px", "s", "s / deepflow"},
      false);
  std::vector<eval::FlowMetrics> total_all(methods.size()), total_noc(methods.size());
  std::vector<double> total_s(methods.size(), 0);
  for (const std::string& c : cases) {
    const fs::path dir = root / c;
    const cv::Mat a = ReadColorImage(dir / "frame_0002.png");
    const cv::Mat b = ReadColorImage(dir / "frame_0003.png");
    const cv::Mat gt = ReadFlo(dir / "gt" / "frame_0002.flo");
    const cv::Mat invalid =
        cv::imread((dir / "gt" / "invalid" / "frame_0002.png").string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat occ =
        cv::imread((dir / "gt" / "occlusions" / "frame_0002.png").string(), cv::IMREAD_GRAYSCALE);
    U4D_CHECK(!invalid.empty() && !occ.empty() && invalid.size() == a.size() &&
                  occ.size() == a.size() && gt.size() == a.size() && b.size() == a.size(),
              "sintel_bench: {}: expected frame_0002/0003.png, gt/frame_0002.flo, "
              "gt/invalid/frame_0002.png and gt/occlusions/frame_0002.png of one size",
              dir.string());
    const cv::Mat valid = invalid == 0;
    const cv::Mat noc = valid & (occ == 0);
    std::vector<cv::Mat> flow(methods.size());
    std::vector<double> secs(methods.size(), 0);
    for (int m = 0; m < 3; ++m) {
      Timer timer;
      flow[m] = baselines::BaselineFlow(baselines::FlowBaselineFromString(methods[m]), a, b);
      secs[m] = timer.Seconds();
    }
    const JointViewOptions jo;
    cv::Mat grey_a, grey_b;
    cv::cvtColor(a, grey_a, cv::COLOR_BGR2GRAY);
    cv::cvtColor(b, grey_b, cv::COLOR_BGR2GRAY);
    for (int m = 3; m < 5; ++m) {
      Timer timer;
      const std::vector<cv::Mat> proposals = FlowFusionProposals(grey_a, grey_b, jo.fusion);
      const bool from_deepflow = methods[m] == "ours-fusion-df";
      flow[m] = OursFusion(a, b, proposals, from_deepflow ? flow[0] : cv::Mat());
      secs[m] = timer.Seconds() + (from_deepflow ? secs[0] : 0.0);
    }
    for (size_t m = 0; m < methods.size(); ++m) {
      const eval::FlowMetrics all = eval::EvaluateFlow(flow[m], gt, valid, cv::Mat(), c);
      const eval::FlowMetrics nc = eval::EvaluateFlow(flow[m], gt, valid, noc, c);
      total_all[m].Add(all);
      total_noc[m].Add(nc);
      total_s[m] += secs[m];
      per_case.Row({c, methods[m], Cell("%.3f", all.Epe()), Cell("%.3f", nc.Epe()),
                    Cell("%.3f", all.Within1Px()), Cell("%.3f", all.Within3Px()),
                    Cell("%.2f", secs[m]), Cell("%.2f", secs[m] / secs[0])});
    }
    std::fflush(stdout);
  }
  bench::Table& all = tables.Start(
      "All cases (pixel-weighted)",
      {"method", "EPE all", "EPE noc", "within 1 px", "within 3 px", "s", "s / deepflow"});
  for (size_t m = 0; m < methods.size(); ++m)
    all.Row({methods[m], Cell("%.3f", total_all[m].Epe()), Cell("%.3f", total_noc[m].Epe()),
             Cell("%.3f", total_all[m].Within1Px()), Cell("%.3f", total_all[m].Within3Px()),
             Cell("%.2f", total_s[m]), Cell("%.2f", total_s[m] / total_s[0])});
  tables.Write();
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "sintel_bench: %s\n", e.what());
  return 1;
}
