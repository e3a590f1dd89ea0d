#include "u4d/pipeline/pipeline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include <fmt/format.h>
#include <open3d/geometry/TriangleMesh.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_group.h>
#include <opencv2/imgproc.hpp>

#include "u4d/eval/evaluate.h"
#include "u4d/eval/scene_consistency.h"
#include "u4d/eval/segment_drift.h"
#include "u4d/fusion/flow_consensus.h"
#include "u4d/fusion/labelled_ply.h"
#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/input_fingerprint.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/label_ids.h"
#include "u4d/io/layout.h"
#include "u4d/io/scene_index.h"
#include "u4d/io/visualize.h"
#include "u4d/joint/parameters.h"
#include "u4d/pipeline/camera_flow.h"
#include "u4d/pipeline/early_stages.h"
#include "u4d/pipeline/initial_objects.h"
#include "u4d/pipeline/mesh_depth.h"
#include "u4d/pipeline/object_classes.h"
#include "u4d/pipeline/run_context.h"
#include "u4d/pipeline/scene_outputs.h"
#include "u4d/pipeline/scene_resume.h"
#include "u4d/util/check.h"
#include "u4d/util/progress.h"
#include "u4d/util/timer.h"

namespace u4d {
namespace {

// An input named explicitly must exist: without it the run would go on with
// no masks or no people and write an empty scene.
MaskSource ResolveMasks(const Capture& cap, MaskSource s) {
  if (s == MaskSource::kGiven) CheckDirExists(cap.root / "masks", "initial masks (--masks given)");
  if (s != MaskSource::kAuto) return s;
  return fs::is_directory(cap.root / "masks") ? MaskSource::kGiven : MaskSource::kUnsupervised;
}

PoseSource ResolvePoses(const Capture& cap, PoseSource s) {
  if (s == PoseSource::kGiven3d)
    CheckDirExists(cap.root / "poses3d", "given 3D poses (--poses given3d)");
  if (s == PoseSource::kFrom2d)
    CheckDirExists(cap.root / "poses2d", "2D keypoints (--poses from2d)");
  if (s != PoseSource::kAuto) return s;
  if (fs::is_directory(cap.root / "poses3d")) return PoseSource::kGiven3d;
  if (fs::is_directory(cap.root / "poses2d")) return PoseSource::kFrom2d;
  return PoseSource::kNone;
}

// Runs `body` (returning its item count) as stage `name` unless an earlier
// run finished it; records time and peak memory, then run.json.
template <typename Body>
void RunStage(RunContext& c, const std::string& name, bool skip_if_done, Body body) {
  if (skip_if_done && c.log.StageDone(name)) {
    fmt::print("[{}] done by an earlier run, skipped\n", name);
    return;
  }
  ResetPeakRss();
  Timer timer;
  const int items = body();
  c.log.AddReport({name, timer.Seconds(), CurrentPeakRssBytes(), items});
  c.log.MarkStage(name);
  WriteRunLog(c.out, c.log);
}

// ---- segments ----

struct Segment {
  int index = 0, keyframe = 0, first = 0, last = 0;  // capture frames
};

std::vector<Segment> Segments(const RunContext& c, const KeyframeSelection& sel) {
  std::vector<Segment> segments(sel.keyframes.size());
  for (size_t s = 0; s < segments.size(); ++s) {
    segments[s].index = static_cast<int>(s);
    segments[s].keyframe = c.f0 + sel.keyframes[s];
    segments[s].first = c.f1;
    segments[s].last = -1;
  }
  for (int k = 0; k < c.NumFrames(); ++k) {
    Segment& s = segments.at(sel.frame_segment[k]);
    s.first = std::min(s.first, c.f0 + k);
    s.last = std::max(s.last, c.f0 + k);
  }
  return segments;
}

// One solved frame at the working resolution.
struct SolvedFrame {
  int frame = -1;
  double scale = 1;                  // working resolution / camera size
  std::vector<Camera> cameras;       // working resolution
  std::vector<cv::Mat> images;       // working resolution, BGR
  std::vector<Camera> full_cameras;  // camera size
  std::vector<cv::Mat> full_images;  // camera size, BGR
  std::vector<cv::Mat> labels, depth, flow;
  // Per view, the solve's initial labels (working resolution) and the
  // initial object ids at camera size; empty where the view was not solved
  // or frame_setup.keep_initial_detail is off (scene_outputs.h ToCameraSize).
  std::vector<cv::Mat> initial, full_initial;
  std::vector<cv::Mat> full_images_t1;  // camera size, BGR; empty: no next frame
  // Per view, the initial object ids of the next frame at camera size; empty
  // where there is none (the run's last frame).
  std::vector<cv::Mat> full_initial_t1;
  std::vector<ViewMaps> maps;  // camera size (FrameMaps), until written
};

// The views' flows on objects from the motion all views see
// (fusion/flow_consensus.h); the cameras have the maps' size.
void ConsensusFlows(const std::vector<Camera>& cameras_t, const std::vector<Camera>& cameras_t1,
                    const std::vector<cv::Mat>& labels, const std::vector<cv::Mat>& depth,
                    const FlowConsensusOptions& options, std::vector<cv::Mat>* flows) {
  std::vector<FlowConsensusView> views(labels.size());
  for (size_t v = 0; v < views.size(); ++v)
    views[v] = {cameras_t[v], cameras_t1[v], labels[v], depth[v], (*flows)[v]};
  *flows = FlowConsensus(views, options);
}

SolvedFrame SolveFrame(RunContext& c, int f, const std::vector<std::vector<Pose3d>>& poses,
                       const std::vector<TemporalTrack>& tracks, const JointViewOptions& joint) {
  const int nv = c.NumViews();
  auto in_run = [&](int g) { return g >= c.f0 && g < c.f1; };
  Timer timer;
  JointFrameData data;
  // Frames f - 1, f, f + 1 in that order (a video is decoded forwards).
  if (c.Continues(f)) {
    data.images_prev = ReadViews(c, f - 1);
    data.masks_prev =
        in_run(f - 1) ? ReadFrameObjects(c.out, c.names, f - 1).ids : std::vector<cv::Mat>(nv);
  }
  data.cameras_t = c.Cameras(f);
  data.images_t = ReadViews(c, f);
  const FrameObjects objects = ReadFrameObjects(c.out, c.names, f);
  data.masks_t = objects.ids;
  if (c.masks == MaskSource::kGiven)  // the detector's scores weigh E_sem
    for (const InstanceMask& m : ReadGivenMasks(c, f)) data.scores_t.push_back(ScoreImage(m));
  if (f + 1 < c.cap.num_frames && c.Continues(f + 1)) {
    data.cameras_t1 = c.Cameras(f + 1);
    data.images_t1 = ReadViews(c, f + 1);
    data.masks_t1 =
        in_run(f + 1) ? ReadFrameObjects(c.out, c.names, f + 1).ids : std::vector<cv::Mat>(nv);
    if (in_run(f + 1)) data.poses_t1 = poses[f + 1 - c.f0];
  }
  data.poses_t = poses[f - c.f0];
  data.masks_are_object_ids = true;
  data.object_depth_ranges = objects.depth_ranges;  // with poses: the objects that are not people
  data.sparse.resize(nv);
  for (int v = 0; v < nv; ++v) data.sparse[v] = SparseMotionsFromTracks(tracks, v, f);

  SolvedFrame solved;
  solved.frame = f;
  double scale = 1;
  std::vector<JointViewInput> inputs;
  // With poses, a frame where nobody was tracked and nothing else found has nothing to reconstruct.
  bool has_objects = c.poses == PoseSource::kNone || !data.poses_t.empty();
  for (const auto& ranges : data.object_depth_ranges) has_objects = has_objects || !ranges.empty();
  if (has_objects) {
    inputs = MakeJointViewInputs(data, c.o.frame_setup, &scale);
  } else {
    scale = std::min(1.0, double(c.o.frame_setup.working_width) / data.cameras_t[0].width);
  }
  solved.labels.resize(nv);
  solved.depth.resize(nv);
  solved.flow.resize(nv);
  solved.initial.resize(nv);
  solved.full_initial.resize(nv);
  for (int v = 0; v < nv; ++v) {
    solved.cameras.push_back(ScaledCamera(data.cameras_t[v], scale));
    cv::Mat img;
    cv::resize(data.images_t[v], img, {solved.cameras[v].width, solved.cameras[v].height}, 0, 0,
               cv::INTER_AREA);
    solved.images.push_back(img);
  }
  c.log.AddSegmentPart("inputs", timer.Seconds());
  timer.Restart();
  tbb::parallel_for(0, nv, [&](int v) {
    const Camera& cam = solved.cameras[v];
    if (has_objects && !inputs[v].objects.empty()) {
      const JointViewResult r = SolveJointView(inputs[v], joint);
      solved.labels[v] = r.labels;
      solved.depth[v] = r.depth;
      solved.flow[v] = r.flow.empty() ? cv::Mat::zeros(cam.height, cam.width, CV_32FC2) : r.flow;
      if (c.o.frame_setup.keep_initial_detail && !data.masks_t[v].empty()) {
        solved.initial[v] = inputs[v].initial_labels;
        solved.full_initial[v] = data.masks_t[v];
      }
    } else {
      solved.labels[v] = cv::Mat::zeros(cam.height, cam.width, CV_16U);
      solved.depth[v] = cv::Mat::zeros(cam.height, cam.width, CV_32F);
      solved.flow[v] = ViewBackgroundFlow(data, v, scale, joint.background_flow);
    }
  });
  c.log.AddSegmentPart("solve", timer.Seconds());
  timer.Restart();
  if (c.o.flow_consensus.enabled && !data.cameras_t1.empty()) {
    std::vector<Camera> cameras_t1;
    for (const Camera& cam : data.cameras_t1) cameras_t1.push_back(ScaledCamera(cam, scale));
    ConsensusFlows(solved.cameras, cameras_t1, solved.labels, solved.depth, c.o.flow_consensus,
                   &solved.flow);
    c.log.AddSegmentPart("flow_consensus", timer.Seconds());
  }
  solved.scale = scale;
  solved.full_cameras = data.cameras_t;
  solved.full_images = data.images_t;
  solved.full_images_t1 = data.images_t1;
  solved.full_initial_t1 = data.masks_t1;
  return solved;
}

// The odd side nearest to `side` (at least 1).
int OddSide(double side) {
  const int k = std::max(1, static_cast<int>(std::lround(side)));
  return k % 2 == 1 ? k : k + 1;
}

// The scene's maps of a solved frame at camera size (ToCameraSize), before
// the flow's camera-size step.
void FrameMaps(const RunContext& c, SolvedFrame& s) {
  s.maps.resize(s.labels.size());
  tbb::parallel_for(size_t{0}, s.labels.size(), [&](size_t v) {
    JointViewResult r;
    r.labels = s.labels[v];
    r.depth = s.depth[v];
    r.flow = s.flow[v];
    const Camera& full = s.full_cameras[v];
    const bool guided = c.o.frame_setup.guided_upsampling;
    s.maps[v] =
        ToCameraSize(r, full.width, full.height, s.scale, s.initial[v], s.full_initial[v],
                     guided ? s.images[v] : cv::Mat(), guided ? s.full_images[v] : cv::Mat());
  });
}

// View v's written camera-size flow of frame s.frame - 1, carried forward to
// s.frame (camera_flow.h CarriedObjectFlow), with
// frame_setup.flow_carried_candidate where that frame is in the run,
// continues into s.frame and has its instances and flow in the scene
// folder; else empty. Read from the folder rather than kept in memory, a
// resumed run carries the same flow as an uninterrupted one. Throws naming
// the files when they are damaged or not the view's size.
cv::Mat CarriedFlow(const RunContext& c, const SolvedFrame& s, int v) {
  const int prev = s.frame - 1;
  if (!c.o.frame_setup.flow_carried_candidate || prev < c.f0 || !c.Continues(s.frame)) return {};
  const fs::path labels = c.out / layout::SceneInstances(c.names[v], prev);
  const fs::path flow = c.out / layout::SceneFlow(c.names[v], prev);
  if (!fs::exists(labels) || !fs::exists(flow)) return {};
  const ViewMaps& maps = s.maps[v];
  const cv::Mat labels_prev = ReadLabelImage(labels), flow_prev = ReadFlo(flow);
  U4D_CHECK(labels_prev.size() == maps.labels.size() && flow_prev.size() == maps.labels.size(),
            "{} and {}: expected {}x{}, the view's size, as the frame before's maps",
            labels.string(), flow.string(), maps.labels.cols, maps.labels.rows);
  return CarriedObjectFlow(labels_prev, flow_prev, maps.labels, maps.flow);
}

// Writes the maps of frame s (FrameMaps) and lets them go. With
// frame_setup.flow_at_camera_size the objects' flow first takes its
// camera-size steps (camera_flow.h: the pick, the median, the
// forward-backward fill, the variational refinement); `labels_t1` are the objects at t+1 per
// view, at camera size, for its object matches (frame_setup.
// flow_object_matches; empty = none). The objects' camera-size flow,
// area-averaged to the working resolution, also replaces s.flow on their
// pixels: the scene flow (WriteFrameOutputs) moves the meshes with the finer
// motion.
void WriteFrameMaps(const RunContext& c, SolvedFrame& s, const std::vector<cv::Mat>& labels_t1) {
  tbb::parallel_for(size_t{0}, s.labels.size(), [&](size_t v) {
    ViewMaps& maps = s.maps[v];
    if (c.o.frame_setup.flow_at_camera_size && !s.full_images_t1.empty()) {
      const bool objects = c.o.frame_setup.flow_object_matches && v < labels_t1.size();
      RefineFlowAtCameraSize(maps.labels, s.full_images[v], s.full_images_t1[v],
                             c.o.frame_setup.flow_window_px, &maps.flow,
                             objects ? labels_t1[v] : cv::Mat(), CarriedFlow(c, s, v));
      if (const int median = c.o.frame_setup.flow_median_px; median > 0)
        MedianFilterObjectFlow(maps.labels, OddSide(median / s.scale), &maps.flow);
      if (const int fill = c.o.frame_setup.flow_fill_radius_px; objects && fill > 0)
        FillInconsistentObjectFlow(maps.labels, labels_t1[v], s.full_images[v], s.full_images_t1[v],
                                   std::max(1, cvRound(fill / s.scale)), &maps.flow);
      if (const int iterations = c.o.frame_setup.flow_variational_iterations;
          objects && iterations > 0)
        RefineObjectFlowVariationally(maps.labels, labels_t1[v], s.full_images[v],
                                      s.full_images_t1[v], iterations, &maps.flow);
      cv::Mat working;
      cv::resize(maps.flow, working, s.flow[v].size(), 0, 0, cv::INTER_AREA);
      working *= s.scale;
      working.copyTo(s.flow[v], s.labels[v] > 0);
    }
    WriteViewMaps(c.out, c.names[v], s.frame, maps, s.full_images[v], c.o.picture_width, c.classes);
  });
  s.maps.clear();
}

// The camera-size labels of a frame's maps, per view.
std::vector<cv::Mat> MapLabels(const SolvedFrame& s) {
  std::vector<cv::Mat> labels;
  for (const ViewMaps& maps : s.maps) labels.push_back(maps.labels);
  return labels;
}

std::set<int> ObjectIds(const SolvedFrame& s) {
  std::set<int> ids;
  for (const cv::Mat& l : s.labels) ids.merge(IdsIn(l));
  return ids;
}

// The depth of frame s's maps (camera size, not yet written) from its fused
// meshes (mesh_depth.h), view by view.
void MeshDepths(SolvedFrame& s, const std::vector<FusedMesh>& fused) {
  std::vector<const open3d::geometry::TriangleMesh*> meshes;  // empty ones are skipped there
  std::vector<int> ids;
  for (const FusedMesh& m : fused) meshes.push_back(m.mesh.get()), ids.push_back(m.object_id);
  tbb::parallel_for(0, static_cast<int>(s.maps.size()), [&](int v) {
    DepthFromMeshes(meshes, ids, s.full_cameras[v], s.maps[v].labels, &s.maps[v].depth);
  });
}

// One mesh per object of frame `current`, each written; at the segment's
// first frame each also starts its object's animation.
std::vector<FusedMesh> FuseFrameObjects(const RunContext& c, const Segment& seg,
                                        const SolvedFrame& current,
                                        std::map<int, AnimatedMesh>& animations) {
  const int f = current.frame;
  std::vector<FusedMesh> meshes;
  for (int id : ObjectIds(current)) {
    const FusedMesh& fused = meshes.emplace_back(
        FuseObject(current.cameras, current.depth, current.labels, current.images, id, c.o.fusion));
    if (fused.Empty()) continue;
    WriteLabelledMesh(c.out / layout::SceneMesh(id, f), *fused.mesh, id,
                      ObjectClass(c.classes, id));
    if (f == seg.first) {
      AnimatedMesh& a = animations[id];
      a.object_id = id;
      a.class_name = ObjectClass(c.classes, id);
      a.first_frame = f;
      a.triangles = fused.mesh->triangles_;
      for (const Eigen::Vector3d& col : fused.mesh->vertex_colors_) a.colors.push_back(col);
      a.positions.push_back(fused.mesh->vertices_);
    }
  }
  return meshes;
}

// Frame f's outputs: the maps of `unwritten` (frame f - 1 when its maps
// wait for f's labels, else null), one mesh per object (FuseFrameObjects)
// and the animations tracked from `previous` (frame f - 1, null at the
// segment's first frame) to it. f's own maps are computed (FrameMaps) and
// wait for frame f + 1. f - 1's maps and f's meshes need nothing of each
// other, so they are made side by side: at a run's end nothing else keeps
// the second core busy. Adds the parts' seconds to `parts`.
void WriteFrameOutputs(const RunContext& c, const Segment& seg, SolvedFrame& current,
                       SolvedFrame* unwritten, const SolvedFrame* previous,
                       std::map<int, AnimatedMesh>& animations, RunLog& parts) {
  Timer timer;
  FrameMaps(c, current);
  parts.AddSegmentPart("maps", timer.Seconds());
  double maps_seconds = 0, fusion_seconds = 0;
  std::vector<FusedMesh> meshes;
  tbb::parallel_invoke(
      [&] {
        const Timer maps_timer;
        if (unwritten) WriteFrameMaps(c, *unwritten, MapLabels(current));
        maps_seconds = maps_timer.Seconds();
      },
      [&] {
        const Timer fusion_timer;
        meshes = FuseFrameObjects(c, seg, current, animations);
        fusion_seconds = fusion_timer.Seconds();
      });
  parts.AddSegmentPart("maps", maps_seconds);
  parts.AddSegmentPart("fusion", fusion_seconds);
  timer.Restart();
  if (c.o.fusion.depth_from_meshes) {
    MeshDepths(current, meshes);
    parts.AddSegmentPart("mesh_depth", timer.Seconds());
    timer.Restart();
  }
  // Scene flow: the segment's meshes from f-1 to f.
  if (previous) {
    std::vector<SceneFlowView> views(c.NumViews());
    for (int v = 0; v < c.NumViews(); ++v)
      views[v] = {previous->cameras[v], current.cameras[v],  previous->depth[v], current.depth[v],
                  previous->flow[v],    previous->labels[v], current.labels[v]};
    for (auto& [id, a] : animations) {
      const TrackResult r =
          TrackVertices(a.positions.back(), a.triangles, views, id, c.o.scene_flow);
      a.positions.push_back(r.positions);
      a.tracked_fraction.push_back(
          r.positions.empty() ? 0.0 : double(r.num_tracked) / r.positions.size());
    }
  }
  parts.AddSegmentPart("scene_flow", timer.Seconds());
}

// A segment's animated meshes (one glTF per object) and its segment.json,
// after its last frame's outputs.
void WriteSegmentAnimation(const RunContext& c, const Segment& seg,
                           const std::map<int, AnimatedMesh>& animations, RunLog& parts) {
  Timer timer;
  const fs::path dir = c.out / layout::SceneSegmentDir(seg.index);
  nlohmann::json objects = nlohmann::json::object();
  for (const auto& [id, a] : animations) {
    if (a.triangles.empty()) continue;
    const std::string glb = fmt::format("{}.glb", id);
    WriteSegmentGlb(dir / glb, a, c.o.gltf);
    objects[std::to_string(id)] = {
        {"glb", glb}, {"vertices", a.NumVertices()}, {"tracked_fraction", a.tracked_fraction}};
  }
  WriteJsonFileAtomic(dir / "segment.json", {{"index", seg.index},
                                             {"keyframe", seg.keyframe},
                                             {"first", seg.first},
                                             {"last", seg.last},
                                             {"objects", objects}});
  parts.AddSegmentPart("animation", timer.Seconds());
}

// Solves the frames of `todo`'s segments one after the other. Each frame's
// outputs (and, after a segment's last frame, its animation) are written by
// a background task while the next frame is solved, across segment borders
// too (the two share the cores: the view solves are parallel, fusion mostly
// is not). A frame's maps wait for the next frame's labels (the flow's
// object matches, WriteFrameMaps), so a segment is reported done
// (`segment_done(seg)`, on the calling thread) once the next frame's task
// has written its last frame's maps; without a next frame (the run's end, a
// gap in `todo`, an error) they take the initial masks of t+1. An error (in
// a solve or in the background) is rethrown after the background task has
// finished, so a segment whose files were all written is still reported
// done.
void RunSegments(RunContext& c, const std::vector<Segment>& todo,
                 const std::vector<std::vector<Pose3d>>& poses,
                 const std::vector<TemporalTrack>& tracks, const JointViewOptions& joint,
                 Progress* progress, const std::function<void(const Segment&)>& segment_done) {
  std::map<int, AnimatedMesh> animations;  // object id -> its mesh moving through the segment
  // frames[0]: the frame whose outputs are being written, frames[1]: the one before it.
  std::array<SolvedFrame, 2> frames;
  RunLog background_parts;  // the background task's part times
  tbb::task_group background;
  bool frame_pending = false;                // a frame's outputs are in the background
  const Segment* last_frame_of = nullptr;    // ... and it is this segment's last
  const Segment* done_after_task = nullptr;  // ... and it writes this segment's last maps
  // A segment whose files are all written but its last frame's maps
  // (frames[0]'s, waiting for the next frame's labels).
  const Segment* waiting = nullptr;
  // Waits for the background task (rethrowing its error: then nothing it
  // worked on is reported), takes its times and reports what it finished.
  auto finish = [&] {
    const bool pending = std::exchange(frame_pending, false);
    const Segment* last = std::exchange(last_frame_of, nullptr);
    const Segment* done = std::exchange(done_after_task, nullptr);
    background.wait();
    for (const PartTime& part : background_parts.segment_parts)
      c.log.AddSegmentPart(part.name, part.seconds);
    background_parts.segment_parts.clear();
    if (pending && progress) progress->Tick();
    if (done) segment_done(*done);
    if (last) waiting = last;
  };
  // frames[0]'s maps without a next frame, and the segment waiting for them.
  auto flush = [&] {
    if (!frames[0].maps.empty()) WriteFrameMaps(c, frames[0], frames[0].full_initial_t1);
    if (const Segment* s = std::exchange(waiting, nullptr)) segment_done(*s);
  };
  try {
    for (const Segment& seg : todo)
      for (int f = seg.first; f <= seg.last; ++f) {
        SolvedFrame current = SolveFrame(c, f, poses, tracks, joint);
        finish();
        if (frames[0].frame != f - 1) flush();
        if (f == seg.first) animations.clear();
        frames[1] = std::move(frames[0]);
        frames[0] = std::move(current);
        SolvedFrame* unwritten = frames[1].maps.empty() ? nullptr : &frames[1];
        const SolvedFrame* previous = f > seg.first ? &frames[1] : nullptr;
        const bool last = f == seg.last;
        frame_pending = true;
        if (unwritten) done_after_task = std::exchange(waiting, nullptr);
        if (last) last_frame_of = &seg;
        background.run([&c, &seg, &frames, unwritten, previous, last, &animations,
                        &background_parts] {
          WriteFrameOutputs(c, seg, frames[0], unwritten, previous, animations, background_parts);
          if (last) WriteSegmentAnimation(c, seg, animations, background_parts);
        });
      }
    finish();
    flush();
  } catch (...) {
    // The first error wins; the background's own, if any, is dropped. A
    // segment that waits only for its last maps still gets them.
    try {
      finish();
      if (waiting) flush();
    } catch (...) {
    }
    throw;
  }
}

// ---- scene.json ----

// The object ids in the instance maps written so far (their sidecars, each
// written atomically; a damaged one is an error naming it).
std::set<int> WrittenInstanceIds(const RunContext& c) {
  std::set<int> ids;
  for (const CaptureView& v : c.cap.views)
    for (int f = c.f0; f < c.f1; ++f) {
      const fs::path json = c.out / layout::SceneInstancesInfo(v.name, f);
      if (!fs::exists(json)) continue;
      for (const InstanceInfo& info : ReadInstanceInfo(json)) ids.insert(info.id);
    }
  return ids;
}

void WriteIndex(const RunContext& c, const KeyframeSelection& sel, const std::vector<Segment>& segs,
                bool has_eval) {
  SceneIndex index;
  index.name = c.cap.name;
  index.fps = c.cap.fps;
  for (int f = c.f0; f < c.f1; ++f) index.frames.push_back(f);
  for (const CaptureView& v : c.cap.views)
    index.views.push_back({v.name, v.cameras.front().width, v.cameras.front().height});
  index.pictures = {"image", "instances", "depth", "flow"};
  std::set<int> ids;
  if (fs::is_directory(c.out / "meshes"))
    for (const auto& e : fs::directory_iterator(c.out / "meshes"))
      if (const auto id = ParseIndexName(e.path().filename().string()); e.is_directory() && id)
        ids.insert(*id);  // stray entries (meshes/abc) are not objects
  index.has_meshes = !ids.empty();
  ids.merge(WrittenInstanceIds(c));  // an object may have pixels and no mesh
  for (int id : ids) {
    const cv::Vec3b col = InstanceColor(id);
    index.objects.push_back({id, ObjectClass(c.classes, id), {col[0], col[1], col[2]}});
  }
  for (size_t s = 0; s < sel.keyframes.size(); ++s) {
    SceneKeyframeInfo kf{c.f0 + sel.keyframes[s], {}};
    for (int k = 0; k < c.NumFrames(); ++k)
      if (sel.frame_keyframe[k] == sel.keyframes[s]) kf.members.push_back(c.f0 + k);
    index.keyframes.push_back(kf);
  }
  for (const Segment& seg : segs) {
    if (!c.log.segments_done.count(seg.index)) continue;
    SceneSegmentInfo info{
        seg.index, seg.keyframe, seg.first, seg.last, layout::SceneSegmentDir(seg.index).string(),
        {}};
    for (int id : ids) {
      const fs::path glb = layout::SceneSegmentDir(seg.index) / fmt::format("{}.glb", id);
      if (fs::exists(c.out / glb)) info.glb[id] = glb.string();
    }
    index.segments.push_back(info);
  }
  index.has_poses3d = c.poses != PoseSource::kNone;
  index.has_tracks = c.log.StageDone("tracks");
  index.has_eval = has_eval;
  index.stages_done = c.log.stages_done;
  WriteSceneIndex(c.out, index);
}

}  // namespace

RunResult RunPipeline(const fs::path& capture_dir, const fs::path& scene_dir,
                      const RunOptions& options) {
  options.Check();
  const Capture cap = ReadCapture(capture_dir);
  const int f1 = options.num_frames < 0
                     ? cap.num_frames
                     : std::min(cap.num_frames, options.first_frame + options.num_frames);
  U4D_CHECK(options.first_frame < cap.num_frames,
            "first frame {} is beyond the capture's {} frames", options.first_frame,
            cap.num_frames);
  // One capsule model: the regions and the split of merged instances use the
  // pose term's (joint.pose; frame_setup.pose is not an option of its own).
  RunOptions resolved = options;
  resolved.frame_setup.pose = options.joint.pose;
  RunContext c{cap, scene_dir, resolved, options.first_frame, f1, {},
               {},  {},        {},       FrameReader(cap),    {}};
  for (const CaptureView& v : cap.views) c.names.push_back(v.name);
  c.masks = ResolveMasks(cap, options.masks);
  c.poses = ResolvePoses(cap, options.poses);
  std::unique_ptr<tbb::global_control> threads;
  if (options.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    options.threads);

  nlohmann::json params = options.ToJson();
  params["capture"] = fs::absolute(cap.root).lexically_normal().string();
  params["masks_used"] = ToString(c.masks);
  params["poses_used"] = ToString(c.poses);
  const InputFingerprint inputs = FingerprintCapture(cap);
  bool resume = options.resume;
  if (resume) {
    const std::string change = ResumeChange(scene_dir, params, inputs);
    if (!change.empty())
      fmt::print("u4d run: {} holds a run of {}: recomputing the whole scene\n", scene_dir.string(),
                 change);
    resume = change.empty();
  }
  if (resume)
    RemoveInterruptedWrites(scene_dir);
  else
    RemoveSceneOutputs(scene_dir);
  fs::create_directories(scene_dir);
  if (resume && fs::exists(scene_dir / layout::SceneRunLog())) c.log = ReadRunLog(scene_dir);
  c.log.capture = params["capture"];
  c.log.masks = ToString(c.masks);
  c.log.poses = ToString(c.poses);
  c.log.stages.clear();
  c.log.segment_parts.clear();
  if (!resume) c.log.stages_done.clear(), c.log.segments_done.clear();
  // inputs.json first: a scene with params.json always has it.
  WriteJsonFileAtomic(scene_dir / layout::SceneInputs(), FingerprintToJson(inputs));
  WriteJsonFileAtomic(scene_dir / layout::SceneParams(), params);
  WriteJsonFileAtomic(scene_dir / layout::SceneCalibration(), CalibrationToJson(cap));
  fmt::print("u4d run: {} frames [{}, {}) of {} views; masks: {}; poses: {}\n", c.NumFrames(), c.f0,
             c.f1, c.NumViews(), ToString(c.masks), ToString(c.poses));

  std::vector<std::vector<Pose3d>> poses(c.NumFrames());
  const bool poses_done = c.log.StageDone("poses");
  RunStage(c, "poses", true, [&] {
    poses = ComputePoses(c);
    return c.NumFrames();
  });
  if (poses_done) poses = ReadScenePoses(c);
  RunStage(c, "initial", true, [&] { return ComputeInitialObjects(c, poses); });
  CheckNotEmpty(c);
  c.classes = ReadRunObjectClasses(c.out, c.f0, c.f1);
  std::vector<TemporalTrack> tracks;
  const bool tracks_done = c.log.StageDone("tracks");
  RunStage(c, "tracks", true, [&] {
    tracks = ComputeTracks(c, poses);
    return c.NumFrames() * c.NumViews();
  });
  if (tracks_done) tracks = ReadSceneTracks(c);
  KeyframeSelection selection;
  const bool keyframes_done = c.log.StageDone("keyframes");
  RunStage(c, "keyframes", true, [&] {
    selection = ComputeKeyframes(c, poses, tracks);
    return c.NumFrames();
  });
  if (keyframes_done) selection = ReadKeyframes(scene_dir / layout::SceneKeyframes());
  U4D_CHECK(static_cast<int>(selection.frame_segment.size()) == c.NumFrames(),
            "{}: the key-frames cover {} frames, the run {}",
            (scene_dir / layout::SceneKeyframes()).string(), selection.frame_segment.size(),
            c.NumFrames());
  const std::vector<Segment> segments = Segments(c, selection);

  JointViewOptions joint = options.joint;
  if (options.paper_weights) joint.weights = PaperWeights(cap.scene, c.NumViews());
  if (c.poses == PoseSource::kNone) joint.terms.pose = false;

  RunResult result;
  int frames_to_solve = 0;
  for (const Segment& s : segments)
    if (!c.log.segments_done.count(s.index)) frames_to_solve += s.last - s.first + 1;
  RunStage(c, "segments", false, [&] {
    Progress progress("segments (frames)", frames_to_solve, options.progress);
    std::vector<Segment> todo;
    for (const Segment& s : segments) {
      if (c.log.segments_done.count(s.index)) {
        ++result.segments_skipped;
        continue;
      }
      todo.push_back(s);
    }
    int solved = 0;
    RunSegments(c, todo, poses, tracks, joint, &progress, [&](const Segment& s) {
      c.log.segments_done.insert(s.index);
      WriteRunLog(c.out, c.log);
      WriteIndex(c, selection, segments, false);
      solved += s.last - s.first + 1;
    });
    return solved;
  });

  // The index must list the segments before the figures below read it.
  WriteIndex(c, selection, segments, false);
  if (options.evaluate) {
    RunStage(c, "consistency", false, [&] {
      const eval::ConsistencyReport report = eval::EvaluateSceneConsistency(cap, scene_dir);
      WriteJsonFileAtomic(scene_dir / layout::SceneConsistency(), report.ToJson());
      fmt::print("{}", report.FormatTable());
      return c.NumFrames();
    });
  }
  const bool whole = c.f0 == 0 && c.f1 == cap.num_frames;
  if (options.evaluate && fs::is_directory(cap.root / "gt") && whole) {
    RunStage(c, "eval", false, [&] {
      const eval::EvalReport report = eval::EvaluateCapture({cap.root, scene_dir, false});
      nlohmann::json j = report.ToJson();
      if (fs::is_directory(cap.root / "gt/meshes")) {
        const eval::DriftReport drift = eval::EvaluateSegmentDrift(cap.root, scene_dir);
        j["vertex_drift"] = drift.ToJson();
        fmt::print(
            "vertex drift at the segments' last frames: {:.1f} mm (a static mesh: {:.1f} mm)\n",
            drift.last_frame_drift.Mean() * 1e3, drift.last_frame_motion.Mean() * 1e3);
      }
      WriteJsonFileAtomic(scene_dir / layout::SceneEval(), j);
      fmt::print("{}", report.FormatTable());
      return 1;
    });
    result.evaluated = true;
  }
  WriteIndex(c, selection, segments, result.evaluated);

  result.log = c.log;
  result.frames = c.NumFrames();
  result.views = c.NumViews();
  result.objects = static_cast<int>(ReadSceneIndex(scene_dir).objects.size());
  result.keyframes = static_cast<int>(selection.keyframes.size());
  result.segments = static_cast<int>(segments.size());
  result.empty_frames = c.log.empty_frames;
  return result;
}

}  // namespace u4d
