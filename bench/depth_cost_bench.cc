// The depth unary term (joint/depth_cost.h): time of ComputeDepthCostVolume
// for one reference view of a generated handshake capture (8 views, 64
// labels) at 480x270 and 960x540, over the full image and over a person ROI
// (the GT person pixels dilated by 3 px), as Mpixel*labels/s of the pixels
// computed; and the accuracy of the winner-take-all plane sweep on the person
// pixels (share within 1% / 5% of the GT z). Plain executable; run:
//   build/bench/depth_cost_bench [repeats=3] [--json FILE]
// Times are the best of `repeats` runs, wall clock and process CPU time (all
// threads; the CPU figure is the one to compare on a shared machine). The captures are generated
// once, outside the timed part.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>

#include <tbb/info.h>
#include <opencv2/imgproc.hpp>

#include "bench_table.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/joint/depth_cost.h"
#include "u4d/synth/generate.h"
#include "u4d/util/timer.h"

namespace u4d {
namespace {

struct Scene {
  std::vector<Camera> cameras;
  std::vector<cv::Mat> images;
  cv::Mat gt_depth, person, roi;
  double near = 0, far = 0;
};

Scene LoadScene(int width, int height) {
  const fs::path dir =
      synth::WriteCaptureToTempDir("depth_cost_bench_" + std::to_string(width),
                                   synth::SmallHandshakeOptions(8, width, height, 2));
  const Capture capture = ReadCapture(dir);
  Scene s;
  for (int v = 0; v < capture.NumViews(); ++v) {
    s.cameras.push_back(capture.views[v].CameraAt(0));
    s.images.push_back(ReadColorImage(capture.ImagePath(v, 0)));
  }
  const std::string ref = capture.views[0].name;
  s.gt_depth = ReadPfm(dir / layout::GtDepth(ref, 0));
  s.person = (ReadLabelImage(dir / layout::GtInstances(ref, 0)) > 0) & (s.gt_depth > 0);
  cv::dilate(s.person, s.roi, cv::Mat::ones(7, 7, CV_8U));
  double lo = 0, hi = 0;
  cv::minMaxLoc(s.gt_depth, &lo, &hi, nullptr, nullptr, s.person);
  s.near = lo - 0.3;
  s.far = hi + 0.3;
  fs::remove_all(dir);
  return s;
}

void Run(const Scene& s, const char* what, const cv::Mat& roi, const DepthCostOptions& o,
         int repeats, bench::Table* table) {
  double best = 1e30, cpu = 1e30;
  DepthCostVolume vol;
  for (int i = 0; i < repeats; ++i) {
    Timer t;
    const std::clock_t c0 = std::clock();
    vol = ComputeDepthCostVolume(s.cameras, s.images, 0, roi, s.near, s.far, o);
    cpu = std::min(cpu, double(std::clock() - c0) / CLOCKS_PER_SEC);
    best = std::min(best, t.Seconds());
  }
  const int w = s.images[0].cols, h = s.images[0].rows;
  const double pixels = roi.empty() ? double(w) * h : cv::countNonZero(roi);
  const cv::Mat wta = WinnerTakeAllDepth(vol, roi);
  int n = 0, in1 = 0, in5 = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!s.person.at<uint8_t>(y, x)) continue;
      ++n;
      const double gt = s.gt_depth.at<float>(y, x), z = wta.at<float>(y, x);
      in1 += z > 0 && std::abs(z - gt) <= 0.01 * gt;
      in5 += z > 0 && std::abs(z - gt) <= 0.05 * gt;
    }
  std::printf(
      "%4dx%-4d %-4s r=%d k=%d aux=%d col=%d %7.0f px  wall %6.3f s %5.2f Mpx*lab/s  cpu %6.3f s "
      "%5.2f "
      "Mpx*lab/cpu-s | person px %5d: within 1%% %.3f, 5%% %.3f\n",
      w, h, what, o.patch_radius, o.num_best_views, o.max_aux_views, int(o.use_color), pixels, best,
      pixels * o.num_depths / best / 1e6, cpu, pixels * o.num_depths / cpu / 1e6, n,
      double(in1) / n, double(in5) / n);
  using bench::Cell;
  table->Row({Cell("%dx%d", w, h), what, Cell("%d", o.patch_radius), Cell("%d", o.num_best_views),
              Cell("%d", o.max_aux_views), Cell("%d", int(o.use_color)), Cell("%.0f", pixels),
              Cell("%.3f", best), Cell("%.2f", pixels * o.num_depths / best / 1e6),
              Cell("%.3f", cpu), Cell("%.2f", pixels * o.num_depths / cpu / 1e6), Cell("%d", n),
              Cell("%.3f", double(in1) / n), Cell("%.3f", double(in5) / n)});
}

}  // namespace
}  // namespace u4d

int main(int argc, char** argv) {
  using namespace u4d;
  bench::BenchTables tables("depth_cost_bench", bench::TakeJsonFlag(&argc, argv));
  bench::Table& table = tables.Record(
      "Depth cost volume", {"size", "roi", "r", "k", "aux", "col", "px", "wall s", "Mpx*lab/s",
                            "cpu s", "Mpx*lab/cpu-s", "person px", "within 1%", "within 5%"});
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  std::printf("TBB threads: %d; 8 views, 64 labels, reference view 0\n",
              tbb::info::default_concurrency());
  for (const auto& [w, h] : {std::pair{480, 270}, std::pair{960, 540}}) {
    const Scene s = LoadScene(w, h);
    std::printf("%dx%d: person depth range [%.2f, %.2f] m, person pixels %d\n", w, h, s.near, s.far,
                cv::countNonZero(s.person));
    const DepthCostOptions o;
    Run(s, "full", cv::Mat(), o, repeats, &table);
    Run(s, "roi", s.roi, o, repeats, &table);
    if (w == 480) {  // the cost does not depend on the patch size (box filters)
      for (int r : {1, 4}) {
        DepthCostOptions ro;
        ro.patch_radius = r;
        Run(s, "roi", s.roi, ro, repeats, &table);
      }
      DepthCostOptions grey;  // grey instead of colour ZNCC
      grey.use_color = false;
      Run(s, "roi", s.roi, grey, repeats, &table);
      DepthCostOptions k1;  // best-1 vs best-3 of 4 vs all of 7 usable views
      k1.num_best_views = 1;
      Run(s, "roi", s.roi, k1, repeats, &table);
      DepthCostOptions all;
      all.num_best_views = 7;
      all.max_aux_views = 7;
      Run(s, "roi", s.roi, all, repeats, &table);
    }
  }
  tables.Write();
  return 0;
}
