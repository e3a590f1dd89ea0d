// Render throughput of the synthetic capture renderer (synth/render.h):
// 8 views at 960x540 of an indoor room with two ~5k-triangle bodies.
#include <cmath>

#include <benchmark/benchmark.h>

#include "u4d/synth/environment.h"
#include "u4d/synth/render.h"
#include "u4d/synth/rig.h"

namespace u4d::synth {
namespace {

// A closed ellipsoid of (rings x segments x 2) triangles standing in for a body.
SceneObject Body(const Eigen::Vector3f& center, int instance_id, int rings, int segments) {
  SceneObject o;
  o.instance_id = instance_id;
  const Eigen::Vector3f radii(0.25f, 0.85f, 0.18f);
  for (int i = 0; i <= rings; ++i) {
    const double theta = M_PI * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * M_PI * j / segments;
      const Eigen::Vector3f d(std::sin(theta) * std::cos(phi), std::cos(theta),
                              std::sin(theta) * std::sin(phi));
      const Eigen::Vector3f p = radii.cwiseProduct(d);
      o.mesh.vertices.push_back(center + p);
      o.mesh.texcoords.push_back(p);
      o.mesh.vertex_part.push_back(i < rings / 5 ? BodyPart::kHead : BodyPart::kTorso);
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = i * segments + j, b = i * segments + (j + 1) % segments;
      o.mesh.faces.emplace_back(a, b + segments, b);
      o.mesh.faces.emplace_back(a, a + segments, b + segments);
    }
  o.mesh.face_material.assign(o.mesh.faces.size(), 0);
  Material m;
  m.pattern = Material::Pattern::kNoise;
  m.color_a = {0.8f, 0.5f, 0.3f};
  m.color_b = {0.2f, 0.3f, 0.5f};
  m.seed = instance_id;
  o.materials = {m};
  return o;
}

SceneFrame BenchFrame(double time) {
  SceneFrame frame;
  frame.time = time;
  const float dx = static_cast<float>(0.3 * std::sin(time));
  frame.people.push_back(Body({-0.6f + dx, 0.9f, 0.1f}, 1, 50, 50));  // 5000 triangles
  frame.people.push_back(Body({0.7f, 0.9f, -0.3f + dx}, 2, 50, 50));
  frame.statics = MakeEnvironment({});
  return frame;
}

void BM_RenderViews8x960x540(benchmark::State& state) {
  const SceneFrame frame = BenchFrame(0.0);
  const std::vector<Camera> cameras = RigCameras({});
  for (auto _ : state) {
    std::vector<RenderedView> views = RenderViews(cameras, frame);
    benchmark::DoNotOptimize(views.data());
  }
  state.counters["frames/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderViews8x960x540)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same frame starting from each static camera's cached background
// (StaticLayer, rendered once outside the loop): what u4d synth does for
// static rigs. Compare with BM_RenderViews8x960x540 in the same run.
void BM_RenderViewsCachedStatics8x960x540(benchmark::State& state) {
  const SceneFrame frame = BenchFrame(0.0);
  const std::vector<Camera> cameras = RigCameras({});
  const std::vector<StaticLayer> layers = RenderStaticLayers(cameras, frame.statics);
  for (auto _ : state) {
    std::vector<RenderedView> views = RenderViews(cameras, frame, {}, &layers);
    benchmark::DoNotOptimize(views.data());
  }
  state.counters["frames/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderViewsCachedStatics8x960x540)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ForwardFlow960x540(benchmark::State& state) {
  const SceneFrame f0 = BenchFrame(0.0), f1 = BenchFrame(1.0 / 30);
  const Camera cam = RigCameras({})[0];
  const RenderedView v0 = RenderView(cam, f0), v1 = RenderView(cam, f1);
  for (auto _ : state) {
    FlowField flow = ForwardFlow(v0, f0, f1, cam, cam, v1);
    benchmark::DoNotOptimize(flow.flow.data);
  }
}
BENCHMARK(BM_ForwardFlow960x540)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace u4d::synth
