// Sparse temporal tracks (features/temporal_tracks.h) on a generated handshake
// capture, 8 views at 960x540 by default: track count, precision against the
// GT flow and time per matched frame pair. The capture is generated once,
// outside the timed part. Run:
//   build/bench/tracks_bench [--benchmark_min_time=...]
// Counters: tracks (feature tracks, all views), joint_tracks, precision (share
// of track steps within 2 px of the composed GT flow), ms_per_pair (matching
// time per frame pair), ms_detect_per_frame (SIFT per view-frame).
#include <benchmark/benchmark.h>

#include "u4d/eval/track_metrics.h"
#include "u4d/features/temporal_tracks.h"
#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/testing/capture_inputs.h"

namespace u4d {
namespace {

void BM_TemporalTracks(benchmark::State& state) {
  synth::SynthOptions o = synth::SynthPreset("handshake");
  o.num_frames = static_cast<int>(state.range(0));
  o.rig.num_views = static_cast<int>(state.range(1));
  o.rig.image_width = 960;
  o.rig.image_height = 540;
  o.write_meshes = false;
  const fs::path dir = fs::temp_directory_path() / "u4d_tracks_bench";
  synth::WriteSyntheticCapture(o, dir);
  const Capture capture = ReadCapture(dir);
  std::vector<std::vector<Pose3d>> poses;
  for (int f = 0; f < capture.num_frames; ++f) {
    poses.push_back(ReadPoses3d(dir / layout::GtJoints3d(f)));
  }
  TrackStats stats;
  std::vector<TemporalTrack> tracks;
  for (auto _ : state) {
    stats = {};
    tracks = ComputeTemporalTracks(capture, poses, TemporalTrackOptions{}, 0, -1, &stats);
  }
  const TrackPrecision p = EvaluateTracksWithGtFlow(capture, tracks, 2.0);
  int feature = 0;
  for (const TemporalTrack& t : tracks) feature += !t.from_joint;
  fs::remove_all(dir);
  state.counters["tracks"] = feature;
  state.counters["joint_tracks"] = static_cast<double>(tracks.size() - feature);
  state.counters["precision"] = p.Precision();
  state.counters["evaluated"] = static_cast<double>(p.evaluated);
  state.counters["one_way"] = static_cast<double>(stats.one_way_matches);
  state.counters["symmetric"] = static_cast<double>(stats.symmetric_matches);
  state.counters["ms_per_pair"] = 1e3 * stats.seconds_match / std::max(1, stats.frame_pairs);
  state.counters["ms_detect_per_frame"] =
      1e3 * stats.seconds_detect / (capture.num_frames * capture.NumViews());
}
BENCHMARK(BM_TemporalTracks)->Args({12, 8})->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace u4d

BENCHMARK_MAIN();
