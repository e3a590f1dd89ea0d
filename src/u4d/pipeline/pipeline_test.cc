// `u4d run` end to end on a small synthetic handshake with ground truth:
// the refined scene must beat the initial masks it started from, the meshes
// must lie on the true surfaces, and interruptions, corrupt frames and
// mismatched options must be handled as pipeline.h promises.
#include "u4d/pipeline/pipeline.h"
#include "u4d/pipeline/initial_objects.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "u4d/eval/baseline_overlap.h"
#include "u4d/eval/evaluate.h"
#include "u4d/features/temporal_tracks.h"
#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/scene_index.h"
#include "u4d/joint/parameters.h"
#include "u4d/keyframes/keyframe_similarity.h"
#include "u4d/synth/generate.h"
#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/file.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

// 4 views at 320x180, 3 frames around the handshake's approach, with GT
// meshes; one optimisation round to keep the test short.
fs::path SmallCapture() {
  synth::SynthOptions o = synth::SmallHandshakeOptions(4, 320, 180, 3);
  o.write_meshes = true;
  return test_util::RemovedAtExit(synth::WriteCaptureToTempDir("pipeline", o));
}

RunOptions FastOptions() {
  RunOptions o;
  o.joint.rounds = 1;
  o.progress = false;
  o.picture_width = 160;
  return o;
}

TEST(PipelineTest, RunsEndToEndAndBeatsTheInitialMasks) {
  const fs::path capture = SmallCapture();
  const fs::path scene = test_util::FreshTestDir("pipeline", "scene");
  const RunResult run = RunPipeline(capture, scene, FastOptions());

  // The synthetic capture ships masks and 2D keypoints, so those are used.
  EXPECT_EQ(run.log.masks, "given");
  EXPECT_EQ(run.log.poses, "from2d");
  EXPECT_EQ(run.frames, 3);
  EXPECT_GE(run.objects, 2);  // both people reconstructed
  ASSERT_TRUE(run.evaluated);
  for (const char* stage :
       {"poses", "initial", "tracks", "keyframes", "segments", "consistency", "eval"})
    EXPECT_TRUE(run.log.StageDone(stage)) << stage;

  // Against ground truth: the joint optimisation must improve on the
  // detector-like masks it started from (paper: +20-40% over Mask R-CNN; we
  // ask for a clear +0.05 of mean instance IoU), depth on people must be
  // mostly within 5% (the reconstruction is multi-view), and the fused
  // meshes must lie on the true surfaces within a limb's radius (6 cm, the
  // capsule model's), the least a per-person mesh must achieve to show the
  // person's shape (the run prints the values).
  const eval::EvalReport initial = eval::EvaluateCapture({capture, {}, true});
  const eval::EvalReport ours = eval::EvaluateCapture({capture, scene, false});
  ASSERT_TRUE(initial.instances && ours.instances && ours.depth_people && ours.meshes);
  const double iou0 = initial.instances->MeanInstanceIoU();
  const double iou = ours.instances->MeanInstanceIoU();
  std::printf(
      "[pipeline] mean instance IoU initial %.3f -> ours %.3f; depth on people within "
      "1%% %.3f, 5%% %.3f; flow EPE on people %.3f px; mesh Chamfer %.1f mm (%d of %d GT "
      "meshes matched); S_e %.3f\n",
      iou0, iou, ours.depth_people->Delta1Pct(), ours.depth_people->Delta5Pct(),
      ours.flow_people ? ours.flow_people->Epe() : -1.0, 1000 * ours.meshes->chamfer.Mean(),
      ours.meshes->matched, ours.meshes->gt_meshes,
      ours.silhouette_overlap_error ? ours.silhouette_overlap_error->Mean() : -1.0);
  EXPECT_GT(iou, iou0 + 0.05);
  EXPECT_GT(ours.depth_people->Delta5Pct(), 0.8);
  EXPECT_EQ(ours.meshes->matched, ours.meshes->gt_meshes);
  EXPECT_LT(ours.meshes->chamfer.Mean(), 0.06);
  // S_e: the GT key-frame masks carried by our flow must lose or gain less
  // than a tenth of each mask over a segment, what the true flow achieves
  // over three frames of a walk (eval_scene_test, 0.092); these frames are
  // nearly still, so this is the least to ask.
  ASSERT_TRUE(ours.silhouette_overlap_error);
  EXPECT_LT(ours.silhouette_overlap_error->Mean(), 0.1);

  // Figures without ground truth: the per-view depths are within 5 % of the
  // truth almost everywhere (asserted above), so most person points seen by
  // another view must agree with its depth (2 % tolerance), and since object
  // ids are the same in every view, nearly all agreeing points must carry
  // the same id (only segmentation errors at the boundaries disagree).
  const nlohmann::json consistency = ReadJsonFile(scene / layout::SceneConsistency());
  EXPECT_GT(consistency["cross_view"]["depth_agreement"].get<double>(), 0.8);
  EXPECT_GT(consistency["cross_view"]["label_agreement"].get<double>(), 0.9);
  // Vertex drift against the GT vertex identities: every multi-frame
  // segment is measured on most of its vertices, and each tracking step may
  // add at most a pixel's footprint (~16 mm at 320x180 and 4 m; the flow is
  // asked for sub-pixel accuracy). The people barely move in these frames,
  // so a static mesh would drift less (the run prints both).
  const nlohmann::json drift = ReadJsonFile(scene / layout::SceneEval())["vertex_drift"];
  ASSERT_GE(drift["segments_measured"].get<int>(), 1);
  for (const auto& seg : drift["segments"])
    EXPECT_GT(seg["followed"].get<double>(), 0.5 * seg["vertices"].get<double>());
  for (const auto& at : drift["by_frame_offset"])
    EXPECT_LT(at["drift_m"].get<double>(), 0.016 * at["frames_after_first"].get<int>());
  std::printf(
      "[pipeline] cross-view depth agreement %.3f, label agreement %.3f; drift at the "
      "segments' last frame %.1f mm (a static mesh %.1f mm)\n",
      consistency["cross_view"]["depth_agreement"].get<double>(),
      consistency["cross_view"]["label_agreement"].get<double>(),
      1e3 * drift["last_frame_drift_m"].get<double>(),
      1e3 * drift["last_frame_motion_m"].get<double>());

  // The scene index lists what was written, with one glb per object and
  // segment.
  const SceneIndex index = ReadSceneIndex(scene);
  EXPECT_EQ(index.frames.size(), 3u);
  ASSERT_EQ(static_cast<int>(index.segments.size()), run.segments);
  for (const SceneSegmentInfo& s : index.segments) {
    EXPECT_FALSE(s.glb.empty());
    for (const auto& [id, glb] : s.glb) EXPECT_TRUE(fs::exists(scene / glb)) << glb;
  }
}

// S_e of the scene's flow (`ours`, EvaluateCapture's) against that of the
// OpenCV flows on the capture's images and of the true flow, alike
// (GtSilhouetteOverlap's protocol for all).
void ExpectFlowCarriesTheMasksAsTheTruthDoes(const fs::path& capture_dir,
                                             const eval::EvalReport& ours) {
  ASSERT_TRUE(ours.silhouette_overlap_error);
  const Capture capture = ReadCapture(capture_dir);
  const eval::EvalOptions options;
  const eval::RatioMean truth = eval::GtSilhouetteOverlap(
      capture,
      [&](int v, int f) {
        const fs::path flo = capture_dir / layout::GtFlow(capture.views[v].name, f);
        return fs::exists(flo) ? ReadFlo(flo) : cv::Mat();
      },
      options);
  const auto baselines =
      eval::BaselineSilhouetteOverlap(capture, baselines::AllFlowBaselines(), options);
  const double se = ours.silhouette_overlap_error->Mean();
  std::printf("[pipeline realistic] S_e ours %.4f, true flow %.4f", se, truth.Mean());
  for (const auto& [name, r] : baselines) std::printf(", %s %.4f", name.c_str(), r.Mean());
  std::printf("\n");
  ASSERT_EQ(baselines.size(), 3u);
  for (const auto& [name, r] : baselines) EXPECT_LT(se, r.Mean()) << name;
  EXPECT_LT(std::abs(se - truth.Mean()), 0.03);
}

// The realistic world (docs/synthetic.md), which nothing was tuned on: two
// captured performers who touch, a detector's failures, no 2D keypoints. The
// run must work from the masks alone, refine them (class and instance IoU
// against GT above the detector's) and mesh every visible person at every
// frame, with one id per person in every view and frame (eval.json
// "identity"). Its flow must carry the GT masks through the frames
// (S_e, docs/metrics.md) better than OpenCV's DIS, DeepFlow and Farneback
// on the same images, and within 0.03 of what the true flow does (issue 23;
// the true flow's S_e is not 0: the pixels that become hidden count).
TEST(PipelineTest, RealisticWorldFromTheDetectorsMasksAlone) {
  const fs::path data = DataDir() / "captured_meshes";
  U4D_SKIP_WITHOUT_SHARED_DATA(data);
  synth::SynthOptions o = synth::SmallRealisticOptions(data, 480, 270, 3);
  o.rig.num_views = 4;
  o.write_meshes = true;
  o.seed = 11;  // not among the seeds the detector model was tuned on
  const fs::path capture =
      test_util::RemovedAtExit(synth::WriteCaptureToTempDir("pipeline_realistic", o));
  const fs::path scene = test_util::FreshTestDir("pipeline", "realistic_scene");
  const RunResult run = RunPipeline(capture, scene, FastOptions());
  EXPECT_EQ(run.log.masks, "given");
  EXPECT_EQ(run.log.poses, "none");
  ASSERT_TRUE(run.evaluated);

  const eval::EvalReport initial = eval::EvaluateCapture({capture, {}, true});
  const eval::EvalReport ours = eval::EvaluateCapture({capture, scene, false});
  ASSERT_TRUE(initial.instances && ours.instances && ours.identity);
  const eval::IdentitySummary id = ours.identity->Summarize();
  std::printf(
      "[pipeline realistic] instance IoU %.3f -> %.3f, class IoU %.3f -> %.3f; %d objects, "
      "%.2f ids per person, %d switches, %d cross-view; %d of %d frames without a mesh\n",
      initial.instances->MeanInstanceIoU(), ours.instances->MeanInstanceIoU(),
      initial.instances->MeanClassIoU(), ours.instances->MeanClassIoU(), run.objects,
      id.mean_ids_per_person, id.switches, id.cross_view_disagreements, id.no_mesh_frames,
      id.visible_frames);
  EXPECT_GT(ours.instances->MeanClassIoU(), initial.instances->MeanClassIoU());
  EXPECT_GT(ours.instances->MeanInstanceIoU(), initial.instances->MeanInstanceIoU());
  EXPECT_EQ(id.matched_people, 2);
  // One identity per person across views and time (issue 22): the detector
  // numbers instances per image; the ground-plane step names them.
  EXPECT_EQ(id.mean_ids_per_person, 1.0);
  EXPECT_EQ(id.switches, 0);
  EXPECT_EQ(id.cross_view_disagreements, 0);
  ASSERT_TRUE(id.with_meshes);
  EXPECT_EQ(id.no_mesh_frames, 0);
  ExpectFlowCarriesTheMasksAsTheTruthDoes(capture, ours);
  fs::remove_all(capture);
}

// Without poses the objects come from the cross-view association of the
// masks (feature and silhouette points); the ids must be consistent across
// views and the initial objects must survive a write/read round trip.
TEST(PipelineTest, ObjectsWithoutPosesAreAssociatedAcrossViews) {
  const fs::path capture_dir = SmallCapture();
  const Capture capture = ReadCapture(capture_dir);
  FrameReader reader(capture);
  std::vector<Camera> cameras;
  std::vector<cv::Mat> images, masks, truth;
  std::vector<std::string> names;
  for (int v = 0; v < capture.NumViews(); ++v) {
    const std::string& name = capture.views[v].name;
    names.push_back(name);
    cameras.push_back(capture.views[v].CameraAt(1));
    images.push_back(reader.Read(v, 1));
    masks.push_back(ReadLabelImage(capture_dir / layout::Mask(name, 1)));
    truth.push_back(ReadLabelImage(capture_dir / layout::GtInstances(name, 1)));
  }
  ObjectLinker linker;
  const FrameObjects objects = ObjectsFromSparse(cameras, images, masks, SparseFrameOptions{},
                                                 ObjectRegionOptions{}, &linker);
  // In the views where the detector separated the two people, every object
  // id must cover one GT person (majority of its pixels), the same person in
  // all those views: a wrong association would pair different people across
  // views. (Where the detector merged them, the merged instance is one
  // object; the joint optimisation splits it later.)
  std::map<int, std::set<int>> person_of;  // object -> GT persons it covers (by majority)
  int separated_views = 0;
  for (int v = 0; v < capture.NumViews(); ++v) {
    double max_id = 0;
    cv::minMaxLoc(masks[v], nullptr, &max_id);
    if (max_id < 2) continue;
    ++separated_views;
    std::map<int, std::map<int, int>> counts;
    for (int y = 0; y < truth[v].rows; ++y)
      for (int x = 0; x < truth[v].cols; ++x)
        if (const int o = objects.ids[v].at<uint16_t>(y, x))
          ++counts[o][truth[v].at<uint16_t>(y, x)];
    for (const auto& [o, by_gt] : counts) {
      const auto best = std::max_element(by_gt.begin(), by_gt.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
      person_of[o].insert(best->first);
    }
  }
  ASSERT_GE(separated_views, 2);
  EXPECT_EQ(person_of.size(), 2u);  // two people
  for (const auto& [o, people] : person_of) {
    EXPECT_EQ(people.size(), 1u) << "object " << o;
    EXPECT_NE(*people.begin(), 0) << "object " << o << " is mostly background";
  }
  for (int v = 0; v < capture.NumViews(); ++v)
    for (const auto& [id, range] : objects.depth_ranges[v]) {
      // The people stand 2-5 m from the cameras of the small rig.
      EXPECT_GT(range.first, 0.5) << names[v];
      EXPECT_LT(range.second, 8.0) << names[v];
    }

  const fs::path out = test_util::FreshTestDir("pipeline", "objects");
  WriteFrameObjects(out, names, 1, objects);
  const FrameObjects back = ReadFrameObjects(out, names, 1);
  ASSERT_EQ(back.ids.size(), objects.ids.size());
  for (size_t v = 0; v < names.size(); ++v) {
    EXPECT_EQ(cv::countNonZero(back.ids[v] != objects.ids[v]), 0);
    EXPECT_EQ(back.depth_ranges[v], objects.depth_ranges[v]);
  }
  EXPECT_EQ(back.centroids.size(), objects.centroids.size());
}

// Masks whose ids are already alike across views (init.h's step 6; here
// the GT instances, ids 1 and 2): each id is one object in every view, its
// pixels unchanged where the object has a depth range, and each object has a
// centroid between the cameras.
TEST(PipelineTest, ObjectsKeepIdsAlikeAcrossViews) {
  const fs::path capture_dir = SmallCapture();
  const Capture capture = ReadCapture(capture_dir);
  FrameReader reader(capture);
  std::vector<Camera> cameras;
  std::vector<cv::Mat> images, truth;
  for (int v = 0; v < capture.NumViews(); ++v) {
    cameras.push_back(capture.views[v].CameraAt(1));
    images.push_back(reader.Read(v, 1));
    truth.push_back(ReadLabelImage(capture_dir / layout::GtInstances(capture.views[v].name, 1)));
  }
  ObjectLinker linker;
  const FrameObjects objects = ObjectsFromSparse(cameras, images, truth, SparseFrameOptions{},
                                                 ObjectRegionOptions{}, &linker, true);
  ASSERT_EQ(objects.centroids.size(), 2u);
  // The linker numbers the first frame's objects 1, 2 in the order of the
  // mask ids: object k is GT person k.
  int ranged = 0;
  for (int v = 0; v < capture.NumViews(); ++v)
    for (const int id : {1, 2}) {
      if (!objects.depth_ranges[v].count(id)) continue;
      ++ranged;
      EXPECT_EQ(cv::countNonZero((objects.ids[v] == id) != (truth[v] == id)), 0)
          << "view " << v << " id " << id;
    }
  EXPECT_GE(ranged, capture.NumViews());  // both people have depth ranges in most views
}

TEST(PipelineTest, ResumesAndRecoversFromAnInterruption) {
  const fs::path capture = SmallCapture();
  const fs::path scene = test_util::FreshTestDir("pipeline", "resume");
  RunOptions options = FastOptions();
  options.frame_setup.working_width = 96;  // the bookkeeping is under test, not the quality
  options.poses = PoseSource::kNone;       // and the path without poses runs end to end
  options.evaluate = false;
  const RunResult first = RunPipeline(capture, scene, options);
  ASSERT_GE(first.segments, 1);
  // run.json splits the segments stage into its parts, each timed.
  std::vector<std::string> part_names;
  for (const PartTime& part : ReadRunLog(scene).segment_parts) {
    part_names.push_back(part.name);
    EXPECT_GE(part.seconds, 0.0) << part.name;
    if (part.name == "solve") {
      EXPECT_GT(part.seconds, 0.0);
    }
  }
  EXPECT_EQ(part_names,
            (std::vector<std::string>{"inputs", "solve", "flow_consensus", "maps", "fusion",
                                      "mesh_depth", "scene_flow", "animation"}));

  // A second run finds everything done and recomputes nothing.
  const RunResult again = RunPipeline(capture, scene, options);
  EXPECT_EQ(again.segments_skipped, again.segments);
  for (const StageReport& s : again.log.stages) EXPECT_NE(s.name, "initial");
  EXPECT_TRUE(again.log.segment_parts.empty());  // no segment was solved again

  // An interruption inside the last segment leaves it unrecorded (run.json
  // is written after a segment's files); the resumed run redoes that one only,
  // and its flow is the uninterrupted run's (the pick's carried candidate
  // reads the frame before's flow back from the scene folder).
  std::map<std::string, std::string> flows;
  for (const auto& e : fs::recursive_directory_iterator(scene / "flow"))
    if (e.is_regular_file()) flows[e.path().string()] = ReadTextFile(e.path());
  ASSERT_FALSE(flows.empty());
  const SceneIndex index = ReadSceneIndex(scene);
  ASSERT_FALSE(index.segments.empty());
  RunLog log = ReadRunLog(scene);
  log.segments_done.erase(index.segments.back().index);
  WriteRunLog(scene, log);
  const fs::path segment_json = scene / index.segments.back().dir / "segment.json";
  ASSERT_TRUE(fs::exists(segment_json));
  fs::remove(segment_json);
  const RunResult resumed = RunPipeline(capture, scene, options);
  EXPECT_EQ(resumed.segments_skipped, resumed.segments - 1);
  EXPECT_TRUE(fs::exists(segment_json));
  EXPECT_EQ(ReadRunLog(scene).segments_done.size(), static_cast<size_t>(resumed.segments));
  for (const auto& [path, bytes] : flows) EXPECT_TRUE(ReadTextFile(path) == bytes) << path;
}

// Frames 0-1 and frame 2 of a capture lie 100 s apart in the source
// (capture.json's source_frames, as imported from a long recording's
// instants): nothing temporal crosses the cut. Frame 2 starts its own
// segment, no track joins it to frame 1, frame 1 has no flow (there is no
// next frame to move to). Identity does cross it, by the people's colours:
// each person of frame 2 takes back its id of frame 1 (against the GT).
TEST(PipelineTest, NothingTemporalCrossesACutInTime) {
  const fs::path capture = SmallCapture();
  nlohmann::json manifest = ReadJsonFile(capture / "capture.json");
  const auto seconds_100_later = static_cast<int64_t>(100 * manifest["fps"].get<double>());
  manifest["source_frames"] = {0, 1, seconds_100_later};
  WriteJsonFileAtomic(capture / "capture.json", manifest);
  const fs::path scene = test_util::FreshTestDir("pipeline", "cut");
  RunOptions options = FastOptions();
  options.frame_setup.working_width = 96;
  options.poses = PoseSource::kNone;
  options.evaluate = false;
  RunPipeline(capture, scene, options);

  const KeyframeSelection sel = ReadKeyframes(scene / layout::SceneKeyframes());
  EXPECT_NE(sel.frame_segment[2], sel.frame_segment[1]);
  const Capture cap = ReadCapture(capture);
  // The refined id most of GT person `person`'s pixels take in a view.
  auto id_of = [&](const std::string& view, int frame, int person) {
    const cv::Mat gt = ReadLabelImage(capture / layout::GtInstances(view, frame));
    const cv::Mat ids = ReadLabelImage(scene / layout::SceneInstances(view, frame));
    std::map<int, int> votes;
    for (int y = 0; y < gt.rows; ++y)
      for (int x = 0; x < gt.cols; ++x)
        if (gt.at<uint16_t>(y, x) == person && ids.at<uint16_t>(y, x))
          ++votes[ids.at<uint16_t>(y, x)];
    int id = 0, most = 0;
    for (const auto& [k, n] : votes)
      if (n > most) id = k, most = n;
    return id;
  };
  int seen_across = 0;
  for (int v = 0; v < cap.NumViews(); ++v) {
    const std::string& name = cap.views[v].name;
    for (const TemporalTrack& t : ReadTemporalTracks(scene / layout::SceneTracks(name), v))
      EXPECT_EQ(t.points.front().first <= 1, t.points.back().first <= 1) << name;
    EXPECT_EQ(cv::norm(ReadFlo(scene / layout::SceneFlow(name, 1))), 0.0) << name;
    for (int person : {1, 2}) {
      const int before = id_of(name, 1, person), after = id_of(name, 2, person);
      if (before == 0 || after == 0) continue;  // not seen in this view
      EXPECT_EQ(after, before) << name << " GT person " << person;
      ++seen_across;
    }
  }
  EXPECT_GE(seen_across, cap.NumViews());  // most people seen on both sides
}

// A frame's outputs are written in the background while the next frame is
// solved: an error there (here `meshes` is a file, so no mesh can be
// written) still fails the run, naming the path, and the segment is not
// recorded as done.
TEST(PipelineTest, AnErrorWritingOutputsInTheBackgroundFailsTheRun) {
  const fs::path capture = SmallCapture();
  const fs::path scene = test_util::FreshTestDir("pipeline", "background_error");
  fs::create_directories(scene);
  WriteTextFileAtomic(scene / "meshes", "not a folder\n");
  RunOptions options = FastOptions();
  options.frame_setup.working_width = 96;
  options.evaluate = false;
  try {
    RunPipeline(capture, scene, options);
    FAIL() << "writing a mesh under a file must throw";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("meshes"), std::string::npos) << e.what();
  }
  const RunLog log = ReadRunLog(scene);
  EXPECT_TRUE(log.StageDone("tracks"));
  EXPECT_TRUE(log.segments_done.empty());
}

// The pick's carried candidate reads the frame before's flow back from the
// scene folder (frame_setup.flow_carried_candidate). A resumed segment that
// finds that file damaged (here: another size than the view's) stops with
// an error naming it, and the finished segments' files stay.
TEST(PipelineTest, ADamagedFlowOfTheFrameBeforeIsAnErrorNamingIt) {
  const fs::path capture = SmallCapture();
  const fs::path scene = test_util::FreshTestDir("pipeline", "carried_damaged");
  RunOptions options = FastOptions();
  options.frame_setup.working_width = 96;  // the bookkeeping is under test, not the quality
  options.poses = PoseSource::kNone;
  options.evaluate = false;
  options.keyframes.threshold = 1.0;  // no two frames alike: a segment per frame
  RunPipeline(capture, scene, options);
  const SceneIndex index = ReadSceneIndex(scene);
  const auto second = std::find_if(index.segments.begin(), index.segments.end(),
                                   [](const SceneSegmentInfo& s) { return s.first == 1; });
  ASSERT_NE(second, index.segments.end()) << "frame 1 starts a segment";
  RunLog log = ReadRunLog(scene);
  log.segments_done.erase(second->index);
  WriteRunLog(scene, log);
  const fs::path flow = scene / layout::SceneFlow("cam00", 0);
  ASSERT_TRUE(fs::exists(flow));
  WriteFlo(flow, cv::Mat::zeros(8, 8, CV_32FC2));
  test_util::ExpectErrorMentions([&] { RunPipeline(capture, scene, options); },
                                 {flow.filename().string(), "cam00"});
  EXPECT_TRUE(fs::exists(scene / layout::SceneInstances("cam00", 0)));
  EXPECT_TRUE(fs::exists(scene / layout::SceneMesh(1, 0)) ||
              fs::exists(scene / layout::SceneMesh(2, 0)));
}

TEST(PipelineTest, CorruptFrameAndMismatchedOptionsFailClearly) {
  const fs::path capture = SmallCapture();
  const fs::path scene = test_util::FreshTestDir("pipeline", "corrupt");
  // A truncated frame: the error names it, and nothing is recorded as done
  // for the stage that met it.
  const fs::path frame = capture / layout::Image("cam01", 1);
  ASSERT_TRUE(fs::exists(frame));
  fs::resize_file(frame, 100);
  try {
    RunPipeline(capture, scene, FastOptions());
    FAIL() << "a truncated frame must throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(frame.filename().string()), std::string::npos) << e.what();
  }
  const RunLog log = ReadRunLog(scene);
  EXPECT_TRUE(log.StageDone("poses"));
  EXPECT_FALSE(log.StageDone("initial"));

  // The same directory with other options is recomputed rather than mixed,
  // whatever the option (params.json holds every one, e.g. the unsupervised
  // masks' foreground threshold, unused with the given masks here): the
  // recomputation meets the truncated frame again; options that only control
  // the run (threads) do not count either.
  RunOptions other = FastOptions();
  other.joint.terms = AblationTerms("P_M");
  testing::internal::CaptureStdout();
  test_util::ExpectErrorMentions([&] { RunPipeline(capture, scene, other); },
                                 {frame.filename().string()});
  const std::string printed = testing::internal::GetCapturedStdout();
  EXPECT_NE(printed.find("/joint/terms/flow): recomputing the whole scene"), std::string::npos)
      << printed;
  RunOptions other_init = FastOptions();
  other_init.init.foreground.threshold_sigmas = 5;
  test_util::ExpectErrorMentions([&] { RunPipeline(capture, scene, other_init); },
                                 {frame.filename().string()});
  RunOptions other_threads = FastOptions();
  other_threads.threads = 2;
  test_util::ExpectErrorMentions([&] { RunPipeline(capture, scene, other_threads); },
                                 {frame.filename().string()});

  // Inputs named explicitly but absent from the capture (the synthetic one
  // has masks and 2D keypoints, no given 3D poses) are refused by name,
  // before anything is written, instead of giving an empty scene.
  RunOptions given3d = FastOptions();
  given3d.poses = PoseSource::kGiven3d;
  const fs::path scene3d = test_util::FreshTestDir("pipeline", "given3d");
  test_util::ExpectErrorMentions([&] { RunPipeline(capture, scene3d, given3d); },
                                 {"poses3d", "--poses given3d"});
  EXPECT_FALSE(fs::exists(scene3d / "run.json"));
}

// A detector that found nobody in any view: the run fails with a message
// that says what would help, after recording the initial stage; with
// allow_empty the same directory resumes and succeeds with no object.
TEST(PipelineTest, NothingFoundFailsUnlessAllowed) {
  synth::SynthOptions so = synth::SmallHandshakeOptions(3, 160, 90, 2);
  const fs::path capture =
      test_util::RemovedAtExit(synth::WriteCaptureToTempDir("pipeline_empty", so));
  const Capture cap = ReadCapture(capture);
  for (const CaptureView& v : cap.views)
    for (int f = 0; f < cap.num_frames; ++f)
      WriteInstanceMask(capture / layout::Mask(v.name, f), capture / layout::MaskInfo(v.name, f),
                        {cv::Mat::zeros(v.CameraAt(f).height, v.CameraAt(f).width, CV_16UC1), {}});
  const fs::path scene = test_util::FreshTestDir("pipeline", "empty");
  test_util::ExpectErrorMentions([&] { RunPipeline(capture, scene, FastOptions()); },
                                 {capture.string(), "no object found", "masks", "--allow-empty"});
  EXPECT_TRUE(ReadRunLog(scene).StageDone("initial"));
  EXPECT_EQ(ReadRunLog(scene).empty_frames, (std::vector<int>{0, 1}));

  RunOptions allow = FastOptions();
  allow.allow_empty = true;
  const RunResult run = RunPipeline(capture, scene, allow);
  EXPECT_EQ(run.objects, 0);
  EXPECT_EQ(run.empty_frames, (std::vector<int>{0, 1}));
  fs::remove_all(capture);
}

}  // namespace
}  // namespace u4d
