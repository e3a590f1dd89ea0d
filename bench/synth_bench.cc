// Speed of the whole synthetic-capture generator (posing, rendering, GT flow,
// degradation, writing every file), 8 views at 960x540 by default. Run:
//   build/bench/synth_bench [--benchmark_min_time=...]
// The reported counter `frames_per_s` is capture frames (all views) per second;
// the baseline in the same run is the rendering alone (synth_render_bench).
// BM_WriteSyntheticCapture is the handshake, BM_WriteRealisticCapture the
// realistic world (captured performers, motion blur, shadows, the realistic
// detector; skipped without the shared data).
#include <benchmark/benchmark.h>

#include "bench_worlds.h"
#include "u4d/synth/generate.h"

namespace u4d::synth {
namespace {

void WriteCaptures(benchmark::State& state, const std::string& preset) {
  if (!bench::WorldAvailable(preset)) {
    state.SkipWithError("no shared data (captured_meshes)");
    return;
  }
  SynthOptions o = bench::World(preset, static_cast<int>(state.range(1)), 960, 540,
                                static_cast<int>(state.range(0)));
  o.write_meshes = true;
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
void BM_WriteSyntheticCapture(benchmark::State& state) { WriteCaptures(state, "handshake"); }
void BM_WriteRealisticCapture(benchmark::State& state) { WriteCaptures(state, "realistic"); }
BENCHMARK(BM_WriteSyntheticCapture)->Args({10, 8})->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_WriteRealisticCapture)->Args({10, 8})->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace u4d::synth

BENCHMARK_MAIN();
