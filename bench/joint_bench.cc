// Accuracy and timing of the joint per-view optimisation of label, depth and
// motion (paper Sec. 2.1, src/u4d/joint/joint_view.h, docs/joint.md) on a
// synthetic capture, against the baselines measured in the same run:
//   segmentation  initial masks, GrabCut seeded with them, joint, ablations
//   depth         winner-take-all plane sweep on the same cost volume, OpenCV SGBM on
//                 rectified pairs (median-fused), joint, ablations
//   flow          zero, DIS, DeepFlow, Farneback, joint, ablations
// Inputs are built as in joint_view_test.cc: GT 3D poses stand in for the
// tracked poses and the sparse motions are GT flow sampled at random GT-valid
// person pixels. Every view of frames 1 .. frames-2 is solved.
// A plain executable that prints; run from a Release build:
//   build/bench/joint_bench [--views 8] [--width 480] [--height 270] [--frames 4]
//       [--start 128] [--preset handshake|meetup|realistic|realistic-moving] [--sparse 150]
//       [--no-ablations] [--max-views N] [--methods full,P_M,...] [--weights '{"pose": 0.9}']
//       [--force-merge] [--per-view] [--dump DIR] [--json FILE]
//       [the options of `u4d run`: --config FILE, --set KEY=VALUE and its named flags
//        (pipeline/run_flags.h, docs/options.md), e.g. --working-width 480 --rounds 2
//        --motion-candidates K; the joint and frame_setup options apply here]
//       [shorthands for options (BenchFlags below): --no-cross-view --reg-linear
//        --no-reg-edge --reg-boundary free|discontinuity|ignore --no-split-merged
//        --pose-3d-any-label --semantic-temporal --occluder-limb-radius M
//        --appearance-refits N --appearance-inset PX --no-carry-depth --depth-coarse-step N
//        --sweeps N --depth-refine-band N --fusion-rounds N --no-depth-object-ranges
//        --motion-window N]
// --weights JSON overrides the paper's row of weights for the capture.
// --per-view: one line per method and view-frame (IoU, depth within 5 %, flow
// EPE), for paired comparisons of the ablations. --dump DIR: per view-frame
// f<frame>_v<view>_<name>: the initial, GT and each method's labels (16-bit
// PNG), each method's depth and the GT depth (PFM), and the pose term's map
// (covering person as PNG, w(p) as PFM), for per-pixel diagnosis.
// --force-merge: the detector merges every touching pair (MaskDegradeOptions
// merge_prob = 1, the other degradations at their defaults) and, unless
// --start is given, the window is centred on the handshake (the hands meet);
// prints per view-frame whether the merged pair comes out as two instances.
// When every view of a frame is solved (no --max-views below --views), each
// depth method's maps of the frame (and the GT depth) are also fused per GT
// person with the GT masks (eval/fused_reconstruction.h): the paper's
// reconstruction projection error and the Chamfer distance to the GT mesh.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <open3d/geometry/TriangleMesh.h>
#include <opencv2/imgproc.hpp>

#include "bench_table.h"
#include "bench_worlds.h"
#include "u4d/baselines/flow_baselines.h"
#include "u4d/baselines/grabcut_baseline.h"
#include "u4d/baselines/stereo_baseline.h"
#include "u4d/eval/dense_metrics.h"
#include "u4d/eval/fused_reconstruction.h"
#include "u4d/eval/mesh_metrics.h"
#include "u4d/eval/segmentation_metrics.h"
#include "u4d/init/init.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/poses.h"
#include "u4d/joint/frame_setup.h"
#include "u4d/joint/joint_view.h"
#include "u4d/pipeline/initial_objects.h"
#include "u4d/pipeline/run_flags.h"
#include "u4d/synth/generate.h"
#include "u4d/testing/capture_inputs.h"
#include "u4d/testing/truth_inputs.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

using namespace u4d;

namespace {

struct Args {
  int views = 8, width = 480, height = 270, frames = 4, start = 128;
  std::string preset = "handshake";
  int sparse = 150;
  bool ablations = true;
  int max_views = -1;        // views solved per frame (-1 = all)
  std::string weights;       // JSON overriding PaperWeights (keys of ToJson(JointWeights))
  std::string methods;       // comma-separated subset of full and the ablations (empty = all)
  bool force_merge = false;  // every touching pair merged in the initial masks (see above)
  bool start_given = false;  // --start was given
  bool per_view = false;     // print every method's IoU / depth / EPE per view-frame
  std::string dump;          // folder: per view-frame labels, depth, truth and pose map (diagnosis)
  RunOverrides overrides;    // the options (joint, frame_setup) as `u4d run` takes them
};

// The bench's shorthands for options of `u4d run` (keys of docs/options.md).
const std::vector<OptionFlag>& BenchFlags() {
  static const std::vector<OptionFlag> flags = {
      {"--no-cross-view", "joint.flow.cross_view", "false"},
      {"--reg-linear", "joint.motion_reg_quadratic", "false"},
      {"--no-reg-edge", "joint.motion_reg_edge_aware", "false"},
      {"--reg-boundary", "joint.motion_reg_boundary", ""},
      {"--no-split-merged", "frame_setup.split_merged", "false"},
      {"--pose-3d-any-label", "joint.pose.shape_own_label_only", "false"},
      {"--semantic-temporal", "joint.semantic_temporal", "true"},
      {"--occluder-limb-radius", "joint.pose.occluder_limb_radius_m", ""},
      {"--appearance-refits", "joint.appearance_refits", ""},
      {"--appearance-inset", "joint.labels.appearance_inset_px", ""},
      {"--no-carry-depth", "joint.label_moves_carry_depth", "false"},
      {"--depth-coarse-step", "joint.depth_coarse_step", ""},
      {"--sweeps", "joint.sweeps_per_block", ""},
      {"--depth-refine-band", "joint.depth_refine_band", ""},
      {"--fusion-rounds", "joint.fusion.rounds", ""},
      {"--no-depth-object-ranges", "joint.depth_object_ranges", "false"},
      {"--motion-window", "joint.motion_labels.window", ""},
  };
  return flags;
}

Args ParseArgs(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> std::string {
      U4D_CHECK(i + 1 < argc, "joint_bench: {} needs a value", k);
      return argv[++i];
    };
    // The bench's own flags first: its --frames is the capture's length.
    if (k == "--views")
      a.views = std::stoi(next());
    else if (k == "--width")
      a.width = std::stoi(next());
    else if (k == "--height")
      a.height = std::stoi(next());
    else if (k == "--frames")
      a.frames = std::stoi(next());
    else if (k == "--start")
      a.start = std::stoi(next()), a.start_given = true;
    else if (k == "--force-merge")
      a.force_merge = true;
    else if (k == "--preset")
      a.preset = next();
    else if (k == "--sparse")
      a.sparse = std::stoi(next());
    else if (k == "--no-ablations")
      a.ablations = false;
    else if (k == "--max-views")
      a.max_views = std::stoi(next());
    else if (k == "--weights")
      a.weights = next();
    else if (k == "--methods")
      a.methods = next();
    else if (k == "--per-view")
      a.per_view = true;
    else if (k == "--dump")
      a.dump = next();
    else if (!a.overrides.Take(argc, argv, &i, BenchFlags()))
      throw Error(fmt::format(
          "joint_bench: unknown argument '{}' (expected --views, --width, --height, --frames, "
          "--start, --preset, --sparse, --no-ablations, --max-views, --methods, --weights, "
          "--force-merge, --per-view, --dump, or an option of `u4d run`: --config, --set, "
          "its named flags, the shorthands of the header)",
          k));
  }
  U4D_CHECK(a.frames >= 3, "joint_bench: --frames must be >= 3 (frames 1..frames-2 are solved)");
  return a;
}

// Everything measured for one method.
struct Stats {
  eval::InstanceSegAccumulator seg;
  eval::DepthMetrics depth;
  eval::FlowMetrics flow;
  double seconds = 0;
  int runs = 0;
  bool has_seg = false, has_depth = false, has_flow = false;
};

// --force-merge: the view-frames whose initial masks merge >= 2 GT people.
struct MergeStats {
  eval::InstanceSegAccumulator seg;
  int view_frames = 0;
  int split = 0;  // every GT person matched by its own instance with IoU >= match_iou
};

// Per energy-trace step (same schedule for every view): energy / E_init and time.
struct TraceStats {
  std::string block;
  double sum_ratio = 0, sum_seconds = 0;
  int count = 0;
};

double Nan() { return std::nan(""); }

// The objects of every frame from the capture's masks, without poses, as
// `u4d run` makes them from given masks (pipeline/early_stages.cc,
// ComputeInitialObjects): the ground step names the people alike in every
// view, each frame from the previous frame's people or, where the backward
// pass found more, the next frame's (PeopleFromTheNextFrame); then the
// sparse step links them through time.
// What the association needs of a frame: its cameras, images and masks at t
// (not the whole JointFrameData, whose neighbouring frames' images would be
// held for every frame).
struct FrameViews {
  std::vector<Camera> cameras;
  std::vector<cv::Mat> images, masks;
};

std::vector<FrameObjects> AssociateObjects(const Capture& capture, FrameReader* reader,
                                           const RunOptions& run) {
  const std::vector<std::vector<Pose3d>> no_poses(capture.num_frames);
  std::vector<FrameViews> frames;
  for (int f = 0; f < capture.num_frames; ++f) {
    JointFrameData d = ReadJointFrameData(capture, reader, f, no_poses);
    frames.push_back({std::move(d.cameras_t), std::move(d.images_t), std::move(d.masks_t)});
  }
  const bool ground = UsesGroundOccupancy(run.init, capture.NumViews());
  std::vector<std::optional<PeoplePositions>> next(capture.num_frames);
  if (ground)
    next = PeopleFromTheNextFrame(capture.num_frames, [&](int f, PeoplePositions start) {
      GroundPeopleFromDetections(frames[f].cameras, frames[f].masks, run.init, &start);
      return start;
    });
  ObjectLinker linker;
  linker.options = run.link;
  PeoplePositions people;  // the previous frame's, on the ground plane
  std::vector<FrameObjects> objects;
  for (int f = 0; f < capture.num_frames; ++f) {
    const FrameViews& d = frames[f];
    if (next[f]) people = *next[f];
    const std::vector<cv::Mat> masks =
        ground ? GroundPeopleFromDetections(d.cameras, d.masks, run.init, &people) : d.masks;
    objects.push_back(
        ObjectsFromSparse(d.cameras, d.images, masks, run.sparse, run.regions, &linker, ground));
  }
  return objects;
}

// Puts the frame's object masks and depth ranges (and its neighbours' masks)
// into `data`.
void UseObjects(const std::vector<FrameObjects>& objects, int frame, JointFrameData* data) {
  data->masks_t = objects[frame].ids;
  if (frame > 0) data->masks_prev = objects[frame - 1].ids;
  if (frame + 1 < static_cast<int>(objects.size())) data->masks_t1 = objects[frame + 1].ids;
  data->masks_are_object_ids = true;
  data->object_depth_ranges = objects[frame].depth_ranges;
}

using StatsMap = std::map<std::string, Stats>;
using bench::Cell;

const Stats& Get(const StatsMap& stats, const std::string& m) {
  static const Stats none;
  const auto it = stats.find(m);
  return it == stats.end() ? none : it->second;
}

using Cells = std::vector<std::string>;

// A table of a row per method of order: the method and row(its stats), none
// where row returns no cells.
void MethodTable(std::string title, Cells columns, const std::vector<std::string>& order,
                 const StatsMap& stats, const std::function<Cells(const Stats&)>& row,
                 bench::BenchTables* out) {
  bench::Table& t = out->Start(std::move(title), std::move(columns));
  for (const std::string& m : order) {
    Cells cells = row(Get(stats, m));
    if (cells.empty()) continue;
    cells.insert(cells.begin(), m);
    t.Row(std::move(cells));
  }
}

Cells SegCells(const Stats& s) {
  if (!s.has_seg) return {};
  return {Cell("%.3f", s.seg.MeanInstanceIoU()), Cell("%d", s.seg.merged), Cell("%d", s.seg.missed),
          Cell("%d", s.seg.false_positives)};
}

Cells DepthCells(const Stats& s) {
  if (!s.has_depth) return {};
  if (!(s.depth.Completeness() > 0))  // e.g. SGBM on a rig without a close enough pair
    return {"–", "–", "–", "0.000 (no estimate)"};
  return {Cell("%.3f", s.depth.Delta1Pct()), Cell("%.3f", s.depth.Delta5Pct()),
          Cell("%.4f", s.depth.AbsRel()), Cell("%.3f", s.depth.Completeness())};
}

Cells FlowCells(const Stats& s) {
  if (!s.has_flow) return {};
  return {Cell("%.3f", s.flow.Epe()), Cell("%.3f", s.flow.Within1Px()),
          Cell("%.3f", s.flow.Within3Px()), Cell("%.3f", s.flow.Completeness())};
}

void MergeTable(const std::vector<std::string>& order,
                const std::map<std::string, MergeStats>& merge_stats, double match_iou,
                bench::BenchTables* out) {
  bench::Table& t = out->Start(
      Cell("Merged input (view-frames whose detector masks merge >= 2 GT people; initial = after "
           "AssignInstancesToPeople; split = every GT person matched by its own instance with "
           "IoU >= %.2f)",
           match_iou),
      {"method", "view-frames", "split", "mean instance IoU", "merged GT"});
  for (const std::string& m : order) {
    const auto it = merge_stats.find(m);
    if (it == merge_stats.end()) continue;
    const MergeStats& ms = it->second;
    t.Row({m, Cell("%d", ms.view_frames), Cell("%d", ms.split),
           Cell("%.3f", ms.seg.MeanInstanceIoU()), Cell("%d", ms.seg.merged)});
  }
}

void ReconTable(const std::vector<std::string>& order,
                const std::map<std::string, eval::FusedReconstruction>& recon,
                bench::BenchTables* out) {
  bench::Table& t = out->Start(
      "Reconstruction (each method's depth of all views fused per GT person with the GT "
      "masks; projection error |render xor mask| / |mask|; Chamfer to the GT mesh)",
      {"method", "projection error", "Chamfer mm", "people fused", "empty"});
  std::vector<std::string> recon_order = {"gt"};
  recon_order.insert(recon_order.end(), order.begin(), order.end());
  for (const std::string& m : recon_order) {
    const auto it = recon.find(m);
    if (it == recon.end()) continue;
    const eval::FusedReconstruction& r = it->second;
    t.Row({m, Cell("%.3f", r.projection_error.Mean()), Cell("%.1f", r.chamfer_m.Mean() * 1e3),
           Cell("%d", r.objects - r.empty), Cell("%d", r.empty)});
  }
}

// Time per view; initial and zero take none.
void TimeTable(std::vector<std::string> order, const StatsMap& stats, bench::BenchTables* out) {
  const Stats& full = Get(stats, "full");
  const double full_s = full.runs ? full.seconds / full.runs : Nan();
  order.erase(std::remove_if(order.begin(), order.end(),
                             [](const std::string& m) { return m == "initial" || m == "zero"; }),
              order.end());
  MethodTable(
      "Time per view (same run)", {"method", "s / view", "joint (full) / method"}, order, stats,
      [&](const Stats& s) -> Cells {
        if (s.runs == 0) return {};
        const double per = s.seconds / s.runs;
        if (s.has_depth && !(s.depth.Completeness() > 0) && !s.has_flow)
          return {"– (no estimate)", "–"};
        return {Cell("%.3f", per), Cell("%.1f", full_s / per)};
      },
      out);
}

void TraceTable(const std::vector<TraceStats>& trace, bench::BenchTables* out) {
  bench::Table& t = out->Start("Energy trace of the full method (mean over views; E / E_init)",
                               {"step", "block", "E / E_init", "s"});
  for (size_t i = 0; i < trace.size(); ++i)
    t.Row({Cell("%zu", i), trace[i].block, Cell("%.4f", trace[i].sum_ratio / trace[i].count),
           Cell("%.3f", trace[i].sum_seconds / trace[i].count)});
}

}  // namespace

int main(int argc, char** argv) try {
  bench::BenchTables tables("joint_bench", bench::TakeJsonFlag(&argc, argv));
  const Args args = ParseArgs(argc, argv);
  synth::SynthOptions so =
      bench::World(args.preset, args.views, args.width, args.height, args.frames);
  so.start_frame = args.start;
  // GT meshes for the fused reconstruction's Chamfer distance (all views solved).
  so.write_meshes = args.max_views <= 0 || args.max_views >= args.views;
  if (args.force_merge) {
    so.masks.merge_prob = 1;
    if (!args.start_given) so.start_frame = -1;  // centred on the handshake
  }
  Timer gen_timer;
  const fs::path dir = synth::WriteCaptureToTempDir("joint_bench", so);
  std::printf("capture: %s, %d views %dx%d, %d frames from script frame %d (generated in %.1f s)\n",
              args.preset.c_str(), args.views, args.width, args.height, args.frames, so.start_frame,
              gen_timer.Seconds());

  const Capture capture = ReadCapture(dir);
  FrameReader reader(capture);
  // Captured performers have no skeleton: without GT joints the solve has no
  // pose prior, and the objects come from the masks' cross-view association,
  // as `u4d run` makes them without poses (pipeline/initial_objects.h).
  const bool gt_poses = fs::exists(dir / layout::GtJoints3d(0));
  const std::vector<std::vector<Pose3d>> poses =
      gt_poses ? ReadGtPoses3d(capture) : std::vector<std::vector<Pose3d>>(capture.num_frames);
  RunOptions run;
  args.overrides.ApplyTo(&run);
  run.Check();
  std::vector<FrameObjects> objects;
  if (!gt_poses) objects = AssociateObjects(capture, &reader, run);

  std::vector<std::string> methods = {"full"};
  if (args.ablations)
    for (const char* m : {"P_M", "P_P", "P_PM", "P_S", "P_PS"}) methods.push_back(m);
  if (!args.methods.empty()) {
    methods.clear();
    std::string rest = args.methods + ",";
    for (size_t pos; (pos = rest.find(',')) != std::string::npos; rest.erase(0, pos + 1))
      if (pos > 0) methods.push_back(rest.substr(0, pos));
  }

  std::map<std::string, Stats> stats;
  std::map<std::string, MergeStats> merge_stats;
  std::vector<std::string> order = {"detector", "initial", "grabcut", "wta", "sgbm", "zero"};
  for (baselines::FlowBaseline b : baselines::AllFlowBaselines())
    order.push_back(baselines::ToString(b));
  for (const std::string& m : methods) order.push_back(m);
  std::vector<TraceStats> trace;
  int num_depth_labels = 0, num_motion_labels = 0, solved_views = 0;
  const eval::InstanceSegOptions seg_options;
  FrameSetupOptions setup = run.frame_setup;
  setup.pose = run.joint.pose;  // one capsule model, as in the pipeline
  double scale = 0;
  std::map<std::string, eval::FusedReconstruction> recon;

  for (int frame = 1; frame + 1 < capture.num_frames; ++frame) {
    JointFrameData data = ReadJointFrameData(capture, &reader, frame, poses);
    if (!gt_poses) UseObjects(objects, frame, &data);
    std::vector<ViewTruth> truth;
    for (int v = 0; v < capture.NumViews(); ++v) {
      truth.push_back(ReadViewTruth(capture, v, frame));
      data.sparse[v] = SparseMotionsFromTruth(truth.back(), args.sparse, 11 + v + 100 * frame);
    }
    const std::vector<JointViewInput> inputs = MakeJointViewInputs(data, setup, &scale);
    JointViewOptions options = run.joint;
    if (run.paper_weights) options.weights = PaperWeights(capture.scene, capture.NumViews());
    if (!args.weights.empty())
      UpdateFromJson(nlohmann::json::parse(args.weights), "--weights", &options.weights);
    const int nv =
        args.max_views > 0 ? std::min(args.max_views, capture.NumViews()) : capture.NumViews();
    // Each depth method's maps of this frame, per view, for the fused reconstruction.
    std::map<std::string, std::vector<cv::Mat>> frame_depths;
    std::vector<cv::Mat> frame_ids(capture.NumViews());
    for (int v = 0; v < nv; ++v) {
      const JointViewInput& in = inputs[v];
      if (in.objects.empty()) continue;
      ++solved_views;
      const ViewTruth t = ScaleViewTruth(truth[v], in.initial_labels.size(), scale);
      const cv::Mat people = t.instances.ids > 0;
      const std::string ctx = fmt::format("frame {} view {}", frame, v);
      bool merged_input = false;
      std::string merge_line;
      auto add_seg = [&](const std::string& m, const cv::Mat& labels, double seconds) {
        Stats& s = stats[m];
        const eval::InstanceSegResult r =
            eval::EvaluateInstances(PersonInstances(labels), t.instances, seg_options, ctx);
        if (m == "detector") merged_input = r.merged > 0;
        if (merged_input) {
          MergeStats& ms = merge_stats[m];
          int matched = 0;
          for (const eval::InstanceMatch& match : r.matches)
            matched += match.pred_id != 0 && match.iou >= seg_options.match_iou;
          const bool split = r.num_gt >= 2 && matched == r.num_gt;
          ms.seg.Add(r);
          ++ms.view_frames;
          ms.split += split;
          merge_line +=
              fmt::format(" {} {}{:.3f}", m, split ? "split " : "MERGED ", r.mean_instance_iou);
        }
        s.seg.Add(r);
        s.has_seg = true;
        s.seconds += seconds;
        ++s.runs;
        return r.mean_instance_iou;
      };
      auto add_depth = [&](const std::string& m, const cv::Mat& depth) {
        stats[m].depth.Add(eval::EvaluateDepth(depth, t.depth, people, ctx));
        stats[m].has_depth = true;
        frame_depths[m].resize(capture.NumViews());
        frame_depths[m][v] = depth;
      };
      frame_depths["gt"].resize(capture.NumViews());
      frame_depths["gt"][v] = t.depth;
      frame_ids[v] = t.instances.ids;
      auto add_flow = [&](const std::string& m, const cv::Mat& flow) {
        stats[m].flow.Add(eval::EvaluateFlow(flow, t.flow, t.flow_valid, people, ctx));
        stats[m].has_flow = true;
      };

      if (args.force_merge) {  // the detector's own instances, before AssignInstancesToPeople
        cv::Mat detector = data.masks_t[v].empty()
                               ? cv::Mat::zeros(in.initial_labels.size(), CV_16U)
                               : data.masks_t[v];
        if (detector.size() != in.initial_labels.size())
          cv::resize(detector, detector, in.initial_labels.size(), 0, 0, cv::INTER_NEAREST);
        add_seg("detector", detector, 0);
      }
      const double iou_initial = add_seg("initial", in.initial_labels, 0);
      if (!args.dump.empty()) {
        fs::create_directories(args.dump);
        const fs::path base = fs::path(args.dump) / fmt::format("f{}_v{}_", frame, v);
        WriteImage(base.string() + "initial_labels.png", in.initial_labels);
        WriteImage(base.string() + "gt_labels.png", t.instances.ids);
        WritePfm(base.string() + "gt_depth.pfm", t.depth);
        WriteImage(base.string() + "image.png", in.images_t[v]);
        const PosePriorMap pm = RenderPosePrior(in.cameras_t[v], in.cameras_t1[v], in.images_t[v],
                                                in.people, options.pose);
        WriteImage(base.string() + "pose_object.png", pm.object);
        WritePfm(base.string() + "pose_weight.pfm", pm.weight);
        cv::Mat bone_id;
        pm.bone.convertTo(bone_id, CV_16U, 1, 1);  // 0 = none, else bone index + 1
        WriteImage(base.string() + "pose_bone.png", bone_id);
      }
      Timer timer;
      const cv::Mat grabcut = baselines::GrabCutInstances(in.images_t[v], in.initial_labels);
      add_seg("grabcut", grabcut, timer.Seconds());
      if (!args.dump.empty())
        WriteImage(
            (fs::path(args.dump) / fmt::format("f{}_v{}_grabcut_labels.png", frame, v)).string(),
            grabcut);

      cv::Mat full_roi;
      for (const std::string& m : methods) {
        JointViewOptions o = options;
        o.terms = AblationTerms(m);
        const JointViewResult r = SolveJointView(in, o);
        const double iou = add_seg(m, r.labels, r.seconds);
        add_depth(m, r.depth);
        add_flow(m, r.flow);
        if (args.per_view) {
          const eval::DepthMetrics dm = eval::EvaluateDepth(r.depth, t.depth, people, ctx);
          const eval::FlowMetrics fm =
              eval::EvaluateFlow(r.flow, t.flow, t.flow_valid, people, ctx);
          std::printf("per-view frame %d view %d %s: IoU %.4f depth5 %.4f EPE %.4f\n", frame, v,
                      m.c_str(), iou, dm.Delta5Pct(), fm.Epe());
        }
        if (!args.dump.empty()) {
          const fs::path base = fs::path(args.dump) / fmt::format("f{}_v{}_", frame, v);
          WriteImage(base.string() + m + "_labels.png", r.labels);
          WritePfm(base.string() + m + "_depth.pfm", r.depth);
        }
        if (m != "full") continue;
        full_roi = r.roi;
        num_depth_labels += r.num_depth_labels;
        num_motion_labels += r.num_motion_labels;
        const double e0 = r.energy_trace.empty() ? 1 : r.energy_trace.front().energy;
        if (trace.size() < r.energy_trace.size()) trace.resize(r.energy_trace.size());
        for (size_t i = 0; i < r.energy_trace.size(); ++i) {
          trace[i].block = r.energy_trace[i].block;
          trace[i].sum_ratio += r.energy_trace[i].energy / e0;
          trace[i].sum_seconds += r.energy_trace[i].seconds;
          ++trace[i].count;
        }
        std::printf("frame %d view %d: IoU %.3f -> %.3f, %d depth / %d motion labels, %.2f s\n",
                    frame, v, iou_initial, iou, r.num_depth_labels, r.num_motion_labels, r.seconds);
      }

      // WTA plane sweep over the joint method's depth range and roi.
      double near = 1e9, far = 0;
      for (const JointObject& o : in.objects)
        near = std::min(near, o.depth_near), far = std::max(far, o.depth_far);
      timer.Restart();
      const DepthCostVolume volume =
          ComputeDepthCostVolume(in.cameras_t, in.images_t, v, full_roi, near, far, options.depth);
      const cv::Mat wta = WinnerTakeAllDepth(volume, full_roi);
      stats["wta"].seconds += timer.Seconds();
      ++stats["wta"].runs;
      add_depth("wta", wta);
      // OpenCV SGBM on rectified pairs with the 2 nearest views, median-fused
      // (baselines/stereo_baseline.h), searched over the same depth range.
      timer.Restart();
      const cv::Mat sgbm = baselines::SgbmFusedDepth(in.cameras_t, in.images_t, v, near, far);
      stats["sgbm"].seconds += timer.Seconds();
      ++stats["sgbm"].runs;
      add_depth("sgbm", sgbm);

      add_flow("zero", cv::Mat::zeros(t.flow.size(), CV_32FC2));
      for (baselines::FlowBaseline b : baselines::AllFlowBaselines()) {
        timer.Restart();
        const cv::Mat flow = baselines::BaselineFlow(b, in.images_t[v], in.images_t1[v]);
        Stats& s = stats[baselines::ToString(b)];
        s.seconds += timer.Seconds();
        ++s.runs;
        add_flow(baselines::ToString(b), flow);
      }
      if (merged_input)
        std::printf("merged input, frame %d view %d:%s\n", frame, v, merge_line.c_str());
      std::fflush(stdout);
    }
    if (nv == capture.NumViews() && !inputs.empty()) {
      // Fuse every depth method's maps with the GT masks (views without an
      // object to solve have no depth: zeros).
      const std::vector<Camera>& cameras = inputs[0].cameras_t;
      for (int v = 0; v < nv; ++v)
        if (frame_ids[v].empty())
          frame_ids[v] = cv::Mat::zeros(cameras[v].height, cameras[v].width, CV_16UC1);
      std::vector<open3d::geometry::TriangleMesh> gt_meshes;
      std::vector<int> gt_mesh_ids;
      for (int id = 1; fs::exists(dir / layout::GtMesh(id, frame)); ++id) {
        gt_meshes.push_back(eval::ReadMesh(dir / layout::GtMesh(id, frame)));
        gt_mesh_ids.push_back(id);
      }
      std::map<int, const open3d::geometry::TriangleMesh*> gt;
      for (size_t i = 0; i < gt_meshes.size(); ++i) gt[gt_mesh_ids[i]] = &gt_meshes[i];
      for (auto& [m, depths] : frame_depths) {
        for (int v = 0; v < nv; ++v)
          if (depths[v].empty())
            depths[v] = cv::Mat::zeros(cameras[v].height, cameras[v].width, CV_32FC1);
        const eval::FusedReconstruction r =
            eval::EvaluateFusedDepth(cameras, depths, frame_ids, inputs[0].images_t, gt);
        eval::FusedReconstruction& acc = recon[m];
        acc.projection_error.Add(r.projection_error);
        acc.chamfer_m.Add(r.chamfer_m);
        acc.objects += r.objects;
        acc.empty += r.empty;
      }
    }
  }
  U4D_CHECK(solved_views > 0, "joint_bench: no view had an object to solve");
  std::printf(
      "\n%d view-frames solved (frames 1..%d), working scale %.3f, mean %.1f depth / %.1f "
      "motion labels\n",
      solved_views, capture.num_frames - 2, scale,
      static_cast<double>(num_depth_labels) / solved_views,
      static_cast<double>(num_motion_labels) / solved_views);

  MethodTable("Segmentation (GT person instances, instance-weighted mean IoU)",
              {"method", "mean instance IoU", "merged GT", "missed", "false pos."}, order, stats,
              SegCells, &tables);
  if (args.force_merge) MergeTable(order, merge_stats, seg_options.match_iou, &tables);
  MethodTable("Depth (GT person pixels)",
              {"method", "within 1%", "within 5%", "AbsRel", "completeness"}, order, stats,
              DepthCells, &tables);
  if (!recon.empty()) ReconTable(order, recon, &tables);
  MethodTable("Flow (GT-valid person pixels, working resolution)",
              {"method", "EPE px", "within 1 px", "within 3 px", "completeness"}, order, stats,
              FlowCells, &tables);
  TimeTable(order, stats, &tables);
  TraceTable(trace, &tables);
  tables.Write();
  fs::remove_all(dir);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "joint_bench: %s\n", e.what());
  return 1;
}
