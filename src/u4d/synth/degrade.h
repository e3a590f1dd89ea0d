// Degraded initial inputs: turns perfect ground truth (GT instance maps, part
// maps, 3D COCO keypoints) into what a real detector would give U4D as its
// *initial* inputs — Mask R-CNN-like instance masks and OpenPose-like 2D
// keypoints — with realistic, controllable errors that the core must repair.
//
// Everything is seeded and deterministic: the same inputs, options and seed
// give bit-identical outputs on every run. The random numbers are our own
// (splitmix64, Box-Muller), not std:: distributions, so they do not depend on
// the standard library either. Each GT instance / person draws from its own
// sub-stream (seed mixed with its id), so turning one degradation on or off
// does not reshuffle the errors of the others. Callers give a distinct seed per
// view and frame, e.g. DegradeSeed(base, view, frame). Errors are independent
// between frames unless the caller keeps a DetectorMemory per view and the
// options give a persistence (a detector that merges two touching people, or
// misses one, tends to do so for several frames).
//
// What each degradation does and the preset strengths: docs/synthetic.md,
// section "Degraded initial inputs".
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/poses.h"

namespace u4d::synth {

// A well-mixed seed for (base, view, frame): distinct for distinct triples.
uint64_t DegradeSeed(uint64_t base, int view, int frame);

// ---------------------------------------------------------------- masks --

struct MaskDegradeOptions {
  // Probability that the whole view-frame has no detections at all (the
  // detector output for this image is missing): the result is `dropped`, with
  // an all-zero id image and no instances.
  double frame_drop_prob = 0.02;
  // Probability that a true instance (or merged group) is not detected.
  double instance_miss_prob = 0.02;

  // Boundary error: the boundary of every detected mask moves along its normal
  // by a smooth random field n(p) (Gaussian, zero mean), i.e. a spatially
  // correlated erosion (n < 0) / dilation (n > 0). The mask becomes
  // {p : signed_distance(p) + n(p) > 0}.
  // Standard deviation of n in pixels; the mean boundary displacement is
  // about 0.8 times this (E|n| = sqrt(2/pi) sigma). 0 disables.
  double boundary_amplitude_px = 2.0;
  // Correlation length of n in pixels: n is white noise on a grid with this
  // spacing, bicubically interpolated. Larger = smoother, blobbier errors.
  double boundary_correlation_px = 24.0;
  // Mask R-CNN predicts masks at low resolution: every mask is first blurred
  // with a Gaussian of this sigma (pixels) and thresholded at 0.5, which
  // rounds corners and removes structures thinner than about 2 sigma
  // (fingers, a gap between legs). 0 disables.
  double blur_sigma_px = 1.5;

  // Thin limbs: each lower arm (a connected component of forearm + hand
  // pixels of one instance in the part map) is missing from the mask with
  // this probability; likewise each lower leg (shin + foot).
  double lower_arm_drop_prob = 0.15;
  double lower_leg_drop_prob = 0.05;

  // Merging: two GT instances whose masks touch or come within
  // `merge_distance_px` pixels of each other are reported as one instance
  // with this probability (decided per such pair; chains merge transitively).
  // The gap between them is bridged (morphological closing, background only).
  double merge_prob = 0.15;
  double merge_distance_px = 3.0;
  // When the caller says which people are in contact in 3D, pairs that are
  // close in the image but not in contact (one passes behind the other) merge
  // with this probability instead. < 0: merge_prob for every close pair.
  double apart_merge_prob = -1;
  // Temporal correlation of merges, with a DetectorMemory: a pair that was
  // touching at the previous frame stays merged with this probability, and
  // becomes merged with the probability that keeps the long-run merge rate at
  // merge_prob (a two-state Markov chain). < 0: every frame independent.
  double merge_persistence = -1;
  // The same for a single GT instance missed at the previous frame
  // (instance_miss_prob is then the long-run miss rate). < 0: independent.
  double miss_persistence = -1;

  // Thin parts, from the mask alone (for people without a part map, and for
  // what a low-resolution mask head loses: forearms, hands, lower legs, a
  // hem): the parts of an instance that a morphological opening with a disc
  // of diameter thin_part_width_px removes, each connected piece of at least
  // thin_part_width_px^2 pixels missing with this probability. 0 disables.
  double thin_part_drop_prob = 0;
  double thin_part_width_px = 12.0;

  // False positives: the number of spurious "person" blobs per view-frame is
  // Poisson with this mean. Each is a noisy ellipse on background pixels with
  // semi-axes uniform in [min, max] pixels and a low score.
  double false_positive_rate = 0.1;
  double false_positive_min_radius_px = 6.0;
  double false_positive_max_radius_px = 30.0;
  double false_positive_score_min = 0.05;  // score ~ uniform [min, max]
  double false_positive_score_max = 0.5;

  // Scores: true instances ~ N(score_mean, score_std) clamped to
  // [score_min, 1]; merged instances have their mean lowered by
  // `merged_score_penalty`.
  double score_mean = 0.93;
  double score_std = 0.04;
  double score_min = 0.3;
  double merged_score_penalty = 0.25;

  // Detections with fewer pixels than this after degradation are dropped.
  int min_area_px = 16;

  // Mixed with the per-call seed; change it to get another realisation.
  uint64_t seed = 0;

  // Throws u4d::Error naming the field when a value is not finite, a
  // probability is outside [0, 1], a length is negative, or a range is empty.
  void Check() const;

  // Presets. None(): the GT unchanged (up to renumbering; scores 1).
  // Mild(): a good detector on easy images. Default(): the field values above,
  // a typical Mask R-CNN on 640-1280 px wide images. Harsh(): a weak detector
  // or crowded, low-resolution images. Realistic(): a Mask R-CNN-class
  // detector's failure modes at the rates it shows on multi-person capture
  // footage, correlated in time (docs/synthetic.md).
  static MaskDegradeOptions None();
  static MaskDegradeOptions Mild();
  static MaskDegradeOptions Default();
  static MaskDegradeOptions Harsh();
  static MaskDegradeOptions Realistic();
};

// What a detector carried over from the previous frame of one view: the GT
// pairs that were touching and which of them it merged, and the GT ids that
// were present and which of them it missed. Start empty; DegradeInstanceMask
// reads and replaces it.
struct DetectorMemory {
  std::set<std::pair<int, int>> touching, merged;
  std::set<int> present, missed;
};

struct DegradedMask {
  // Ids are renumbered 1..K in random order (a detector does not know the GT
  // ids); an instance's label is the class of its GT instance (of the one
  // with the most pixels when merged: a person holding a box is a "person"),
  // "person" without classes and for false positives. All-zero and empty
  // when dropped.
  InstanceMask mask;
  bool dropped = false;  // the whole view-frame was dropped
  // For evaluation only, parallel to mask.instances: the GT ids an instance
  // came from (one id; two or more when merged; empty for a false positive).
  std::vector<std::vector<int>> instance_gt_ids;
  // Pairs (a < b) of GT ids whose merge was decided (touching pairs only).
  std::vector<std::pair<int, int>> merged_gt_ids;
  // GT ids present in the input but in no output instance (missed, too small
  // after degradation, or every GT id when dropped). Sorted.
  std::vector<int> missed_gt_ids;
  int dropped_limbs = 0;    // lower arms / legs removed
  int false_positives = 0;  // spurious blobs added
};

// Degrades one GT instance map.
// gt_ids: CV_16UC1, 0 = background, other values = GT instance ids.
// parts: CV_8UC1 of the same size with BodyPart values (scene.h), or empty
//   for "no part map" (then no limb is ever dropped).
// seed: per view-frame (see DegradeSeed), mixed with options.seed.
// memory: the view's DetectorMemory (updated), or null for independent frames.
// contacts: pairs (a < b) of GT ids in contact in 3D (synth/contact.h), or
// null when unknown (see apart_merge_prob).
// classes: the class of each GT id, or null when all are people.
// Throws u4d::Error on an empty or wrongly typed image, mismatched sizes, a
// part value outside BodyPart, or invalid options.
DegradedMask DegradeInstanceMask(const cv::Mat& gt_ids, const cv::Mat& parts,
                                 const MaskDegradeOptions& options, uint64_t seed,
                                 DetectorMemory* memory = nullptr,
                                 const std::vector<std::pair<int, int>>* contacts = nullptr,
                                 const std::map<int, std::string>* classes = nullptr);

// ------------------------------------------------------------ keypoints --

// COCO-17 keypoint order: coco17::Keypoint (io/poses.h).

struct KeypointDegradeOptions {
  // Gaussian pixel noise, standard deviation per coordinate.
  double noise_sigma_px = 2.0;
  // Gross errors: with this probability a keypoint lands uniformly within
  // `outlier_radius_px` of its true position instead (wrong limb, clutter).
  double outlier_prob = 0.01;
  double outlier_radius_px = 40.0;
  // Probability that a visible keypoint is not detected (confidence 0).
  double keypoint_miss_prob = 0.05;
  // Probability that a whole person is not detected.
  double person_miss_prob = 0.03;
  // Probability of a whole-body left/right swap (every L/R pair exchanged) for
  // a person seen from the front, and for one seen from behind (the person's
  // left shoulder projects left of the right shoulder), where OpenPose
  // confuses the sides far more often.
  double swap_prob = 0.02;
  double swap_prob_from_behind = 0.15;
  // Occlusion by another person, decided from the GT instance map: a keypoint
  // whose projected pixel belongs to a different instance is missed with
  // `occluded_miss_prob`; otherwise its confidence is multiplied by
  // `occluded_confidence_scale` and its noise sigma by `occluded_noise_scale`.
  double occluded_miss_prob = 0.5;
  double occluded_confidence_scale = 0.35;
  double occluded_noise_scale = 2.0;
  // Confidence of a detected keypoint ~ N(mean, std) clamped to [0.05, 1].
  double confidence_mean = 0.8;
  double confidence_std = 0.1;
  // A person with fewer detected keypoints than this is not reported.
  int min_keypoints = 3;
  // Mixed with the per-call seed.
  uint64_t seed = 0;

  // Throws u4d::Error naming the field on a non-finite value, a probability
  // outside [0, 1], a negative length, or a bad confidence range.
  void Check() const;

  // Presets, as for MaskDegradeOptions: None() = exact projections with
  // confidence 1 (only out-of-image / behind-camera keypoints are missed);
  // Default() = the field values above.
  static KeypointDegradeOptions None();
  static KeypointDegradeOptions Mild();
  static KeypointDegradeOptions Default();
  static KeypointDegradeOptions Harsh();
};

struct DetectedPose2d {
  // (x, y, confidence) in COCO-17 order, pixels per docs/conventions.md;
  // (0, 0, 0) = not detected.
  std::array<Eigen::Vector3d, coco17::kNumKeypoints> keypoints;
  double score = 0;      // mean confidence over the 17 keypoints
  int gt_person = -1;    // index into the input, for evaluation only
  bool swapped = false;  // left/right labels exchanged
};

// Projects each person's 3D COCO keypoints (world, metres) into `camera` and
// degrades them. Person i has GT instance id i + 1 in `gt_ids` (as in
// SceneFrame). Keypoints behind the camera or outside the
// image (before or after noise) are not detected. Returns the detected people sorted by decreasing
// score. gt_ids: CV_16UC1 of the camera's size. Throws u4d::Error on a bad camera, a wrongly typed
// / sized gt_ids, a non-finite keypoint, or invalid options.
std::vector<DetectedPose2d> DegradeKeypoints(
    const std::vector<std::array<Eigen::Vector3d, coco17::kNumKeypoints>>& coco_keypoints_3d,
    const Camera& camera, const cv::Mat& gt_ids, const KeypointDegradeOptions& options,
    uint64_t seed);

}  // namespace u4d::synth
