// Throughput of the hot kernels of the per-view joint optimisation and of the
// fusion (docs/results.md, "Hot kernels and the phases of one joint view
// solve"), on a generated
// handshake capture (8 views, frames 0 and 1) at 480x270 and 960x540:
//   DepthCostVolume  ComputeDepthCostVolume, 64 labels, over a person ROI (GT
//                    person pixels dilated by 8 px, as the solver's roi) or the
//                    whole image: Mpx*labels/s of the pixels computed
//   FlowCostVolume   ComputeFlowCostVolume (e_F^T + e_F^V + e_F^S), the motion
//                    labels of 150 GT-sampled sparse tracks, same ROI, GT depth
//                    for e_F^V: Mpx*labels/s
//   MaxFlow          own Boykov-Kolmogorov on a stereo-like binary grid graph
//                    (bench/mrf_bench_graph.h, 480x270): edges/s
//   ExpansionSweep   one alpha-expansion sweep (16 labels) of a truncated-linear
//                    stereo-like energy on the full grid: pixel*labels/s
//   FusionMove       one fusion move of the same energy with a noisy proposal: pixels/s
//   GmmFit           the 10-component colour GMM of E_a on 4000 samples
//                    (FitColorGmm) against cv::ml::EM, the implementation it
//                    replaced (same algorithm), in the same run: samples/s
//   Poisson          Open3D screened Poisson (octree depth 8) of one person's
//                    oriented points from the GT depth maps: points/s; and the
//                    whole FuseObject
// Google Benchmark; run from a Release build:
//   build/bench/kernels_bench [--benchmark_filter=Depth]
// The captures are generated once, outside the timed parts.
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <random>

#include <benchmark/benchmark.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/ml.hpp>

#include "mrf_bench_graph.h"
#include "u4d/fusion/depth_fusion.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/joint/depth_cost.h"
#include "u4d/joint/flow_cost.h"
#include "u4d/joint/label_costs.h"
#include "u4d/joint/motion_labels.h"
#include "u4d/mrf/expansion.h"
#include "u4d/mrf/max_flow.h"
#include "u4d/synth/generate.h"
#include "u4d/testing/truth_inputs.h"

namespace u4d {
namespace {

// Frames 0 and 1 of an 8-view handshake capture, GT maps of frame 0.
struct Scene {
  std::vector<Camera> cameras_t, cameras_t1;
  std::vector<cv::Mat> images_t, images_t1, depths, ids;
  cv::Mat roi;  // view 0: GT person pixels dilated by 8 px
  double near = 0, far = 0;
  std::vector<SparseMotion> sparse;  // view 0, 150 GT-sampled tracks t -> t+1
};

const Scene& GetScene(int width) {
  static std::map<int, std::unique_ptr<Scene>> scenes;
  auto& s = scenes[width];
  if (s) return *s;
  s = std::make_unique<Scene>();
  const int height = width * 9 / 16;
  const fs::path dir = synth::WriteCaptureToTempDir(
      "kernels_bench_" + std::to_string(width), synth::SmallHandshakeOptions(8, width, height, 2));
  const Capture c = ReadCapture(dir);
  for (int v = 0; v < c.NumViews(); ++v) {
    const std::string& name = c.views[v].name;
    s->cameras_t.push_back(c.views[v].CameraAt(0));
    s->cameras_t1.push_back(c.views[v].CameraAt(1));
    s->images_t.push_back(ReadColorImage(c.ImagePath(v, 0)));
    s->images_t1.push_back(ReadColorImage(c.ImagePath(v, 1)));
    s->depths.push_back(ReadPfm(dir / layout::GtDepth(name, 0)));
    s->ids.push_back(ReadLabelImage(dir / layout::GtInstances(name, 0)));
  }
  const cv::Mat person = (s->ids[0] > 0) & (s->depths[0] > 0);
  cv::dilate(person, s->roi, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(17, 17)));
  double lo = 0, hi = 0;
  cv::minMaxLoc(s->depths[0], &lo, &hi, nullptr, nullptr, person);
  s->near = lo - 0.35;
  s->far = hi + 0.35;
  s->sparse = SparseMotionsFromTruth(ReadViewTruth(c, 0, 0), 150, 11);
  fs::remove_all(dir);
  return *s;
}

void BM_DepthCostVolume(benchmark::State& state) {
  const Scene& s = GetScene(static_cast<int>(state.range(0)));
  const bool use_roi = state.range(1) != 0;
  const cv::Mat roi = use_roi ? s.roi : cv::Mat();
  const DepthCostOptions o;
  for (auto _ : state) {
    const DepthCostVolume v =
        ComputeDepthCostVolume(s.cameras_t, s.images_t, 0, roi, s.near, s.far, o);
    benchmark::DoNotOptimize(v.cost.data());
  }
  const double px = use_roi ? cv::countNonZero(s.roi) : s.roi.total();
  state.SetLabel(use_roi ? "person roi" : "full image");
  state.counters["roi_px"] = px;
  state.counters["Mpx*labels/s"] = benchmark::Counter(px * o.num_depths * 1e-6 * state.iterations(),
                                                      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DepthCostVolume)
    ->ArgsProduct({{480, 960}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_FlowCostVolume(benchmark::State& state) {
  const Scene& s = GetScene(static_cast<int>(state.range(0)));
  FlowCostInput in;
  in.ref_view = 0;
  in.cameras_t = s.cameras_t;
  in.cameras_t1 = s.cameras_t1;
  in.images_t = s.images_t;
  in.images_t1 = s.images_t1;
  in.depth_t = s.depths[0];
  in.sparse = s.sparse;
  in.roi = s.roi;
  const MotionLabelOptions lo;
  const std::vector<Eigen::Vector2f> motions = BuildMotionLabels(s.sparse, lo);
  size_t forbidden = 0;
  for (auto _ : state) {
    const MotionCostVolume v = ComputeFlowCostVolume(in, motions, lo, FlowCostOptions{});
    benchmark::DoNotOptimize(v.cost.data());
    forbidden =
        std::count_if(v.cost.begin(), v.cost.end(), [](float c) { return c >= kForbiddenMotion; });
  }
  const double px = cv::countNonZero(s.roi);
  // Share of the roi's (pixel, label) pairs that e_F^S forbids.
  state.counters["forbidden"] = forbidden / (px * motions.size());
  state.counters["labels"] = static_cast<double>(motions.size());
  state.counters["Mpx*labels/s"] = benchmark::Counter(
      px * motions.size() * 1e-6 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FlowCostVolume)->Arg(480)->Arg(960)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MaxFlow(benchmark::State& state) {
  const mrf::FlowGraph graph = mrf::bench::StereoGraph(static_cast<int>(state.range(0)));
  mrf::MinCutSolver solver;
  mrf::MinCut cut;
  for (auto _ : state) {
    solver.Solve(graph, mrf::MaxFlowAlgorithm::kBoykovKolmogorov, &cut);
    benchmark::DoNotOptimize(cut.sink_side.data());
  }
  state.SetLabel(std::to_string(state.range(0)) + "-conn 480x270");
  state.counters["edges/s"] = benchmark::Counter(
      static_cast<double>(graph.edges.size()) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["nodes/s"] = benchmark::Counter(
      static_cast<double>(graph.num_nodes) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MaxFlow)->Arg(4)->Arg(8)->Unit(benchmark::kMillisecond)->UseRealTime();

// Stereo-like truncated-linear energy with 16 labels on a width x height grid.
class StereoEnergy : public mrf::GridEnergy {
 public:
  static constexpr int kLabels = 16;
  StereoEnergy(int width, int height)
      : width_(width), unary_(static_cast<size_t>(width) * height * kLabels) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const double d = std::clamp(6 + 3 * std::sin(x * 8.0 / width) +
                                        2 * std::cos(y * 6.0 / height) + (x > width / 2 ? 4 : 0),
                                    0.0, kLabels - 1.0);
        for (int l = 0; l < kLabels; ++l)
          unary_[(static_cast<size_t>(y) * width + x) * kLabels + l] =
              static_cast<float>(std::min(std::abs(l - d), 4.0)) + 2 * u(rng);
      }
  }
  double Unary(int p, int l) const override { return unary_[static_cast<size_t>(p) * kLabels + l]; }
  double Pairwise(int, int, int lp, int lq) const override {
    return 0.8 * std::min(std::abs(lp - lq), 2);
  }

 private:
  int width_;
  std::vector<float> unary_;
};

mrf::GridGraph Grid(int width) {
  mrf::GridGraph g;
  g.width = width;
  g.height = width * 9 / 16;
  g.connectivity = 8;
  return g;
}

void BM_ExpansionSweep(benchmark::State& state) {
  const mrf::GridGraph grid = Grid(static_cast<int>(state.range(0)));
  const StereoEnergy energy(grid.width, grid.height);
  std::vector<int> candidates(StereoEnergy::kLabels);
  for (int i = 0; i < StereoEnergy::kLabels; ++i) candidates[i] = i;
  mrf::ExpansionOptions o;
  o.max_sweeps = 1;
  double e = 0;
  for (auto _ : state) {
    std::vector<int> labels(grid.NumPixels(), 0);
    e = mrf::AlphaExpansion(grid, energy, candidates, &labels, o).final_energy;
  }
  state.counters["energy"] = e;
  state.counters["px*labels/s"] = benchmark::Counter(
      static_cast<double>(grid.NumPixels()) * StereoEnergy::kLabels * state.iterations(),
      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ExpansionSweep)->Arg(480)->Arg(960)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FusionMove(benchmark::State& state) {
  const mrf::GridGraph grid = Grid(static_cast<int>(state.range(0)));
  const StereoEnergy energy(grid.width, grid.height);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> label(0, StereoEnergy::kLabels - 1);
  std::vector<int> current(grid.NumPixels()), proposal(grid.NumPixels());
  for (int& l : current) l = label(rng);
  for (int& l : proposal) l = label(rng);
  int changed = 0;
  for (auto _ : state) {
    std::vector<int> labels = current;
    changed = mrf::FusionMove(grid, energy, proposal, &labels).changed_pixels;
  }
  state.counters["changed"] = changed;
  state.counters["px/s"] = benchmark::Counter(
      static_cast<double>(grid.NumPixels()) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FusionMove)->Arg(480)->Arg(960)->Unit(benchmark::kMillisecond)->UseRealTime();

// 4000 colour samples of person 1 of view 0 (480x270), as AppearanceCosts draws them.
std::vector<cv::Vec3b> GmmSamples() {
  const Scene& s = GetScene(480);
  std::vector<cv::Vec3b> samples;
  for (int y = 0; y < s.ids[0].rows; ++y)
    for (int x = 0; x < s.ids[0].cols; ++x)
      if (s.ids[0].at<uint16_t>(y, x) == 1) samples.push_back(s.images_t[0].at<cv::Vec3b>(y, x));
  std::shuffle(samples.begin(), samples.end(), std::mt19937_64(7));
  samples.resize(std::min<size_t>(samples.size(), 4000));
  return samples;
}

void BM_GmmFit(benchmark::State& state) {
  const std::vector<cv::Vec3b> samples = GmmSamples();
  const bool opencv = state.range(0) != 0;
  cv::Mat data(static_cast<int>(samples.size()), 3, CV_64F);
  for (int i = 0; i < data.rows; ++i)
    for (int c = 0; c < 3; ++c) data.at<double>(i, c) = samples[i][c];
  for (auto _ : state) {
    if (opencv) {  // the former FitColorGmm: cv::ml::EM, same settings and seed
      cv::theRNG() = cv::RNG(7);
      cv::Ptr<cv::ml::EM> em = cv::ml::EM::create();
      em->setClustersNumber(10);
      em->setCovarianceMatrixType(cv::ml::EM::COV_MAT_GENERIC);
      em->setTermCriteria(
          cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30, 1e-3));
      benchmark::DoNotOptimize(em->trainEM(data));
    } else {
      const ColorGmm gmm = FitColorGmm(samples, 10, 7);
      benchmark::DoNotOptimize(gmm.weights.data());
    }
  }
  state.SetLabel(opencv ? "cv::ml::EM (before)" : "FitColorGmm");
  state.counters["samples/s"] = benchmark::Counter(
      static_cast<double>(samples.size()) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GmmFit)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Poisson(benchmark::State& state) {
  const Scene& s = GetScene(static_cast<int>(state.range(0)));
  const FusionOptions o;
  const std::vector<OrientedPoint> points =
      ObjectPoints(s.cameras_t, s.depths, s.ids, s.images_t, 1, o);
  open3d::geometry::PointCloud cloud;
  for (const OrientedPoint& p : points) {
    cloud.points_.push_back(p.position);
    cloud.normals_.push_back(p.normal);
  }
  size_t vertices = 0;
  for (auto _ : state) {
    auto [mesh, densities] = open3d::geometry::TriangleMesh::CreateFromPointCloudPoisson(
        cloud, o.poisson_depth, 0.0f, static_cast<float>(o.poisson_scale), false,
        o.poisson_threads);
    vertices = mesh->vertices_.size();
  }
  state.counters["points"] = static_cast<double>(points.size());
  state.counters["vertices"] = static_cast<double>(vertices);
  state.counters["points/s"] = benchmark::Counter(
      static_cast<double>(points.size()) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Poisson)->Arg(480)->Arg(960)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FuseObject(benchmark::State& state) {
  const Scene& s = GetScene(static_cast<int>(state.range(0)));
  int points = 0;
  for (auto _ : state) {
    const FusedMesh m = FuseObject(s.cameras_t, s.depths, s.ids, s.images_t, 1, FusionOptions{});
    points = m.num_points;
  }
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(points) * state.iterations(),
                                                  benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FuseObject)->Arg(480)->Arg(960)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace u4d

BENCHMARK_MAIN();
