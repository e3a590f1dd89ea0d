// The objects a run reconstructs, per frame, before the joint optimisation:
// the initial instance masks turned into object-id masks (the same id for the
// same person in every view and frame) and, without poses, each view's depth
// range per object.
//
// With 3D poses (tracked people, person_id >= 1): a detector instance takes
// the person whose projected joints fall inside it most often
// (joint/frame_setup.h AssignInstancesToPeople); the joint optimisation then
// draws each person's region and depth range from the joints.
//
// Without poses: the paper's sparse reconstruction of the frame
// (features/sparse_points.h ReconstructSparseFrame) associates the per-view
// instances across views into objects, and features/object_regions.h gives
// each object's depth range per view (sparse points, else the visual hull).
// Wide-baseline rigs give few feature matches, so silhouette points join the
// feature points: surface points of the masks' visual hull
// (features/silhouette_points.h SilhouettePoints),
// each observed in every view it projects into. An instance left out of the
// association (a fragment of a person split in one view) joins the object
// that most of its silhouette points' other observations belong to. A view
// where an object has neither enough feature points nor enough silhouette
// points (RegionOptions::min_points) gets no depth range for it, and the
// object's pixels there go back to background. A view that did not detect
// an object (missed, or merged into another) gets its depth range all the
// same where its points project (the solve looks for it there,
// joint/frame_setup.h). Masks whose ids are already
// alike across views (init.h's step 6) skip the association: mask id k is
// object k.
// Identities through time: an object takes the id of the nearest tracked
// object (greedy, nearest pairs first) within max_centroid_jump_m per frame
// since that object was last seen; otherwise a new id. A tracked object not
// seen in a frame (missed everywhere, or merged with another person in every
// view) keeps its id for max_missing_frames, so that it takes it back when it
// reappears instead of becoming a new person. Across a cut in time (frames
// far apart in the source, RunOptions::max_frame_gap_s) positions say
// nothing: an object takes the id of the tracked object whose colours are
// nearest (features/object_appearance.h; greedy, nearest pairs first) within
// max_appearance_distance when no other track or object is within
// min_appearance_margin of that distance, else a new id.
//
// Files (io/layout.h): initial/masks/<view>/<frame>.png (16-bit ids, an
// absent file = no mask in that view) and initial/objects/<frame>.json
// {"frame", "objects": [{"id", "centroid": [x,y,z] | null}],
//  "depth_ranges": {"<view>": {"<id>": [near, far]}},
//  "classes": {"<id>": {"<class>": votes}}} ("classes" may be absent).
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/features/object_appearance.h"
#include "u4d/features/object_regions.h"
#include "u4d/features/sparse_points.h"
#include "u4d/init/init.h"
#include "u4d/io/poses.h"
#include "u4d/joint/frame_setup.h"
#include "u4d/pipeline/object_classes.h"
#include "u4d/util/file.h"

namespace u4d {

struct FrameObjects {
  std::vector<cv::Mat> ids;  // per view: CV_16U object ids at camera size; empty = no mask
  // Per view: object id -> (near, far) metres; filled without poses only.
  std::vector<std::map<int, std::pair<double, double>>> depth_ranges;
  std::map<int, Eigen::Vector3d> centroids;  // object id -> world centroid (without poses)
  int num_sparse_points = 0;                 // points of the frame's sparse reconstruction
  // Object id -> class -> views voting for it (object_classes.h); filled by
  // the pipeline from the given masks' classes, empty without them.
  ClassVotes class_votes;
};

// How objects without a pose keep their ids from frame to frame (above).
struct ObjectLinkOptions {
  double max_centroid_jump_m = 0.5;  // farther centroids (per frame unseen) are different objects
  int max_missing_frames = 25;       // an unseen object is forgotten after this many frames
  // Across a cut, an object's colours (Delta E, object_appearance.h) may
  // differ from a track's by at most this and still be that object (0 = a
  // cut forgets every object). 10: colours that differ by more are distinct
  // at a glance (2.3 is the smallest difference an eye sees); one person's
  // colours change less between views and instants under the same light.
  double max_appearance_distance = 10.0;
  // ... and only when no rival comes near: every other track within this
  // (Delta E) of the object's distance to the track, or another object
  // within it of the track's, makes the link ambiguous, and the object takes
  // a new id. 2.3, the smallest difference an eye sees: a rival nearer than
  // that is as much that person by colour. People dressed alike (dark
  // clothes in a studio) lie a few Delta E from each other, and a link
  // taken at chance is a wrong one: one id for two people merges their
  // tracks and meshes, which a new id for a person seen before does not.
  // 0 = the nearest pairs are linked first, whatever their rivals.
  double min_appearance_margin = 2.3;

  void Check() const;  // throws u4d::Error naming the field on a bad value
};

// Identity state carried from frame to frame (no poses).
struct ObjectLinker {
  ObjectLinkOptions options;
  struct Track {
    Eigen::Vector3d position;     // world centroid when last seen
    ObjectAppearance appearance;  // colours, pixel-weighted over the frames seen
    int missing = 0;              // frames since then
    std::string label;            // the detector's class ("" when unknown): links only alike
  };
  std::map<int, Track> tracks;  // object id -> track
  int next_id = 1;
  bool after_cut = false;       // the next frame links by appearance (set at a cut, then cleared)
  bool keep_appearance = true;  // tracks keep their colours (false where no cut comes)
};

// A cut in time: positions say nothing. With colours kept and
// max_appearance_distance > 0, the next LinkObjects links by colour (if any
// track is left to link to); otherwise every track is forgotten.
void CutLinker(ObjectLinker* linker);

// Per-frame object k (keys of `centroids`, world; `appearances` and
// `labels` of the same keys, each may lack some) -> its id, updating the
// linker's tracks as above: nearest tracked centroid, or after a cut
// (linker->after_cut, then cleared) nearest colours that no rival comes
// near (ObjectLinkOptions); else a new id.
std::map<int, int> LinkObjects(const std::map<int, Eigen::Vector3d>& centroids,
                               const std::map<int, ObjectAppearance>& appearances,
                               const std::map<int, std::string>& labels, ObjectLinker* linker);

// Without poses: detector masks (ids local to each image; an empty Mat = no
// mask file, nothing detected) named by the people of the frame's voxel hull
// on the ground plane (init.h step 6, SeparatePeopleOnGround): the same id is
// the same person in every view of the frame, an instance that merges two
// people is split between them, and instances no person's hull explains
// (false positives) are dropped. `people` holds the previous frame's people
// (ground positions, world) on input and this frame's on output: a hull
// region that holds two of the previous people is split between them, so
// that people who touch stay two. Views without a mask stay empty. Ids are
// not alike through time (ObjectLinker does that). The given masks keep
// their pixels (KeepGivenPixels): the ground step names them, it does not
// segment them.
std::vector<cv::Mat> GroundPeopleFromDetections(const std::vector<Camera>& cameras,
                                                const std::vector<cv::Mat>& masks,
                                                const InitOptions& options,
                                                std::vector<Eigen::Vector3d>* people);

// The ground step (GroundPeopleFromDetections) through one shot of
// `num_frames` frames, forwards and then backwards in time. `ground_step(k,
// start)` runs it on frame k from the people `start` (the previous frame's,
// empty at the first) and returns the people found. Forwards each frame
// starts from the previous one's result; backwards, a frame with fewer
// people than the next one runs again from the next frame's people and
// keeps that result when it finds more (a detector that merges two people
// who touch at the start of a shot, where no earlier frame holds them
// apart). Returns per frame the next frame's people where that run found
// more, else nullopt (start from the previous frame's, as forwards).
using PeoplePositions = std::vector<Eigen::Vector3d>;
std::vector<std::optional<PeoplePositions>> PeopleFromTheNextFrame(
    int num_frames, const std::function<PeoplePositions(int, PeoplePositions)>& ground_step);

// Step 6 drops the pixels of an instance that lie far from every ray meeting
// a person (clutter in the unsupervised masks; a hand or a foot the
// low-resolution hull misses in given ones). Given masks keep them: a pixel
// of `given` (ids local to the image) that `named` left at 0 takes the id
// most of its instance's named pixels took; an instance named nowhere (no
// person explains it, a false positive) stays dropped. Throws u4d::Error on
// mismatched sizes or types (both CV_16U).
cv::Mat KeepGivenPixels(const cv::Mat& given, const cv::Mat& named);

// With poses: `masks[v]` detector ids (empty = none) -> object ids.
FrameObjects ObjectsFromPoses(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& masks,
                              const std::vector<Pose3d>& poses, const FrameSetupOptions& options);

// With poses and masks of several classes: the people from `people_masks`
// (ObjectsFromPoses) and, from `other_masks` (the instances that are not
// people: a box, a chair), the objects without a pose, associated across
// views and linked through time as without poses (ObjectsFromSparse, ids from
// `linker`, which the caller starts above every person id), with their depth
// ranges; `other_classes` are the classes of the other masks' ids, and the
// people's masks are where the views cannot tell (DetectorContext). Where
// both claim a pixel the person keeps it. `other_masks` without any instance
// pixel give exactly ObjectsFromPoses.
// `people` (the frame's people, from poses or the ground step) with the
// objects of `other_masks` added as ObjectsFromPosesAndOthers adds them
// (ids from `linker`, which the caller keeps apart from the people's ids;
// `people_masks` are where the views cannot tell). Without any other
// instance pixel, `people` unchanged.
FrameObjects WithOtherObjects(FrameObjects people, const std::vector<Camera>& cameras,
                              const std::vector<cv::Mat>& images,
                              const std::vector<cv::Mat>& people_masks,
                              const std::vector<cv::Mat>& other_masks,
                              const SparseFrameOptions& sparse_options,
                              const ObjectRegionOptions& region_options, ObjectLinker* linker,
                              const InstanceClasses* other_classes);

FrameObjects ObjectsFromPosesAndOthers(
    const std::vector<Camera>& cameras, const std::vector<cv::Mat>& images,
    const std::vector<cv::Mat>& people_masks, const std::vector<cv::Mat>& other_masks,
    const std::vector<Pose3d>& poses, const FrameSetupOptions& frame_options,
    const SparseFrameOptions& sparse_options, const ObjectRegionOptions& region_options,
    ObjectLinker* linker, const InstanceClasses* other_classes = nullptr);

// Without poses: see above. With `ids_alike_across_views` (masks whose id
// is already the same person in every view, e.g. init.h's step 6) mask id k
// is object k in every view and the feature/silhouette association is not
// run (the points still give centroids and depth ranges). `detector` adds
// what the detector said beyond the masks (DetectorContext). Throws
// u4d::Error on mismatched sizes.
//
// What the detector says beyond the masks being associated (each optional):
//  - classes: the class of each mask id (features/sparse_points.h). Instances
//    of different classes are never one object, a fragment joins only an
//    object of its class, and an object links only to a track of its class.
//  - unknown: per view (empty Mat = none), the pixels of detections that are
//    not among the masks: the people, when the masks hold the objects
//    without a pose. A silhouette point projecting there abstains in that
//    view (SilhouettePoints), so that a box the detector merged with the
//    person holding it in half the views is not carved out of the hull.
struct DetectorContext {
  const InstanceClasses* classes = nullptr;
  const std::vector<cv::Mat>* unknown = nullptr;
};
FrameObjects ObjectsFromSparse(const std::vector<Camera>& cameras,
                               const std::vector<cv::Mat>& images,
                               const std::vector<cv::Mat>& masks,
                               const SparseFrameOptions& sparse_options,
                               const ObjectRegionOptions& region_options, ObjectLinker* linker,
                               bool ids_alike_across_views = false,
                               const DetectorContext& detector = {});

// Writes / reads the files above for `frame` under the scene root `out`.
// Reading a frame never written throws u4d::Error naming the file.
void WriteFrameObjects(const fs::path& out, const std::vector<std::string>& view_names, int frame,
                       const FrameObjects& objects);
FrameObjects ReadFrameObjects(const fs::path& out, const std::vector<std::string>& view_names,
                              int frame);

}  // namespace u4d
