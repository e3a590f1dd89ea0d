// Where the time of one joint view solve goes (src/u4d/joint/joint_view.h,
// JointViewResult::phases; docs/results.md, "Hot kernels and the phases of
// one joint view solve"): the full method on
// the same synthetic inputs as bench/joint_bench (handshake capture, GT 3D
// poses and GT-sampled sparse motions), per-phase wall time averaged over the
// solved views, and the accuracy of the result (instance IoU, depth within
// 1% / 5%, flow EPE on GT person pixels) so that a speed change can be checked
// not to change the results. A plain executable that prints; Release build:
//   build/bench/joint_phases_bench [--views 8] [--width 480] [--height 270]
//       [--frames 3] [--start 128] [--max-views N] [--repeats 1] [the options of `u4d run`:
//       --config FILE, --set KEY=VALUE, its named flags such as --working-width 480]
//       [--json FILE]
// --repeats solves each view that many times (the phase times are averaged).
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "bench_table.h"
#include "u4d/eval/dense_metrics.h"
#include "u4d/eval/segmentation_metrics.h"
#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/layout.h"
#include "u4d/io/poses.h"
#include "u4d/joint/frame_setup.h"
#include "u4d/joint/joint_view.h"
#include "u4d/joint/parameters.h"
#include "u4d/pipeline/run_flags.h"
#include "u4d/synth/generate.h"
#include "u4d/testing/capture_inputs.h"
#include "u4d/testing/truth_inputs.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

using namespace u4d;

namespace {

struct Args {
  int views = 8, width = 480, height = 270, frames = 3, start = 128;
  int max_views = -1, repeats = 1;
  RunOverrides overrides;  // the joint and frame_setup options, as `u4d run` takes them
};

Args ParseArgs(int argc, char** argv) {
  Args a;
  const std::map<std::string, int*> ints = {{"--views", &a.views},    {"--width", &a.width},
                                            {"--height", &a.height},  {"--frames", &a.frames},
                                            {"--start", &a.start},    {"--max-views", &a.max_views},
                                            {"--repeats", &a.repeats}};
  for (int i = 1; i < argc; ++i) {
    const auto it = ints.find(argv[i]);
    if (it == ints.end() && a.overrides.Take(argc, argv, &i)) continue;
    U4D_CHECK(it != ints.end() && i + 1 < argc,
              "joint_phases_bench: unknown argument or missing value '{}' (expected --views, "
              "--width, --height, --frames, --start, --max-views, --repeats, or an option of "
              "`u4d run`: --config, --set, its named flags such as --working-width)",
              argv[i]);
    *it->second = std::stoi(argv[++i]);
  }
  U4D_CHECK(a.frames >= 3, "joint_phases_bench: --frames must be >= 3");
  U4D_CHECK(a.repeats >= 1, "joint_phases_bench: --repeats must be >= 1");
  return a;
}

}  // namespace

int main(int argc, char** argv) try {
  bench::BenchTables tables("joint_phases_bench", bench::TakeJsonFlag(&argc, argv));
  const Args args = ParseArgs(argc, argv);
  synth::SynthOptions so =
      synth::SmallHandshakeOptions(args.views, args.width, args.height, args.frames);
  so.start_frame = args.start;
  const fs::path dir = synth::WriteCaptureToTempDir("joint_phases_bench", so);
  const Capture capture = ReadCapture(dir);
  FrameReader reader(capture);
  const std::vector<std::vector<Pose3d>> poses = ReadGtPoses3d(capture);

  RunOptions run;
  args.overrides.ApplyTo(&run);
  run.Check();
  FrameSetupOptions setup = run.frame_setup;
  setup.pose = run.joint.pose;  // one capsule model, as in the pipeline
  const eval::InstanceSegOptions seg_options;
  eval::InstanceSegAccumulator seg;
  eval::DepthMetrics depth;
  eval::FlowMetrics flow;
  std::vector<JointViewResult::Phase> phases;  // summed over solves
  double total_seconds = 0, total_cpu = 0;
  int solves = 0;
  for (int frame = 1; frame + 1 < capture.num_frames; ++frame) {
    JointFrameData data = ReadJointFrameData(capture, &reader, frame, poses);
    std::vector<ViewTruth> truth;
    for (int v = 0; v < capture.NumViews(); ++v) {
      truth.push_back(ReadViewTruth(capture, v, frame));
      data.sparse[v] = SparseMotionsFromTruth(truth.back(), 150, 11 + v + 100 * frame);
    }
    double scale = 0;
    const std::vector<JointViewInput> inputs = MakeJointViewInputs(data, setup, &scale);
    JointViewOptions options = run.joint;
    if (run.paper_weights) options.weights = PaperWeights(capture.scene, capture.NumViews());
    const int nv =
        args.max_views > 0 ? std::min(args.max_views, capture.NumViews()) : capture.NumViews();
    for (int v = 0; v < nv; ++v) {
      const JointViewInput& in = inputs[v];
      if (in.objects.empty()) continue;
      JointViewResult r;
      for (int rep = 0; rep < args.repeats; ++rep) {
        r = SolveJointView(in, options);
        if (phases.empty())
          for (const JointViewResult::Phase& ph : r.phases) phases.push_back({ph.name, 0, 0});
        U4D_CHECK(phases.size() == r.phases.size(),
                  "joint_phases_bench: the phases differ between views");
        for (size_t i = 0; i < phases.size(); ++i) {
          phases[i].seconds += r.phases[i].seconds;
          phases[i].cpu_seconds += r.phases[i].cpu_seconds;
          total_cpu += r.phases[i].cpu_seconds;
        }
        total_seconds += r.seconds;
        ++solves;
      }
      const ViewTruth t = ScaleViewTruth(truth[v], in.initial_labels.size(), scale);
      const std::string ctx = fmt::format("frame {} view {}", frame, v);
      const eval::InstanceSegResult s =
          eval::EvaluateInstances(PersonInstances(r.labels), t.instances, seg_options, ctx);
      seg.Add(s);
      const cv::Mat people = t.instances.ids > 0;
      depth.Add(eval::EvaluateDepth(r.depth, t.depth, people, ctx));
      flow.Add(eval::EvaluateFlow(r.flow, t.flow, t.flow_valid, people, ctx));
      std::printf("frame %d view %d: IoU %.4f, %d depth / %d motion labels, %.2f s\n", frame, v,
                  s.mean_instance_iou, r.num_depth_labels, r.num_motion_labels, r.seconds);
      std::fflush(stdout);
    }
  }
  U4D_CHECK(solves > 0, "joint_phases_bench: no view had an object to solve");
  std::printf("\ncapture %d views %dx%d, working width %d, %d solves\n", args.views, args.width,
              args.height, setup.working_width, solves);
  std::printf("accuracy: IoU %.4f | depth within 1%% %.4f, 5%% %.4f, AbsRel %.5f | EPE %.4f px\n",
              seg.MeanInstanceIoU(), depth.Delta1Pct(), depth.Delta5Pct(), depth.AbsRel(),
              flow.Epe());
  // CPU time (all threads of this process) is the figure to compare on a
  // shared machine; wall time depends on the load.
  std::printf("\n");
  bench::Table& t =
      tables.Start("Phases", {"phase", "wall s / view", "CPU s / view", "CPU share"}, false);
  for (const JointViewResult::Phase& ph : phases)
    t.Row({ph.name, bench::Cell("%.3f", ph.seconds / solves),
           bench::Cell("%.3f", ph.cpu_seconds / solves),
           bench::Cell("%.1f%%", 100.0 * ph.cpu_seconds / total_cpu)});
  t.Row({"total", bench::Cell("%.3f", total_seconds / solves),
         bench::Cell("%.3f", total_cpu / solves), "100%"});
  tables.Write();
  fs::remove_all(dir);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "joint_phases_bench: %s\n", e.what());
  return 1;
}
