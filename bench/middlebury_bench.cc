// The depth data term E_d alone on real stereo pairs with ground truth: the
// Middlebury 2001/2003 pairs in $U4D_DATA_DIR/middlebury_stereo (default
// /work/shared/data; tsukuba, venus, teddy, cones: imL/imR, groundtruth.png =
// disparity * scale (info.txt: scale, then the maximum disparity), nonocc.png
// = 255 on the non-occluded pixels).
//
// A rectified pair is a two-view rig: K = [f 0 cx; 0 f cy] for both, the left
// camera at the origin, the right one at (B, 0, 0) (cam_from_world
// translation (-B, 0, 0)), so a disparity d means z = f B / d. Our E_d
// (joint/depth_cost.h: ZNCC over (2r+1)^2 BGR patches, plane sweep) is built
// with one depth label per integer disparity in [1, max disparity] (uniform in
// inverse depth = uniform in disparity), k = 1 auxiliary view, default
// options otherwise, and read
//   ours-wta     winner-take-all with the sub-sample parabola
//                (WinnerTakeAllDepth; pixels whose best cost is >= M_U unknown)
//   ours-mrf     α-expansion (mrf/expansion.h) of E_d + E_s alone: the joint
//                energy's depth block with one label everywhere, i.e. λ_d E_d
//                (with the unknown label at M_U) + λ_s λ_s^s min(|Δd|, τ_d)/τ_d
//                over 8-neighbours, the paper's weights (PaperWeights indoor,
//                2 views) and τ_d of JointViewOptions; then the parabola
//   sgbm, bm     OpenCV StereoSGBM (3-way, block 5, P1/P2 = 8/32 * 3 * 25,
//                uniqueness 10, left-right check 1, speckle 100/2) and
//                StereoBM (block 15 on grey, OpenCV defaults otherwise) over
//                disparities [0, 16 * ceil((max + 1) / 16)).
// Metric (Middlebury): bad-pixel rate |d - d_gt| > 1 px on the non-occluded
// pixels with GT (unknown = bad, as Middlebury counts a missing value), the
// density of the estimate there, and the mean absolute error on the pixels
// with an estimate.
//   build/bench/middlebury_bench [scene ...] [--json FILE]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench_table.h"
#include "u4d/geometry/camera.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/joint/depth_cost.h"
#include "u4d/joint/joint_view.h"
#include "u4d/joint/parameters.h"
#include "u4d/mrf/expansion.h"
#include "u4d/util/check.h"
#include "u4d/util/file.h"
#include "u4d/util/timer.h"

namespace fs = std::filesystem;
using namespace u4d;

namespace {

struct Scene {
  std::string name;
  cv::Mat left, right;  // BGR
  cv::Mat gt;           // CV_32F disparity, 0 = unknown
  cv::Mat nonocc;       // CV_8U nonzero = evaluated
  int max_disp = 0;
};

Scene ReadScene(const fs::path& dir) {
  Scene s;
  s.name = dir.filename().string();
  s.left = ReadColorImage(dir / "imL.png");
  s.right = ReadColorImage(dir / "imR.png");
  std::ifstream info(dir / "info.txt");
  double scale = 0;
  info >> scale >> s.max_disp;
  U4D_CHECK(info && scale > 0 && s.max_disp > 1,
            "middlebury_bench: {} must hold the GT scale and the maximum disparity",
            (dir / "info.txt").string());
  const cv::Mat raw = cv::imread((dir / "groundtruth.png").string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat nonocc = cv::imread((dir / "nonocc.png").string(), cv::IMREAD_GRAYSCALE);
  U4D_CHECK(!raw.empty() && !nonocc.empty() && raw.size() == s.left.size() &&
                nonocc.size() == s.left.size() && s.right.size() == s.left.size(),
            "middlebury_bench: {}: groundtruth.png, nonocc.png, imL.png and imR.png must exist "
            "and have one size",
            dir.string());
  raw.convertTo(s.gt, CV_32F, 1.0 / scale);
  s.nonocc = (nonocc > 128) & (raw > 0);
  return s;
}

struct Score {
  double bad = 0, density = 0, mae = 0;
};

Score Evaluate(const cv::Mat& disp, const Scene& s) {
  long n = 0, bad = 0, valid = 0;
  double abs_sum = 0;
  for (int y = 0; y < disp.rows; ++y)
    for (int x = 0; x < disp.cols; ++x) {
      if (!s.nonocc.at<uint8_t>(y, x)) continue;
      ++n;
      const float d = disp.at<float>(y, x);
      if (!(d > 0) || !std::isfinite(d)) {
        ++bad;
        continue;
      }
      ++valid;
      const double e = std::abs(d - s.gt.at<float>(y, x));
      abs_sum += e;
      bad += e > 1.0;
    }
  Score r;
  r.bad = n ? static_cast<double>(bad) / n : NAN;
  r.density = n ? static_cast<double>(valid) / n : NAN;
  r.mae = valid ? abs_sum / valid : NAN;
  return r;
}

// Depth (z) -> disparity f B / z, 0 stays 0.
cv::Mat ToDisparity(const cv::Mat& depth, double fb) {
  cv::Mat d = cv::Mat::zeros(depth.size(), CV_32F);
  for (int i = 0; i < depth.rows * depth.cols; ++i) {
    const float z = depth.ptr<float>()[i];
    if (z > 0) d.ptr<float>()[i] = static_cast<float>(fb / z);
  }
  return d;
}

cv::Mat FromOpenCv(const cv::Mat& disp16) {
  cv::Mat d;
  disp16.convertTo(d, CV_32F, 1.0 / 16);
  d.setTo(0, d < 0);  // invalid marker (min disparity - 1)
  return d;
}

// E_d + E_s of the joint energy's depth block (joint_view.cc DepthUnary and
// PairV with one label everywhere): labels 0..n-1 are depths, n the unknown.
struct DepthEnergy : mrf::GridEnergy {
  const DepthCostVolume& volume;
  double lambda_d, lambda_s, tau;
  int unknown;
  DepthEnergy(const DepthCostVolume& v, double ld, double ls, double t)
      : volume(v), lambda_d(ld), lambda_s(ls), tau(t), unknown(v.NumLabels()) {}
  double Unary(int p, int l) const override {
    return lambda_d * (l == unknown ? volume.unknown_cost : volume.At(p, l));
  }
  double Pairwise(int, int, int a, int b) const override {
    if (a == unknown || b == unknown) return a == b ? 0.0 : lambda_s;
    return lambda_s * std::min<double>(std::abs(a - b), tau) / tau;
  }
};

}  // namespace

int main(int argc, char** argv) try {
  bench::BenchTables tables("middlebury_bench", bench::TakeJsonFlag(&argc, argv));
  const char* env = std::getenv("U4D_DATA_DIR");
  const fs::path root = (env != nullptr && *env ? fs::path(env) : fs::path("/work/shared/data")) /
                        "middlebury_stereo";
  std::vector<std::string> names = {"tsukuba", "venus", "teddy", "cones"};
  if (argc > 1) names.assign(argv + 1, argv + argc);

  const std::vector<std::string> methods = {"ours-wta", "ours-mrf", "sgbm", "bm"};
  std::printf("Middlebury stereo (%s): bad pixels |d - d_gt| > 1 px on non-occluded GT pixels\n",
              root.string().c_str());
  std::printf(
      "(unknown = bad), density of the estimate there, mean abs. error (px) where "
      "estimated, wall time\n\n");
  bench::Table& per_scene = tables.Start(
      "Per scene", {"scene", "method", "bad > 1 px", "density", "mean abs err px", "s"}, false);
  std::vector<double> bad_sum(methods.size(), 0), time_sum(methods.size(), 0);
  for (const std::string& name : names) {
    const Scene s = ReadScene(root / name);
    const int w = s.left.cols, h = s.left.rows;
    Camera left;
    left.width = w;
    left.height = h;
    const double f = w, baseline = 0.1, fb = f * baseline;
    left.K << f, 0, (w - 1) / 2.0, 0, f, (h - 1) / 2.0, 0, 0, 1;
    Camera right = left;
    right.cam_from_world.translation = Eigen::Vector3d(-baseline, 0, 0);
    const std::vector<Camera> cameras = {left, right};
    const std::vector<cv::Mat> images = {s.left, s.right};

    std::vector<cv::Mat> disp(methods.size());
    std::vector<double> secs(methods.size(), 0);
    // Ours: one label per integer disparity max..1.
    DepthCostOptions dco;
    dco.num_depths = s.max_disp;
    dco.num_best_views = 1;
    dco.max_aux_views = 1;
    Timer timer;
    const DepthCostVolume volume =
        ComputeDepthCostVolume(cameras, images, 0, cv::Mat(), fb / s.max_disp, fb / 1.0, dco);
    const double volume_s = timer.Seconds();
    timer.Restart();
    disp[0] = ToDisparity(WinnerTakeAllDepth(volume, cv::Mat()), fb);
    secs[0] = volume_s + timer.Seconds();

    timer.Restart();
    {
      const JointWeights jw = PaperWeights(SceneType::kIndoor, 2);
      const JointViewOptions jo;
      const DepthEnergy energy(volume, jw.depth, jw.smooth * jw.smooth_spatial,
                               jo.depth_truncation);
      mrf::GridGraph grid;
      grid.width = w;
      grid.height = h;
      // Start from the WTA labels (unknown where WTA is unknown).
      std::vector<int> labels(static_cast<size_t>(w) * h);
      for (int p = 0; p < w * h; ++p) {
        int best = energy.unknown;
        double bc = volume.unknown_cost;
        for (int l = 0; l < volume.NumLabels(); ++l)
          if (volume.At(p, l) < bc) bc = volume.At(p, l), best = l;
        labels[p] = best;
      }
      std::vector<int> candidates(volume.NumLabels() + 1);
      for (int l = 0; l <= volume.NumLabels(); ++l) candidates[l] = l;
      mrf::ExpansionOptions eo;
      eo.max_sweeps = 3;
      const mrf::ExpansionSummary sum = mrf::AlphaExpansion(grid, energy, candidates, &labels, eo);
      for (int& l : labels)
        if (l == energy.unknown) l = -1;
      disp[1] = ToDisparity(RefineDepthLabels(volume, labels), fb);
      std::fprintf(stderr, "%s: expansion %d sweeps, energy %.1f -> %.1f\n", name.c_str(),
                   sum.sweeps, sum.initial_energy, sum.final_energy);
    }
    secs[1] = volume_s + timer.Seconds();

    const int num_disp = (s.max_disp + 1 + 15) / 16 * 16;
    timer.Restart();
    {
      const int bs = 5, area = bs * bs;
      auto sgbm = cv::StereoSGBM::create(0, num_disp, bs, 8 * 3 * area, 32 * 3 * area, 1, 0, 10,
                                         100, 2, cv::StereoSGBM::MODE_SGBM_3WAY);
      cv::Mat d16;
      sgbm->compute(s.left, s.right, d16);
      disp[2] = FromOpenCv(d16);
    }
    secs[2] = timer.Seconds();
    timer.Restart();
    {
      cv::Mat gl, gr, d16;
      cv::cvtColor(s.left, gl, cv::COLOR_BGR2GRAY);
      cv::cvtColor(s.right, gr, cv::COLOR_BGR2GRAY);
      auto bm = cv::StereoBM::create(num_disp, 15);
      bm->compute(gl, gr, d16);
      disp[3] = FromOpenCv(d16);
    }
    secs[3] = timer.Seconds();

    for (size_t m = 0; m < methods.size(); ++m) {
      const Score sc = Evaluate(disp[m], s);
      bad_sum[m] += sc.bad;
      time_sum[m] += secs[m];
      per_scene.Row({name, methods[m], bench::Cell("%.3f", sc.bad), bench::Cell("%.3f", sc.density),
                     bench::Cell("%.2f", sc.mae), bench::Cell("%.2f", secs[m])});
    }
    std::fflush(stdout);
  }
  bench::Table& mean =
      tables.Start("Mean over the scenes", {"method", "mean bad > 1 px", "total s", "s / sgbm s"});
  for (size_t m = 0; m < methods.size(); ++m)
    mean.Row({methods[m], bench::Cell("%.3f", bad_sum[m] / names.size()),
              bench::Cell("%.2f", time_sum[m]), bench::Cell("%.1f", time_sum[m] / time_sum[2])});
  tables.Write();
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "middlebury_bench: %s\n", e.what());
  return 1;
}
