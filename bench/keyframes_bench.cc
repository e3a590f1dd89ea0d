// Key-frames (keyframes/keyframe_similarity.h, paper Sec. 2.1.3) against the
// GT 3D poses of a generated handshake (GT masks, GT joints, SIFT tracks):
// per-term statistics of KS, then the selections (former count cover, count
// cover + medoids, the default) and the default with each of the five terms
// switched off and with other pose scales. Per configuration: mean KS, number
// of key-frames, mean GT pose distance member -> key-frame, over random
// pairs, their ratio, the max, the same for equal temporal segments with as
// many key-frames ("uniform"), and the recurrences (members > 10 frames from
// their key-frame: count and mean distance). Run:
//   build/bench/keyframes_bench [frames] [fps] [views] [csv] [seed] [--json FILE]
// Defaults: 64 frames at 8 fps from script frame 0 (the whole 8 s script:
// walk in, handshake, turn, walk away), 4 views 320x180, no csv, seed 1.
// `csv` (a path; "" for none) writes the view-averaged terms and the GT pose
// distance, one row per frame pair.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "bench_table.h"
#include "u4d/eval/keyframe_eval.h"
#include "u4d/io/capture.h"
#include "u4d/io/layout.h"
#include "u4d/keyframes/keyframe_similarity.h"
#include "u4d/synth/generate.h"
#include "u4d/testing/capture_inputs.h"
#include "u4d/util/timer.h"

namespace u4d {
namespace {

std::string Join(const std::vector<int>& v) {
  std::string s;
  for (int x : v) {
    if (!s.empty()) s += ' ';  // appended, not `" " + ...`: GCC 12's false -Wrestrict
    s += std::to_string(x);
  }
  return s;
}

int Main(int argc, char** argv) {
  bench::BenchTables tables("keyframes_bench", bench::TakeJsonFlag(&argc, argv));
  const int frames = argc > 1 ? std::atoi(argv[1]) : 64;
  const double fps = argc > 2 ? std::atof(argv[2]) : 8;
  const int views = argc > 3 ? std::atoi(argv[3]) : 4;
  const std::string csv = argc > 4 ? argv[4] : "";
  const uint64_t seed = argc > 5 ? std::strtoull(argv[5], nullptr, 10) : 1;
  synth::SynthOptions o = synth::SmallHandshakeOptions(views, 320, 180, frames);
  o.start_frame = 0;
  o.fps = fps;
  o.seed = seed;
  o.script_seconds = std::max(o.script_seconds, frames / fps);
  Timer timer;
  const fs::path dir = synth::WriteCaptureToTempDir("keyframes_bench", o);
  const Capture capture = ReadCapture(dir);
  std::vector<std::vector<Pose3d>> gt_poses;
  for (int f = 0; f < capture.num_frames; ++f)
    gt_poses.push_back(ReadPoses3d(dir / layout::GtJoints3d(f)));
  const std::vector<TemporalTrack> tracks =
      ComputeTemporalTracks(capture, {}, TemporalTrackOptions{});
  const KeyframeObservations obs = ReadKeyframeObservations(capture, true, tracks);
  const Eigen::MatrixXd gt = GtPoseDistanceMatrix(gt_poses);
  std::printf(
      "handshake: %d frames at %.1f fps, %d views 320x180 (GT masks, GT joints, SIFT "
      "tracks); generated in %.1f s\n",
      capture.num_frames, fps, views, timer.Seconds());

  Timer ks_timer;
  const KeyframeTermMatrices terms = ComputeKeyframeTermMatrices(obs);
  std::printf("term matrices in %.1f s\n", ks_timer.Seconds());
  if (!csv.empty()) {
    std::ofstream out(csv);
    out << "i,j,m,l,d,p,s,gt\n";
    for (int i = 0; i < obs.num_frames; ++i) {
      for (int j = i + 1; j < obs.num_frames; ++j) {
        out << i << ',' << j << ',' << terms.m(i, j) << ',' << terms.l(i, j) << ',' << terms.d(i, j)
            << ',' << terms.p(i, j) << ',' << terms.i(i, j) << ',' << gt(i, j) << '\n';
      }
    }
  }
  // Per term: mean over pairs, and mean over the pairs of GT pose distance
  // below / above the median (how much the term separates alike from unlike).
  {
    std::vector<double> all;
    for (int a = 0; a < gt.rows(); ++a)
      for (int b = a + 1; b < gt.rows(); ++b) all.push_back(gt(a, b));
    std::nth_element(all.begin(), all.begin() + all.size() / 2, all.end());
    const double median = all[all.size() / 2];
    std::printf("GT pose distance: median over pairs %.4f m\n", median);
    std::printf("%-5s %7s %12s %12s\n", "term", "mean", "GT<=median", "GT>median");
    bench::Table& term_rows = tables.Record(
        bench::Cell("Keyframe terms (GT pose distance: median over pairs %.4f m)", median),
        {"term", "mean", "GT<=median", "GT>median"});
    const std::pair<const char*, const Eigen::MatrixXd*> named[] = {
        {"M", &terms.m}, {"L", &terms.l}, {"D", &terms.d}, {"P", &terms.p}, {"I", &terms.i}};
    for (const auto& [name, m] : named) {
      double s = 0, lo = 0, hi = 0;
      int n = 0, nlo = 0, nhi = 0;
      for (int a = 0; a < gt.rows(); ++a) {
        for (int b = a + 1; b < gt.rows(); ++b) {
          s += (*m)(a, b), ++n;
          if (gt(a, b) <= median)
            lo += (*m)(a, b), ++nlo;
          else
            hi += (*m)(a, b), ++nhi;
        }
      }
      std::printf("%-5s %7.3f %12.3f %12.3f\n", name, s / n, lo / std::max(1, nlo),
                  hi / std::max(1, nhi));
      term_rows.Row({name, bench::Cell("%.3f", s / n), bench::Cell("%.3f", lo / std::max(1, nlo)),
                     bench::Cell("%.3f", hi / std::max(1, nhi))});
    }
  }

  // Selections: the former greedy cover by count (no refinement), the cover
  // by count with medoid refinement, and the default (similarity cover +
  // medoids); then the default with each term switched off and with other
  // pose scales.
  struct Config {
    std::string name;
    KeyframeOptions options;
    KeyframeSelectOptions select;
    double pose_scale_m = 0;  // 0: the terms above
  };
  std::vector<Config> configs;
  auto add = [&](std::string name) {
    configs.push_back({std::move(name), {}, {}, 0});
    return &configs.back();
  };
  Config* c = add("count cover, no medoids (former)");
  c->select.cover = KeyframeCover::kCount;
  c->select.medoid_rounds = 0;
  c = add("count cover + medoids");
  c->select.cover = KeyframeCover::kCount;
  add("similarity cover + medoids (default)");
  add("default without M")->options.use_correspondence = false;
  add("default without L")->options.use_semantic = false;
  add("default without D")->options.use_distance = false;
  add("default without P")->options.use_pose = false;
  add("default without I")->options.use_shape = false;
  for (double scale : {0.15, 0.1}) {
    c = add(fmt::format("default, pose scale {} m", scale));
    c->pose_scale_m = scale;
  }
  c = add("former selection, pose scale 0.1 m");
  c->select.cover = KeyframeCover::kCount;
  c->select.medoid_rounds = 0;
  c->pose_scale_m = 0.1;
  std::printf("%-40s %6s %4s %9s %9s %6s %7s %9s %9s  %s\n", "configuration", "meanKS", "#KF",
              "member_m", "random_m", "ratio", "max_m", "uniform_m", "recur", "key-frames");
  bench::Table& selections =
      tables.Record("Selections", {"configuration", "meanKS", "#KF", "member_m", "random_m",
                                   "ratio", "max_m", "uniform_m", "recur", "key-frames"});
  for (const Config& c : configs) {
    KeyframeTermMatrices t = terms;
    if (c.pose_scale_m > 0) {
      KeyframeOptions pose_only;
      pose_only.use_correspondence = pose_only.use_semantic = pose_only.use_distance =
          pose_only.use_shape = false;
      pose_only.pose_scale_m = c.pose_scale_m;
      t.p = ComputeKeyframeTermMatrices(obs, pose_only).p;
    }
    const Eigen::MatrixXd ks = CombineKeyframeTerms(t, c.options);
    const KeyframeSelection sel = SelectKeyframes(ks, c.select);
    const KeyframeGtEvaluation e = EvaluateKeyframesWithGtPoses(sel, gt);
    const std::string recur = fmt::format("{}:{:.4f}", e.recurring_members, e.mean_recurring);
    std::printf("%-40s %6.3f %4d %9.4f %9.4f %6.2f %7.4f %9.4f %9s  [%s]\n", c.name.c_str(),
                ks.mean(), e.num_keyframes, e.mean_member, e.mean_all, e.MemberRatio(),
                e.max_member, e.mean_member_uniform, recur.c_str(), Join(sel.keyframes).c_str());
    using bench::Cell;
    selections.Row({c.name, Cell("%.3f", ks.mean()), Cell("%d", e.num_keyframes),
                    Cell("%.4f", e.mean_member), Cell("%.4f", e.mean_all),
                    Cell("%.2f", e.MemberRatio()), Cell("%.4f", e.max_member),
                    Cell("%.4f", e.mean_member_uniform), recur, Join(sel.keyframes)});
  }
  fs::remove_all(dir);
  tables.Write();
  return 0;
}

}  // namespace
}  // namespace u4d

int main(int argc, char** argv) { return u4d::Main(argc, argv); }
