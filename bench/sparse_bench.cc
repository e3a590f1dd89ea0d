// Sparse multi-view reconstruction (features/sparse_points.h) on a generated
// handshake capture (8 views at 960x540, 10 frames by default), against its
// GT: points per frame, reprojection RMSE (px), share of points whose depth
// (median over their observations) is within 1/2/5 cm of the GT depth, share
// on the right instance (object -> GT person by majority, as in
// sparse_test.cc) and time per frame. Two configurations are run on the same
// frames: `all_pairs` (every view pair matched, the former method) and
// `neighbours` (the default: each view with its 2 nearest views). Run:
//   build/bench/sparse_bench [frames] [epipolar_px] [--json FILE]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

#include "bench_table.h"
#include "u4d/features/sparse_points.h"
#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/util/timer.h"

namespace u4d {
namespace {

struct Totals {
  double points = 0, sq = 0, obs = 0, within[3] = {0, 0, 0}, with_depth = 0, right = 0, seconds = 0;
  int frames = 0;
};

int Majority(const std::map<int, int>& votes) {
  return std::max_element(votes.begin(), votes.end(),
                          [](const auto& a, const auto& b) { return a.second < b.second; })
      ->first;
}

void Run(const fs::path& dir, int num_frames, const char* name, const SparseFrameOptions& o,
         bench::Table* table) {
  const Capture capture = ReadCapture(dir);
  FrameReader reader(capture);
  Totals t;
  for (int f = 0; f < std::min(num_frames, capture.num_frames); ++f) {
    std::vector<Camera> cams;
    std::vector<cv::Mat> images, masks, gt_ids, gt_depth;
    for (int v = 0; v < capture.NumViews(); ++v) {
      const std::string& n = capture.views[v].name;
      cams.push_back(capture.views[v].CameraAt(f));
      images.push_back(reader.Read(v, f));
      // A dropped detection (degraded input) has no mask file: empty mask.
      masks.push_back(
          fs::exists(dir / layout::Mask(n, f))
              ? ReadInstanceMask(dir / layout::Mask(n, f), dir / layout::MaskInfo(n, f)).ids
              : cv::Mat());
      gt_ids.push_back(
          ReadInstanceMask(dir / layout::GtInstances(n, f), dir / layout::GtInstancesInfo(n, f))
              .ids);
      gt_depth.push_back(ReadPfm(dir / layout::GtDepth(n, f)));
    }
    Timer timer;
    const SparseFrame sf = ReconstructSparseFrame(cams, images, masks, o);
    t.seconds += timer.Seconds();
    ++t.frames;
    std::vector<int> gt_of(sf.points.size());
    std::map<int, std::map<int, int>> votes;  // object -> GT id -> count
    for (size_t i = 0; i < sf.points.size(); ++i) {
      const SparsePoint& p = sf.points[i];
      t.sq += p.reprojection_rmse * p.reprojection_rmse * p.observations.size();
      t.obs += p.observations.size();
      std::map<int, int> gt_votes;
      std::vector<double> errors;
      for (size_t k = 0; k < p.observations.size(); ++k) {
        const int v = p.observations[k].first;
        ++gt_votes[MaskIdAt(gt_ids[v], p.pixels[k])];
        const int c = static_cast<int>(std::lround(p.pixels[k].x()));
        const int r = static_cast<int>(std::lround(p.pixels[k].y()));
        if (c < 0 || r < 0 || c >= gt_depth[v].cols || r >= gt_depth[v].rows) continue;
        const float z = gt_depth[v].at<float>(r, c);
        if (std::isfinite(z) && z > 0) errors.push_back(std::abs(cams[v].Depth(p.position) - z));
      }
      gt_of[i] = Majority(gt_votes);
      ++votes[p.instance][gt_of[i]];
      if (errors.empty()) continue;
      std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
      const double e = errors[errors.size() / 2];
      ++t.with_depth;
      t.within[0] += e < 0.01;
      t.within[1] += e < 0.02;
      t.within[2] += e < 0.05;
    }
    for (size_t i = 0; i < sf.points.size(); ++i) {
      const int obj = sf.points[i].instance;
      t.right += (obj == 0 ? 0 : Majority(votes[obj])) == gt_of[i];
    }
    t.points += sf.points.size();
  }
  std::printf(
      "%-10s frames %d  points/frame %.1f  reproj_rmse %.3f px  within 1/2/5 cm %.3f/%.3f/%.3f"
      "  right_instance %.3f  ms/frame %.0f\n",
      name, t.frames, t.points / t.frames, std::sqrt(t.sq / std::max(1.0, t.obs)),
      t.within[0] / t.with_depth, t.within[1] / t.with_depth, t.within[2] / t.with_depth,
      t.right / std::max(1.0, t.points), 1000 * t.seconds / t.frames);
  using bench::Cell;
  table->Row({name, Cell("%d", t.frames), Cell("%.1f", t.points / t.frames),
              Cell("%.3f", std::sqrt(t.sq / std::max(1.0, t.obs))),
              Cell("%.3f", t.within[0] / t.with_depth), Cell("%.3f", t.within[1] / t.with_depth),
              Cell("%.3f", t.within[2] / t.with_depth),
              Cell("%.3f", t.right / std::max(1.0, t.points)),
              Cell("%.0f", 1000 * t.seconds / t.frames)});
}

}  // namespace
}  // namespace u4d

int main(int argc, char** argv) {
  using namespace u4d;
  bench::BenchTables tables("sparse_bench", bench::TakeJsonFlag(&argc, argv));
  bench::Table& table = tables.Record(
      "Sparse points", {"matching", "frames", "points/frame", "reproj_rmse px", "within 1 cm",
                        "within 2 cm", "within 5 cm", "right_instance", "ms/frame"});
  const int frames = argc > 1 ? std::atoi(argv[1]) : 10;
  const double epipolar_px = argc > 2 ? std::atof(argv[2]) : 2.0;
  synth::SynthOptions o = synth::SmallHandshakeOptions(8, 960, 540, frames);
  const fs::path dir = synth::WriteCaptureToTempDir("sparse_bench", o);
  std::printf("handshake, 8 views 960x540, %d frames, epipolar gate %.2f px\n", frames,
              epipolar_px);
  SparseFrameOptions all;
  all.matching.neighbour_views = 0;
  all.matching.max_epipolar_px = epipolar_px;
  SparseFrameOptions neighbours;
  neighbours.matching.max_epipolar_px = epipolar_px;
  Run(dir, frames, "all_pairs", all, &table);
  Run(dir, frames, "neighbours", neighbours, &table);
  fs::remove_all(dir);
  tables.Write();
  return 0;
}
