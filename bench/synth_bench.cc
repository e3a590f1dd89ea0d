// Speed of the whole synthetic-capture generator (posing, rendering, GT flow,
// degradation, writing every file), 8 views at 960x540 by default. Run:
//   build/bench/synth_bench [--benchmark_min_time=...]
// The reported counter `frames_per_s` is capture frames (all views) per second;
// the baseline in the same run is the rendering alone (synth_render_bench).
#include <benchmark/benchmark.h>

#include "u4d/synth/generate.h"

namespace u4d::synth {
namespace {

void BM_WriteSyntheticCapture(benchmark::State& state) {
  SynthOptions o = SynthPreset("handshake");
  o.num_frames = static_cast<int>(state.range(0));
  o.rig.num_views = static_cast<int>(state.range(1));
  o.rig.image_width = 960;
  o.rig.image_height = 540;
  const fs::path dir = fs::temp_directory_path() / "u4d_synth_bench";
  double render_seconds = 0, seconds = 0;
  for (auto _ : state) {
    const SynthSummary s = WriteSyntheticCapture(o, dir);
    render_seconds += s.render_seconds;
    seconds += s.seconds;
  }
  fs::remove_all(dir);
  const double frames = static_cast<double>(state.iterations()) * o.num_frames;
  state.counters["frames_per_s"] = frames / seconds;
  state.counters["render_share"] = render_seconds / seconds;
}
BENCHMARK(BM_WriteSyntheticCapture)->Args({10, 8})->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace u4d::synth

BENCHMARK_MAIN();
