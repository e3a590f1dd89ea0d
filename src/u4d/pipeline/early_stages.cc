// The stages of `u4d run` before the joint solve (early_stages.h).
#include "u4d/pipeline/early_stages.h"

#include <algorithm>
#include <functional>
#include <optional>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/visualize.h"
#include "u4d/pipeline/initial_objects.h"
#include "u4d/pipeline/object_classes.h"
#include "u4d/pipeline/unlabelled_objects.h"
#include "u4d/pipeline/view_stage.h"
#include "u4d/pose/given_poses.h"
#include "u4d/pose/pose_smoothing.h"
#include "u4d/util/check.h"
#include "u4d/util/progress.h"

namespace u4d {
namespace {

// The mean of a pose's known joints (world), its position for LinkObjects.
Eigen::Vector3d PoseCentroid(const Pose3d& pose) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const Eigen::Vector4d& j : pose.joints)
    if (j.w() > 0) sum += j.head<3>(), ++n;
  return n > 0 ? Eigen::Vector3d(sum / n) : sum;
}

// The run's ids of the people of a shot starting at `first` (`people`, its
// poses there, track ids from 0): after a cut the given masks' colours name
// them after the people of earlier shots (LinkObjects across a cut, the
// linker holding those people, CutLinker); where the linker keeps no
// colours (no given masks, or no cut in the run), each gets a new id.
std::map<int, int> ShotIds(RunContext& c, int first, const std::vector<Pose3d>& people,
                           ObjectLinker* linker) {
  std::vector<Pose3d> named = people;
  for (Pose3d& p : named) ++p.person_id;  // object ids start at 1
  std::map<int, Eigen::Vector3d> centroids;
  for (const Pose3d& p : named) centroids[p.person_id] = PoseCentroid(p);
  std::map<int, ObjectAppearance> appearances;
  if (linker->keep_appearance && linker->options.max_appearance_distance > 0) {
    const std::vector<cv::Mat> masks = IdImages(KeepInstances(ReadGivenMasks(c, first), true));
    appearances = ObjectAppearances(
        ReadViews(c, first), ObjectsFromPoses(c.Cameras(first), masks, named, c.o.frame_setup).ids);
  }
  CutLinker(linker);
  std::map<int, int> ids;
  for (const auto& [k, id] : LinkObjects(centroids, appearances, {}, linker)) ids[k - 1] = id;
  return ids;
}

// Poses tracked and smoothed within each shot (a cut ends every track);
// ids are unique over the run and start at 1, and a person seen in an
// earlier shot takes its id back (ShotIds).
std::vector<std::vector<Pose3d>> TrackPosesInShots(RunContext& c,
                                                   const std::vector<std::vector<Pose3d>>& raw) {
  std::vector<std::vector<Pose3d>> poses;
  ObjectLinker linker;
  linker.options = c.o.link;
  linker.keep_appearance = c.masks == MaskSource::kGiven && c.Shots().size() > 1;
  for (const auto& [first, last] : c.Shots()) {
    const std::vector<std::vector<Pose3d>> shot(raw.begin() + (first - c.f0),
                                                raw.begin() + (last - c.f0));
    std::vector<std::vector<Pose3d>> tracked =
        SmoothTrackedPoses(TrackPoses(shot, c.o.pose_tracking), c.cap.fps, c.o.pose_smoothing);
    std::map<int, int> ids = ShotIds(c, first, tracked.front(), &linker);
    for (std::vector<Pose3d>& frame : tracked) {
      for (Pose3d& p : frame) {
        if (!ids.count(p.person_id)) ids[p.person_id] = linker.next_id++;  // enters later
        p.person_id = ids.at(p.person_id);
      }
      poses.push_back(std::move(frame));
    }
  }
  return poses;
}

// Given masks on two or more static cameras: objects the detector missed
// everywhere are looked for (unlabelled_objects.h).
bool FindsUnlabelledObjects(const RunContext& c) {
  if (c.masks != MaskSource::kGiven || !c.o.unlabelled.enabled || c.NumViews() < 2) return false;
  for (const CaptureView& view : c.cap.views)
    if (view.IsMoving()) return false;
  return true;
}

// Given masks, no poses: per frame run, the people to start its ground
// step from where they are the next frame's (PeopleFromTheNextFrame, each
// shot on its own).
std::vector<std::optional<PeoplePositions>> NextFramePeople(RunContext& c) {
  std::vector<std::optional<PeoplePositions>> hints;
  for (const auto& [shot_first, shot_last] : c.Shots()) {
    const int first = shot_first;  // a variable, not a binding: lambdas capture it (C++17)
    const auto shot = PeopleFromTheNextFrame(shot_last - first, [&](int k, PeoplePositions start) {
      const int f = first + k;
      GroundPeopleFromDetections(c.Cameras(f), IdImages(KeepInstances(ReadGivenMasks(c, f), true)),
                                 c.o.init, &start);
      return start;
    });
    hints.insert(hints.end(), shot.begin(), shot.end());
  }
  return hints;
}

// View v's given mask of `frame`; empty without a mask file.
InstanceMask ReadGivenMask(const RunContext& c, int v, int frame) {
  const fs::path png = c.cap.root / layout::Mask(c.names[v], frame);
  if (!fs::exists(png)) return {};
  InstanceMask mask = ReadInstanceMask(png, c.cap.root / layout::MaskInfo(c.names[v], frame));
  CheckImageSize(mask.ids, c.cap.views[v].CameraAt(frame).width,
                 c.cap.views[v].CameraAt(frame).height, png.string());
  return mask;
}

}  // namespace

std::vector<InstanceMask> ReadGivenMasks(const RunContext& c, int frame) {
  std::vector<InstanceMask> masks(c.NumViews());
  for (int v = 0; v < c.NumViews(); ++v) masks[v] = ReadGivenMask(c, v, frame);
  return masks;
}

// ---- poses ----

std::vector<std::vector<Pose3d>> ComputePoses(RunContext& c) {
  std::vector<std::vector<Pose3d>> poses(c.NumFrames());
  if (c.poses == PoseSource::kGiven3d) {
    const auto all = ReadGivenPoses3d(c.cap.root, c.f1, /*allow_missing=*/true);
    int min_id = 1;
    for (int k = 0; k < c.NumFrames(); ++k) {
      poses[k] = all[c.f0 + k];
      for (const Pose3d& p : poses[k]) min_id = std::min(min_id, p.person_id);
    }
    // Object ids must be >= 1: shift given ids (e.g. 0-based or -1) up.
    for (auto& frame : poses)
      for (Pose3d& p : frame) p.person_id += 1 - min_id;
  } else if (c.poses == PoseSource::kFrom2d) {
    Progress progress("poses", c.NumFrames(), c.o.progress);
    std::vector<std::vector<Pose3d>> raw(c.NumFrames());
    for (int k = 0; k < c.NumFrames(); ++k) {
      const int f = c.f0 + k;
      std::vector<std::vector<Pose2d>> per_view(c.NumViews());
      for (int v = 0; v < c.NumViews(); ++v) {
        const fs::path path = c.cap.root / layout::Poses2d(c.names[v], f);
        if (fs::exists(path)) per_view[v] = ReadPoses2d(path);
      }
      raw[k] = TriangulatePoses(per_view, c.Cameras(f), c.o.pose);
      progress.Tick();
    }
    poses = TrackPosesInShots(c, raw);
  }
  if (c.poses != PoseSource::kNone)
    for (int k = 0; k < c.NumFrames(); ++k)
      WritePoses3d(c.out / layout::ScenePoses3d(c.f0 + k), poses[k]);
  return poses;
}

std::vector<std::vector<Pose3d>> ReadScenePoses(const RunContext& c) {
  std::vector<std::vector<Pose3d>> poses(c.NumFrames());
  if (c.poses == PoseSource::kNone) return poses;
  for (int k = 0; k < c.NumFrames(); ++k)
    poses[k] = ReadPoses3d(c.out / layout::ScenePoses3d(c.f0 + k));
  return poses;
}

// ---- initial objects ----

namespace {

// Each view's background or key, for the unsupervised masks or the
// unlabelled-objects step. With given masks, the background's median leaves
// out the pixels their instances explain (ExplainedPixels).
void ReadViewStages(RunContext& c, std::vector<BackgroundModel>* backgrounds,
                    std::vector<ChromaKey>* keys) {
  for (int v = 0; v < c.NumViews(); ++v) {
    U4D_CHECK(!c.cap.views[v].IsMoving(),
              "view {} moves: unsupervised masks need static cameras (give masks/ instead)",
              c.names[v]);
    std::function<cv::Mat(int)> known;
    if (c.masks == MaskSource::kGiven)
      known = [&c, v](int f) { return ExplainedPixels(ReadGivenMask(c, v, f), c.o.unlabelled); };
    ViewStage stage = ReadViewStage(
        c.cap, v, [&](int f) { return c.reader.Read(v, f); }, c.o.background, c.o.chroma_key,
        known);
    backgrounds->push_back(std::move(stage.background));
    keys->push_back(stage.key);
  }
}

}  // namespace

int ComputeInitialObjects(RunContext& c, const std::vector<std::vector<Pose3d>>& poses) {
  std::vector<BackgroundModel> backgrounds;
  std::vector<ChromaKey> keys;
  if (c.masks == MaskSource::kUnsupervised || FindsUnlabelledObjects(c))
    ReadViewStages(c, &backgrounds, &keys);
  ObjectLinker linker;  // with poses it names the objects that are not people, after them
  linker.options = c.o.link;
  // Without poses the people come from the ground step and the objects of
  // other classes are named apart, from one counter of ids.
  ObjectLinker others_linker;
  others_linker.options = c.o.link;
  linker.keep_appearance = others_linker.keep_appearance = c.Shots().size() > 1;
  for (const auto& frame : poses)
    for (const Pose3d& p : frame) linker.next_id = std::max(linker.next_id, p.person_id + 1);
  // The ground-plane step (init.h step 6) names people alike in every
  // view: unsupervised masks come from it, given masks go through it.
  const bool ground = UsesGroundOccupancy(c.o.init, c.NumViews());
  const bool with_poses = c.poses != PoseSource::kNone;
  const bool given_on_ground = c.masks == MaskSource::kGiven && !with_poses && ground;
  std::vector<std::optional<PeoplePositions>> next_people(c.NumFrames());
  if (given_on_ground) next_people = NextFramePeople(c);
  std::vector<Eigen::Vector3d> ground_people;  // the previous frame's, for given masks
  std::vector<int> empty_frames;
  Progress progress("initial", c.NumFrames(), c.o.progress);
  for (int k = 0; k < c.NumFrames(); ++k) {
    const int f = c.f0 + k;
    if (!c.Continues(f)) {  // after a cut positions say nothing; colours may
      CutLinker(&linker);
      CutLinker(&others_linker);
      ground_people.clear();
    }
    if (next_people[k]) ground_people = *next_people[k];
    const std::vector<Camera> cams = c.Cameras(f);
    const std::vector<cv::Mat> images = ReadViews(c, f);
    std::vector<InstanceMask> given =
        c.masks == MaskSource::kGiven ? ReadGivenMasks(c, f) : std::vector<InstanceMask>();
    if (FindsUnlabelledObjects(c))
      AddUnlabelledObjects(
          UnexplainedForeground(cams, images, backgrounds, keys, given, c.o.init, c.o.unlabelled),
          c.o.unlabelled, &given);
    std::vector<cv::Mat> masks = IdImages(given);
    if (c.masks == MaskSource::kUnsupervised)
      masks = UnsupervisedInstanceMasks(cams, images, backgrounds, c.o.init, keys);
    // The ground step names the people; given instances of other classes
    // join after it (WithOtherObjects).
    if (given_on_ground)
      masks = GroundPeopleFromDetections(cams, IdImages(KeepInstances(given, true)), c.o.init,
                                         &ground_people);
    linker.next_id = std::max(linker.next_id, others_linker.next_id);
    // With poses, instances that are not people become objects without a
    // pose. The detector's classes keep objects of different classes apart
    // where the masks are its own (not renamed by the ground step).
    const InstanceClasses classes = InstanceClassesOf(given);
    const InstanceClasses* given_classes = given.empty() || given_on_ground ? nullptr : &classes;
    FrameObjects objects =
        !with_poses     ? ObjectsFromSparse(cams, images, masks, c.o.sparse, c.o.regions, &linker,
                                            ground, {given_classes})
        : given.empty() ? ObjectsFromPoses(cams, masks, poses[k], c.o.frame_setup)
                        : ObjectsFromPosesAndOthers(
                              cams, images, IdImages(KeepInstances(given, true)),
                              IdImages(KeepInstances(given, false)), poses[k], c.o.frame_setup,
                              c.o.sparse, c.o.regions, &linker, given_classes);
    if (given_on_ground) {
      others_linker.next_id = linker.next_id;
      objects = WithOtherObjects(std::move(objects), cams, images, masks,
                                 IdImages(KeepInstances(given, false)), c.o.sparse, c.o.regions,
                                 &others_linker, &classes);
    }
    if (!given.empty()) objects.class_votes = VoteObjectClasses(objects.ids, given);
    WriteFrameObjects(c.out, c.names, f, objects);
    bool any = false;
    for (const cv::Mat& ids : objects.ids) any = any || (!ids.empty() && cv::countNonZero(ids) > 0);
    if (!any) empty_frames.push_back(f);
    progress.Tick();
  }
  c.log.empty_frames = empty_frames;
  return c.NumFrames();
}

void CheckNotEmpty(const RunContext& c) {
  const std::vector<int>& empty = c.log.empty_frames;
  if (empty.empty()) return;
  const bool all = static_cast<int>(empty.size()) == c.NumFrames();
  U4D_CHECK(!all || c.o.allow_empty,
            "{}: no object found in any view at any of the {} frames run (masks: {}). "
            "Give initial masks (masks/<view>/<frame>.png, docs/formats.md) or 3D or 2D poses "
            "(poses3d/, poses2d/); without them people are found only where they move against "
            "the background of the capture's frames, unless the capture holds a clean plate "
            "(background/<view>.png) or is keyed (--chroma-key on). --allow-empty accepts an "
            "empty scene.",
            c.cap.root.string(), c.NumFrames(), ToString(c.masks));
  fmt::print(
      "[initial] warning: no object found in any view at {} of {} frames (first: {}); "
      "those frames stay empty (run.json lists them)\n",
      empty.size(), c.NumFrames(), empty.front());
}

// ---- temporal tracks ----

// The views run in parallel (each reads only its own frames).
std::vector<TemporalTrack> ComputeTracks(RunContext& c,
                                         const std::vector<std::vector<Pose3d>>& poses) {
  Progress progress("tracks", int64_t(c.NumFrames()) * c.NumViews(), c.o.progress);
  std::vector<std::vector<TemporalTrack>> per_view(c.NumViews());
  tbb::parallel_for(0, c.NumViews(), [&](int v) {
    std::vector<TemporalTrack>& view_tracks = per_view[v];
    for (const auto& [first, last] : c.Shots(c.o.track_chunk_frames)) {
      std::vector<FrameFeatures> features;
      std::vector<cv::Mat> ids;
      std::vector<std::vector<Pose3d>> chunk_poses;
      for (int f = first; f < last; ++f) {
        const fs::path png = c.out / layout::SceneInitialMask(c.names[v], f);
        ids.push_back(fs::exists(png) ? ReadLabelImage(png) : cv::Mat());
        features.push_back(DetectFrameFeatures(c.reader.Read(v, f), ids.back(), c.o.tracks));
        chunk_poses.push_back(poses[f - c.f0]);
        progress.Tick();
      }
      for (TemporalTrack& t : LinkFeatureTracks(v, first, features, c.o.tracks))
        view_tracks.push_back(std::move(t));
      if (c.poses != PoseSource::kNone && c.o.tracks.add_joint_tracks)
        for (TemporalTrack& t : JointTracks(c.cap, v, first, chunk_poses, ids, c.o.tracks))
          view_tracks.push_back(std::move(t));
    }
    WriteTemporalTracks(c.out / layout::SceneTracks(c.names[v]), c.names[v], v, view_tracks);
  });
  std::vector<TemporalTrack> all;
  for (std::vector<TemporalTrack>& view_tracks : per_view)
    for (TemporalTrack& t : view_tracks) all.push_back(std::move(t));
  return all;
}

std::vector<TemporalTrack> ReadSceneTracks(const RunContext& c) {
  std::vector<TemporalTrack> all;
  for (int v = 0; v < c.NumViews(); ++v)
    for (TemporalTrack& t : ReadTemporalTracks(c.out / layout::SceneTracks(c.names[v]), v))
      all.push_back(std::move(t));
  return all;
}

// ---- key-frames ----

KeyframeSelection ComputeKeyframes(RunContext& c, const std::vector<std::vector<Pose3d>>& poses,
                                   const std::vector<TemporalTrack>& tracks) {
  KeyframeObservations obs;
  obs.num_frames = c.NumFrames();
  obs.poses = poses;
  obs.masks.resize(c.NumViews());
  for (int k = 0; k < c.NumFrames(); ++k) {
    const FrameObjects objects = ReadFrameObjects(c.out, c.names, c.f0 + k);
    for (int v = 0; v < c.NumViews(); ++v) {
      InstanceMask m;
      if (!objects.ids[v].empty()) {
        // The terms compare shapes and positions relative to the image, so a
        // downscaled mask keeps them while bounding memory.
        const cv::Mat small =
            DownscaleToWidth(objects.ids[v], c.o.keyframe_mask_width, /*nearest=*/true);
        m = ToInstanceMask(small);
      }
      obs.masks[v].push_back(m);
    }
  }
  // Track frames relative to f0, as the observations'.
  for (const TemporalTrack& t : tracks) {
    TemporalTrack r = t;
    for (auto& [frame, x] : r.points) frame -= c.f0;
    obs.tracks.push_back(std::move(r));
  }
  const Eigen::MatrixXd ks = KeyframeSimilarityMatrix(obs, c.o.keyframes);
  std::vector<int> shot_starts;
  for (const auto& shot : c.Shots()) shot_starts.push_back(shot.first - c.f0);
  KeyframeSelectOptions select;
  select.threshold = c.o.keyframes.threshold;
  KeyframeSelection selection = SelectKeyframesInShots(ks, shot_starts, select);
  WriteKeyframes(c.out / layout::SceneKeyframes(), selection);
  return selection;
}

}  // namespace u4d
