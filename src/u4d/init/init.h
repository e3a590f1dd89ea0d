// Unsupervised initial instance masks: what U4D starts from when a capture
// has neither initial masks (masks/) nor poses (issue 5; the paper, Sec. 2,
// assumes an off-the-shelf instance segmentation, this module replaces it
// for static cameras). Three steps, each usable alone:
//
// 1. Background model (static camera). Per view, the per-pixel median of up
//    to `max_frames` frames spread evenly over the sequence, in CIE Lab
//    (OpenCV's 8-bit Lab: L in [0, 255], a and b offset by 128). The noise
//    level sigma is estimated from the same frames: the median over pixels
//    and sampled frames of the Lab distance to the background, divided by
//    1.54 (the median of a 3-dof chi distribution, i.e. per-channel Gaussian
//    noise of std sigma); moving people cover a minority of the pixels, so
//    the median sees the noise. A per-pixel noise level (the median distance
//    of that pixel over the samples / 1.54) raises the threshold where the
//    background itself flickers (compression, leaves, screens).
//
// 2. Foreground. A pixel is foreground when its Lab distance to the
//    background exceeds threshold_sigmas * max(sigma, pixel sigma, floor),
//    unless it is a shadow: darker than the background by a factor in
//    [shadow_min_ratio, shadow_max_ratio] in L with a chroma (a, b) change
//    below shadow_chroma_sigmas * sigma. The binary mask is cleaned by a
//    morphological opening and closing and by removing connected components
//    smaller than min_blob_fraction of the image area; holes smaller than
//    that are filled.
//
// 3. Cross-view consistency (calibrated static cameras; a visual-hull test
//    on the silhouettes). At a reduced resolution (longest side
//    consistency_max_side), a foreground pixel of view c is consistent when
//    its ray has a depth at which it projects into the (dilated) foreground
//    of at least ceil(min_view_fraction * n) of the n other views in whose
//    image it falls, with n >= min(min_views_seeing, views - 1). Requiring
//    two views matters: points just in front of camera c project, in the
//    camera facing it, onto the people between the two. The ray is marched
//    from min_depth_m to max_depth_m with steps adapted so that its
//    projection moves about step_px (reduced) pixels in the other views
//    (0.5x..2x per step, between 1 mm and 0.25 m). A connected component of
//    the full-resolution mask is kept when at least min_consistent_fraction of
//    its pixels are consistent; with carve_pixels, inconsistent pixels are
//    also removed inside kept components.
//
// 4. People instances. Connected components of the foreground, dilated by
//    group_radius_px (fragments of one person stay together), are the
//    instances. HOG boxes with little foreground are filled by GrabCut
//    before the cross-view check (AddDetectedPeople), for people who stand
//    still and are thus in the background model: by default (box_fill
//    kEmptyViews) only in views where the background leaves less foreground
//    than one instance (min_instance_fraction of the image), since where it finds people HOG's
//    false boxes lower the IoU (docs/init.md); kAlways in every view, kNever not. Where boxes are
//    filled and two or more calibrated views exist, the boxes are those of the people the views'
//    boxes place on the floor (step 4b, PeopleFromBoxes below). OpenCV's HOG
//    people detector (Dalal-Triggs, HOGDescriptor::getDefaultPeopleDetector, 64x128 windows; the
//    image is upscaled so that people of min_person_height_px fit the window) gives boxes: a
//    component holding two or more boxes whose centres are apart horizontally is split between them
//    (each pixel goes to the box whose centre column is nearest, among the boxes containing it when
//    any does). Without detections, a component is split at a deep valley of its column profile
//    (people standing side by side touching with an arm). With require_detection, components no box
//    overlaps are dropped. Optionally each instance is refined by cv::grabCut seeded from the mask
//    (sure foreground = eroded mask, probable foreground = the mask's convex hull, probable
//    background = a ring around the hull, background elsewhere in its box and on other instances).
//
// 5. Subjects who stay in place (on by default; docs/init.md). A median
//    background contains a subject who stays in place for most of the
//    sampled frames, so step 2 finds only the parts that move (limbs) and
//    "ghosts" where the subject was in the model but no longer is. The
//    background also keeps the temporal envelope of the sampled frames'
//    foreground (where the moving parts swept). Per frame, ghost components
//    are dropped (RemoveGhosts: their outline is an edge of the model, not of
//    the image), then FillStillSubjects runs GrabCut in the convex hull of
//    the envelope's components that the frame's foreground touches, with
//    colour models learnt from the sure pixels only (the frame's foreground;
//    the surroundings beyond a ring around the hull), and adds what it finds
//    in the hull where the background model also shows the subject. In
//    UnsupervisedInstanceMasks the added pixels are kept only where the
//    cross-view check confirms them (carve_still_fill).
//
// 6. People on the ground plane (SeparatePeopleOnGround, below; with at
//    least occupancy_min_views calibrated cameras): step 4's instances are
//    named, split where they merge people, or dropped, by the people of a
//    voxel hull of all views separated on the ground plane.
//
// Output: CV_16UC1 ids per view, 0 = background, the format of the
// capture's masks/ (io/instance_mask.h, docs/formats.md). With step 6 an id
// is the same person in every view of the time step (ids need not be
// contiguous in a view); without it ids are 1..n local to the view (sorted
// left to right by the instance's centroid). Ids are NOT the same person
// across frames.
//
// Failure modes: throws u4d::Error on empty images, a size that differs
// between a frame and its background or camera, a non-BGR image, mismatched
// vector sizes, or bad options. It does not detect people who stand
// entirely still for most of the sampled frames (no envelope: they are
// background; the HOG box GrabCut is the optional remedy), nor separate
// people who overlap in a view without a HOG detection for each.
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"
#include "u4d/init/chroma_key.h"
#include "u4d/io/instance_mask.h"

namespace u4d {

struct BackgroundOptions {
  int max_frames = 25;  // frames sampled evenly over the sequence for the median (>= 1)
  // Temporal envelope (step 5): also keep, per pixel, whether the sampled
  // frames' foreground (step 2 with a default InitOptions, i.e. the
  // defaults of its foreground fields) covered it in at least
  // envelope_min_frames of them. Costs one foreground pass per sampled frame
  // (the frames are in memory already).
  bool envelope = true;
  int envelope_min_frames = 1;  // >= 1; 1 = the union of the sampled frames' foreground

  void Check() const;  // throws u4d::Error naming the offending field
};

// A static camera's background.
struct BackgroundModel {
  cv::Mat lab;          // CV_8UC3 per-pixel median in OpenCV 8-bit Lab
  cv::Mat bgr;          // CV_8UC3 the same in BGR (for pictures)
  cv::Mat pixel_sigma;  // CV_32FC1 per-pixel noise level (Lab units)
  double sigma = 0;     // global noise level (Lab units), see above
  int frames_used = 0;  // frames in the median
  cv::Mat envelope;     // CV_8UC1 0/255 temporal envelope of the foreground (step 5);
                        // empty when BackgroundOptions::envelope is off

  bool Empty() const { return lab.empty(); }
  int Width() const { return lab.cols; }
  int Height() const { return lab.rows; }
};

// From BGR frames (CV_8UC3, all the same size). Uses up to max_frames of
// them, evenly spread. Throws on no frames, an empty or non-BGR frame, or
// differing sizes (naming the frame index).
BackgroundModel EstimateBackground(const std::vector<cv::Mat>& frames,
                                   const BackgroundOptions& options = {});
// The same, reading frame k in [0, num_frames) through `read_frame` (e.g. a
// FrameReader); only the sampled frames are read, in increasing order.
// Where `known_foreground` is given, known_foreground(k) (CV_8U, nonzero =
// a person or object is known to cover the pixel, e.g. given masks; empty =
// nothing known) leaves frame k out of that pixel's median and noise level:
// a person who stands on a pixel in most frames is not its background. A
// pixel covered in every sampled frame keeps the median of all of them.
// Throws when a known mask is not CV_8U of the frames' size.
BackgroundModel EstimateBackground(int num_frames, const std::function<cv::Mat(int)>& read_frame,
                                   const BackgroundOptions& options = {},
                                   const std::function<cv::Mat(int)>& known_foreground = {});

// From a clean plate (io/clean_plate.h: the empty stage filmed from the
// view, one picture or a few frames) instead of the capture's own frames, so
// that people who stay in place are foreground: the model is the per-pixel
// median of the plate frames (up to max_frames of them, evenly spread). The
// noise levels come from the plate when it
// has at least 3 frames; from fewer, the global level is the median
// distance of the take's sampled frames to the plate (people are a minority
// of the pixels) and there is no per-pixel level. The envelope (step 5) is
// taken from the take's sampled frames as in EstimateBackground. Throws on
// no plate frame, a non-BGR frame, or sizes that differ.
BackgroundModel BackgroundFromPlate(const std::vector<cv::Mat>& plate, int num_frames,
                                    const std::function<cv::Mat(int)>& read_frame,
                                    const BackgroundOptions& options = {});

// Foreground (step 2, ForegroundMask; also cleans the masks of steps 4a and 5).
struct ForegroundOptions {
  double threshold_sigmas = 4.0;      // foreground: distance > this * noise level
  double min_noise_sigma = 2.0;       // floor of the noise level (Lab units)
  bool suppress_shadows = true;       // classify darker, same-chroma pixels as background
  double shadow_min_ratio = 0.45;     // shadow: L / L_background >= this
  double shadow_max_ratio = 0.95;     // shadow: L / L_background <= this
  double shadow_chroma_sigmas = 3.0;  // shadow: chroma change <= this * noise level
  int morph_radius_px = 0;            // opening/closing radius; 0 = 1 px per 360 px of height
  double min_blob_fraction = 2e-4;    // components (and holes) smaller than this * area go

  void Check() const;  // throws u4d::Error naming the offending field
};

// Cross-view consistency (step 3, CrossViewConsistentMasks).
struct CrossViewOptions {
  bool enabled = true;                   // run it when >= 2 calibrated views are given
  int consistency_max_side = 160;        // longest image side at which rays are tested (px)
  double step_px = 0.8;                  // ray march step: projected motion in other views (px)
  double min_depth_m = 0.3;              // nearest depth tested (m)
  double max_depth_m = 0;                // farthest; 0 = 1.5 x the largest camera baseline
  double min_view_fraction = 0.75;       // of the other views seeing the point, in foreground
  int min_views_seeing = 2;              // a depth counts only when this many others see it
                                         // (capped at views - 1)
  int consistency_dilation_px = 1;       // dilation of the other views' masks (reduced px)
  double min_consistent_fraction = 0.3;  // a component is kept above this consistent share
  bool carve_pixels = false;             // also drop inconsistent pixels in kept components

  void Check() const;  // throws u4d::Error naming the offending field
};

// People instances (step 4: DetectPeople, AddDetectedPeople, the per-view split).
struct PeopleOptions {
  bool use_hog = true;             // split/confirm components with HOG people boxes
  double hog_threshold = 0.0;      // HOG SVM hit threshold (higher: fewer boxes)
  int min_person_height_px = 96;   // upscale so that people this tall fit 128 px windows
  int hog_max_side = 800;          // longest side at which HOG runs (downscale above)
  bool require_detection = false;  // drop components with no HOG box
  int group_radius_px = 0;         // fragments closer than this are one instance; 0 = h/100
  double box_min_coverage = 0.25;  // HOG boxes with less foreground get GrabCut (below)
  // Where HOG boxes with little foreground get GrabCut (AddDetectedPeople).
  enum class BoxFill { kNever, kEmptyViews, kAlways };
  BoxFill box_fill = BoxFill::kEmptyViews;  // kEmptyViews: views with < 1 instance of foreground
  int grabcut_box_iterations = 3;           // GrabCut iterations in such boxes (>= 1)
  // Step 4b: where boxes get GrabCut, boxes of people that two views' boxes
  // place on the floor replace the single-view boxes (PeopleFromBoxes).
  bool boxes_from_views = true;         // calibrated views confirm and complete boxes
  double views_hog_threshold = -0.5;    // HOG threshold of the boxes other views confirm
  double foot_max_gap_m = 0.2;          // two views' foot rays of one person pass this close
  double floor_tolerance_m = 0.25;      // their meeting points are this close to the floor
  double person_radius_m = 0.35;        // a person's cylinder (m): feet of one person
  double person_height_m = 2.0;         // a person's cylinder height (m)
  bool split_by_profile = true;         // split wide components at column-profile valleys
  double profile_valley_ratio = 0.3;    // valley < this * the smaller neighbouring peak
  double min_instance_fraction = 5e-4;  // instances smaller than this * area are dropped
  int grabcut_iterations = 0;           // cv::grabCut iterations per instance; 0 = off
  int grabcut_max_side = 400;           // instance box is downscaled to this side for GrabCut

  void Check() const;  // throws u4d::Error naming the offending field
};

// Still subjects (step 5: RemoveGhosts, FillStillSubjects; needs BackgroundModel::envelope).
struct StillOptions {
  int still_grabcut_iterations = 3;  // GrabCut iterations in the envelope's hull; 0 = off
  double envelope_dilation = 0.02;   // envelope dilation before its hull (x image height)
  double envelope_ring = 0.04;       // probable-background ring around the hull (x height)
  int still_max_side = 400;          // GrabCut runs with the image's longest side at most this
  bool still_require_model = true;   // add only where the background model shows the subject
  bool carve_still_fill = true;      // keep filled pixels only where cross-view consistent
  bool remove_ghosts = true;         // drop ghost components (RemoveGhosts) before step 5
  double ghost_edge_ratio = 0.5;     // ghost: outline gradient in the image < this x in
                                     // the model (0.5: the model's edge is clearly stronger)

  void Check() const;  // throws u4d::Error naming the offending field
};

// People on the ground plane (step 6, SeparatePeopleOnGround); replaces
// step 4's per-view split when at least occupancy_min_views cameras are given.
struct GroundOptions {
  bool enabled = true;                     // run step 6 (else step 4 splits each view)
  int occupancy_min_views = 3;             // cameras needed; also views that must see a voxel
  int occupancy_max_side = 320;            // longest image side at which voxels are tested (px)
  int occupancy_cells = 128;               // cells per side of the cubic grid
  double occupancy_extent = 0.8;           // grid half-size: this x median camera distance to
                                           // the rig centre
  double min_column_height_m = 0.3;        // lower columns are floor, shadow, clutter (m)
  double min_person_height_m = 1.0;        // a person's highest column reaches this (m)
  double previous_radius_m = 0.3;          // a previous person's position holds a candidate
                                           // within this (m; SeparatePeopleOnGround)
  double min_lone_height_m = 0.6;          // a lower region touching none that tall is a person
                                           // when it reaches this (m)
  double person_smoothing_m = 0.1;         // Gaussian sigma on the height map (m)
  double person_saddle_ratio = 0.7;        // regions merge above this x the lower peak
  double min_exclusive_share = 0.3;        // phantoms: no view has this share of its rays alone
  double min_split_share = 0.25;           // an instance merges a second person nearest on this
                                           // x as many of its rays as its own person
  double instance_split_view_share = 0.5;  // a candidate k instances hold in this share of the
                                           // views holding it is k touching people; 0 = off
  double min_split_exclusive_share = 0.5;  // ... kept when each part is alone on this share of
                                           // its rays in some view (0 = always kept)
  double occupancy_fill_fraction = 0.03;   // pixels missing an id take the nearest within
                                           // this x image height, else are dropped

  void Check() const;  // throws u4d::Error naming the offending field
};

// The options of the unsupervised chain, one struct per step.
struct InitOptions {
  ForegroundOptions foreground;
  CrossViewOptions cross_view;
  PeopleOptions people;
  StillOptions still;
  GroundOptions ground;

  void Check() const;  // each step's Check()
};

// Step 2: CV_8UC1 mask (255 = foreground) of a BGR image against its view's
// background. Throws on an empty image, a non-BGR image or a size mismatch.
cv::Mat ForegroundMask(const cv::Mat& image_bgr, const BackgroundModel& background,
                       const InitOptions& options = {});

// Step 3: the masks (CV_8UC1, one per view, same sizes as the cameras) with
// the cross-view-inconsistent foreground removed. `consistent_share`
// (optional) receives per view the share of foreground pixels consistent at
// the reduced resolution. Throws on size mismatches or fewer than 2 views.
std::vector<cv::Mat> CrossViewConsistentMasks(const std::vector<Camera>& cameras,
                                              const std::vector<cv::Mat>& masks,
                                              const InitOptions& options = {},
                                              std::vector<double>* consistent_share = nullptr);

// Step 4: HOG people boxes (pixels of `image_bgr`) with their SVM scores.
struct PersonBox {
  cv::Rect box;
  double score = 0;
};
std::vector<PersonBox> DetectPeople(const cv::Mat& image_bgr, const InitOptions& options = {});

// Box fill names: "never", "empty-views", "always" (throws on another).
PeopleOptions::BoxFill BoxFillFromString(const std::string& name);

// Step 4a: the foreground plus, in every HOG box whose foreground covers
// less than box_min_coverage of it (a person standing still is part of the
// background), what cv::grabCut finds in the box: probable foreground in its
// central half and on the existing foreground, probable background in the
// rest of the box, background in a margin around it. Cleaned as step 2.
// Only as box_fill says: never, always, or (kEmptyViews) when `foreground`
// holds less than min_instance_fraction of the image.
cv::Mat AddDetectedPeople(const cv::Mat& image_bgr, const cv::Mat& foreground,
                          const std::vector<PersonBox>& boxes, const InitOptions& options = {});

// Step 4b (two or more calibrated views): people standing on the floor,
// from the detector's boxes of all views. A box's foot point (its bottom
// centre, raised by 1/16 of its height: HOG boxes hold a margin below the
// feet, boxes that cut a person short have none) casts a ray; two rays of
// different views that pass within foot_max_gap_m of each other, in front
// of both cameras, meet at the feet of one person. The floor is the median
// height (along RigUpDirection) of the meeting points; points farther than
// floor_tolerance_m from it pair different people (the rays of two people
// seen one behind the other from opposite sides cross below the floor) and
// are dropped. The rest are projected onto the floor and clustered
// greedily: the point with the most others within person_radius_m is a
// person at their mean, those points are used up, and so on. One view's
// false box meets another view's ray only by chance, so a box that no other
// view confirms makes no person; a person one view's detector missed still
// gets a box there (BoxesOfPeople). Throws when cameras and boxes differ in
// number; no people for fewer than 2 views.
struct FloorPerson {
  Eigen::Vector3d foot = Eigen::Vector3d::Zero();  // world, on the floor
  int num_views = 0;                               // views whose boxes meet there
};
std::vector<FloorPerson> PeopleFromBoxes(const std::vector<Camera>& cameras,
                                         const std::vector<std::vector<PersonBox>>& boxes,
                                         const InitOptions& options = {});
// Per view, the box of each person whose feet it sees: the bounding box of
// an upright cylinder of person_radius_m and person_height_m standing on
// the foot point (score: FloorPerson::num_views), clipped to the image.
std::vector<std::vector<PersonBox>> BoxesOfPeople(const std::vector<Camera>& cameras,
                                                  const std::vector<FloorPerson>& people,
                                                  const InitOptions& options = {});

// Step 5a: ghosts out of the foreground. Where a subject stood in most of
// the background's frames but no longer does, the uncovered background
// differs from the model and is foreground ("ghost"). A real object's
// outline is an edge of the image; a ghost's outline is an edge of the
// background model (the subject who was there) while the image shows the
// continuing background. A connected component of `foreground` whose mean
// gradient magnitude (Sobel of the grey image) on the band just inside its
// outline (2 px per 360 px of height) is below ghost_edge_ratio x that of
// the background model is removed. `ghosts` (optional) receives the removed
// pixels. Throws on a non-BGR image or sizes that differ.
cv::Mat RemoveGhosts(const cv::Mat& image_bgr, const cv::Mat& foreground,
                     const BackgroundModel& background, const InitOptions& options = {},
                     cv::Mat* ghosts = nullptr);

// Step 5b: the foreground plus the still parts of subjects that moved only
// partly (in the background model, so not found by step 2). Per connected
// component of the background's envelope (dilated by envelope_dilation x
// height) that this frame's foreground touches, its convex hull is the region
// that may hold a subject staying in place. cv::grabCut, at a resolution of at
// most still_max_side, is seeded with: sure foreground = `foreground`,
// probable foreground = the hulls, probable background = a ring of
// envelope_ring x height around them, sure background elsewhere (in a box
// around the ring). Its colour models (5-component GMMs) are learnt from the
// sure pixels only, a first cut is made with them frozen, then
// still_grabcut_iterations - 1 rounds of GrabCut's usual alternation. With
// still_require_model a pixel is added only if the same cut on the
// background model image (final colour models, frozen) also calls it
// foreground: the subject is missing from step 2 only where the model shows
// it. What is found inside the hulls is added; the result is cleaned as step
// 2. Returns `foreground` unchanged when the background has no envelope, the
// envelope or the foreground is empty, fewer than 50 sure pixels of either
// kind exist, or still_grabcut_iterations is 0. Deterministic (fixed seed
// for GrabCut's k-means). Throws on a non-BGR image or sizes that differ.
cv::Mat FillStillSubjects(const cv::Mat& image_bgr, const cv::Mat& foreground,
                          const BackgroundModel& background, const InitOptions& options = {});

// Step 6: people separated on a ground-plane occupancy map of all views
// (docs/init.md). Per time step, a cubic voxel grid (occupancy_cells per
// side, half-size occupancy_extent x the median distance of the cameras to
// the point nearest their optical axes) with two axes on the ground plane
// (orthogonal to RigUpDirection). A voxel is occupied when it falls in the
// (dilated, occupancy_max_side resolution) foreground of at least
// min_view_fraction of the views whose image it is in, and at least
// min(occupancy_min_views, views) views see it. The height of each ground
// column (occupied voxels x cell) is smoothed (person_smoothing_m); columns
// at least min_column_height_m high climb it to a local maximum, and the
// regions so formed merge where their saddle is at least
// person_saddle_ratio of the lower peak (legs, arms; the floor between two
// people is lower). A region is a candidate when its highest column reaches
// min_person_height_m (flat shadows and floor patches are not). Phantoms
// (where silhouette cones of different people cross) go: every ray through
// a phantom also crosses a real person, so the candidate whose best view
// has the smallest share of its rays crossing no other candidate is dropped
// while that share is below min_exclusive_share. People who touch are one
// candidate on the map but separate instances in the views that see them
// apart (given masks, instances_are_people): a candidate that k instances hold in at least
// instance_split_view_share of the views where any instance holds it (two
// views at least) is split into k people (its columns
// clustered on the ground, seeded at its highest column and the columns
// farthest from it; an instance holds the candidate its rays meet first
// most often, on at least min_split_share x as many rays as the instance
// holding it most in that view); the rays are then cast again. A share, not
// a count: a detector may split one person in a view, and a person's
// silhouette cone, fat where few views carve it, can meet first the rays of
// another person behind it in a few views. The split is undone unless every
// part is then alone on at least min_split_exclusive_share of its rays in
// some view (the phantom test's share, RemovePhantoms, with a stricter
// bound): people who touch are seen apart from some side, while a cone fat
// enough to meet the other person's instance cuts one person into parts
// that overlap in every view.
// Then per view, `instances` (step 4's ids) are the units: instances and
// people are paired one to one, largest count first, by rays whose nearest
// person is that person, then (people still unpaired) by rays crossing
// them; a paired instance in which another person is the nearest on at
// least min_split_share x as many rays as its own, and on more rays than in
// any instance that person already holds (its pair, which may be a scrap of
// it the detector kept apart, or an instance split before), is split by
// each pixel's nearest person; other instances take the person nearest on
// most of their rays; instances no ray of which meets a person, and pixels
// farther than occupancy_fill_fraction x height from any ray that meets one,
// become background. Ids are the same person in every view of the time step
// (ordered along the grid's first axis, then second, of their peaks), not
// across time steps.
struct OccupancyMap {
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();  // world up (RigUpDirection)
  Eigen::Vector3d axis_a, axis_b;                 // ground axes: grid columns, rows
  Eigen::Vector3d origin;                         // world position of the grid's corner
  double cell_m = 0;                              // cell size (m)
  int cells = 0;                                  // cells per side
  cv::Mat height;                                 // CV_32FC1 cells x cells: occupied m per column
  cv::Mat people;                                 // CV_16UC1: person id per column (0 = none)
  int num_people = 0;
  std::vector<double> exclusive_share;     // per id (index 0 unused): best view's share of
                                           // the person's rays that cross no other person
  std::vector<Eigen::Vector3d> positions;  // per id (index 0 unused): height-weighted ground
                                           // position (world), for the next frame
};
// `instances`: CV_16UC1 per view at its camera's size (0 = background; one
// id per view for a plain foreground mask). Returns CV_16UC1 person ids per
// view; `map` (optional) receives the grid. `previous_people` (optional):
// the previous frame's people (OccupancyMap::positions, world); a region of
// the map that holds two or more of them (within previous_radius_m) is split
// between them, each column to the nearest, so that people who touch stay
// apart when they were apart before. `instances_are_people`: the instances
// are per-person detections (given masks), not step 4's heuristic splits
// (HOG boxes, column-profile valleys, which cut one person in several views
// at once); only then is a candidate they hold apart split by them
// (instance_split_view_share). Throws on a wrong type or size, fewer than 2
// views, or cameras that all sit at one point.
std::vector<cv::Mat> SeparatePeopleOnGround(
    const std::vector<Camera>& cameras, const std::vector<cv::Mat>& instances,
    const InitOptions& options = {}, OccupancyMap* map = nullptr,
    const std::vector<Eigen::Vector3d>& previous_people = {}, bool instances_are_people = false);
// Whether UnsupervisedInstanceMasks runs step 6 with this many calibrated
// cameras (its ids are then alike across views).
bool UsesGroundOccupancy(const InitOptions& options, int num_cameras);
// World "up" of a rig whose images are upright (no roll: every camera's x
// axis is horizontal): the direction most nearly orthogonal to all x axes,
// signed like the mean of the cameras' -y axes; that mean itself when all x
// axes are parallel. Throws on no cameras.
Eigen::Vector3d RigUpDirection(const std::vector<Camera>& cameras);

// Step 4: instance ids (CV_16UC1, 1..n left to right) from a foreground mask
// and the image; `boxes` as from DetectPeople (may be empty).
cv::Mat SplitInstances(const cv::Mat& image_bgr, const cv::Mat& foreground,
                       const std::vector<PersonBox>& boxes, const InitOptions& options = {});

// The whole chain for one time step: cameras[v], images_t[v] (BGR) and
// backgrounds[v] per view; cameras may be empty (no cross-view check).
// `keys` (empty, or one per view): a view whose key is `keyed` takes its
// step-2 foreground from ChromaKeyMask (chroma_key.h; cleaned as step 2)
// instead of its background, which may then be empty, and skips steps 5a
// and 5b (they need a background model); the other steps are alike.
// Returns CV_16UC1 ids per view (0 = background, 1..n per view).
std::vector<cv::Mat> UnsupervisedInstanceMasks(const std::vector<Camera>& cameras,
                                               const std::vector<cv::Mat>& images_t,
                                               const std::vector<BackgroundModel>& backgrounds,
                                               const InitOptions& options = {},
                                               const std::vector<ChromaKey>& keys = {});

// The ids as an InstanceMask (class "person", score 1 for every id present),
// ready for WriteInstanceMask.
InstanceMask ToInstanceMask(const cv::Mat& ids);

}  // namespace u4d
