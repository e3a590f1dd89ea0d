// E_f cost volume (joint/flow_cost.h) vs the dense flow baselines
// (baselines/flow_baselines.h) on a generated handshake capture, 6 views at
// 480x270, script frames 128-130 (people walking apart). Plain executable:
//   build/bench/flow_cost_bench [--json FILE]
// Prints, for window = 1..4: labels, cost-volume time (ms, TBB over labels,
// roi = people dilated by 8 px) and the WTA EPE on GT-valid person pixels; then
// each baseline's EPE and time on the same frames, and the time ratios.
#include <cstdio>
#include <random>

#include <opencv2/imgproc.hpp>

#include "bench_table.h"
#include "bench_worlds.h"
#include "u4d/baselines/flow_baselines.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/joint/flow_cost.h"
#include "u4d/synth/generate.h"
#include "u4d/util/timer.h"

namespace u4d {
namespace {

double Epe(const cv::Mat& flow, const cv::Mat& gt, const cv::Mat& mask) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < flow.rows; ++y)
    for (int x = 0; x < flow.cols; ++x)
      if (mask.at<uint8_t>(y, x)) {
        sum += cv::norm(flow.at<cv::Vec2f>(y, x) - gt.at<cv::Vec2f>(y, x));
        ++n;
      }
  return sum / n;
}

// One world: the cost volumes' winner-take-all flow and OpenCV's flows
// against GT on view 0, frame 1.
void RunWorld(const std::string& world, bench::Table* volumes, bench::Table* baseline_rows) {
  synth::SynthOptions o = bench::World(world, 6, 480, 270, 3);
  if (world == "handshake") o.start_frame = 128;
  const fs::path dir = synth::WriteCaptureToTempDir("flow_cost_bench", o);
  const Capture capture = ReadCapture(dir);
  const int t = 1, ref = 0;
  FlowCostInput in;
  in.ref_view = ref;
  for (int v = 0; v < capture.NumViews(); ++v) {
    in.cameras_t.push_back(capture.views[v].CameraAt(t));
    in.cameras_t1.push_back(capture.views[v].CameraAt(t + 1));
    in.images_t.push_back(ReadColorImage(capture.ImagePath(v, t)));
    in.images_t1.push_back(ReadColorImage(capture.ImagePath(v, t + 1)));
  }
  const std::string& name = capture.views[ref].name;
  in.depth_t = ReadPfm(dir / layout::GtDepth(name, t));
  const cv::Mat gt = ReadFlo(dir / layout::GtFlow(name, t));
  const cv::Mat person = ReadLabelImage(dir / layout::GtInstances(name, t)) != 0;
  const cv::Mat mask = person & ReadMaskImage(dir / layout::GtFlowValid(name, t));
  cv::dilate(person, in.roi, cv::Mat(), cv::Point(-1, -1), 8);
  std::vector<cv::Point> pts;
  cv::findNonZero(mask, pts);
  std::mt19937 rng(7);
  std::shuffle(pts.begin(), pts.end(), rng);
  pts.resize(std::min<size_t>(pts.size(), 300));
  for (const cv::Point& q : pts) {
    const cv::Vec2f f = gt.at<cv::Vec2f>(q);
    in.sparse.push_back({Eigen::Vector2d(q.x, q.y), Eigen::Vector2d(f[0], f[1]), 0});
  }
  const double zero = Epe(cv::Mat(gt.size(), CV_32FC2, cv::Scalar(0, 0)), gt, mask);
  std::printf(
      "%s 480x270, view %s, %d GT-valid person pixels, roi %d pixels, zero-flow EPE %.3f px\n",
      world.c_str(), name.c_str(), cv::countNonZero(mask), cv::countNonZero(in.roi), zero);
  double ms_ref = 0;
  for (int window = 1; window <= 4; ++window) {
    MotionLabelOptions lo;
    lo.window = window;
    const std::vector<Eigen::Vector2f> labels = BuildMotionLabels(in.sparse, lo);
    for (bool cross : {false, true}) {
      FlowCostOptions fo;
      fo.cross_view = cross;
      Timer timer;
      const MotionCostVolume vol = ComputeFlowCostVolume(in, labels, lo, fo);
      const double ms = timer.Seconds() * 1e3;
      const cv::Mat flow = WinnerTakeAllFlow(vol, in.roi);
      if (window == 3 && cross) ms_ref = ms;
      std::printf(
          "E_f window %d cross_view %d: %4zu labels, cost volume %7.1f ms, WTA EPE %.3f px\n",
          window, cross, labels.size(), ms, Epe(flow, gt, mask));
      volumes->Row({world, bench::Cell("%d", window), bench::Cell("%d", cross),
                    bench::Cell("%zu", labels.size()), bench::Cell("%.1f", ms),
                    bench::Cell("%.3f", Epe(flow, gt, mask))});
    }
  }
  for (baselines::FlowBaseline b : baselines::AllFlowBaselines()) {
    Timer timer;
    const cv::Mat flow = baselines::BaselineFlow(b, in.images_t[ref], in.images_t1[ref]);
    const double ms = timer.Seconds() * 1e3;
    std::printf("%-10s EPE %.3f px, %7.1f ms (E_f window 3 / this: %.2f)\n",
                baselines::ToString(b).c_str(), Epe(flow, gt, mask), ms, ms_ref / ms);
    baseline_rows->Row({world, baselines::ToString(b), bench::Cell("%.3f", Epe(flow, gt, mask)),
                        bench::Cell("%.1f", ms), bench::Cell("%.2f", ms_ref / ms)});
  }
  fs::remove_all(dir);
}

int Main(int argc, char** argv) {
  bench::BenchTables tables("flow_cost_bench", bench::TakeJsonFlag(&argc, argv));
  bench::Table& volumes = tables.Record(
      "E_f cost volumes", {"world", "window", "cross_view", "labels", "ms", "WTA EPE px"});
  bench::Table& baseline_rows =
      tables.Record("Flow baselines", {"world", "method", "EPE px", "ms", "E_f window 3 / this"});
  for (const std::string& world : bench::AvailableWorlds({"handshake", "realistic"}))
    RunWorld(world, &volumes, &baseline_rows);
  tables.Write();
  return 0;
}

}  // namespace
}  // namespace u4d

int main(int argc, char** argv) { return u4d::Main(argc, argv); }
