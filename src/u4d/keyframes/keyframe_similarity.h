// Key-frame similarity and key-frame detection (paper Sec. 2.1.3, Eq. for
// KS_ij, "Long-term temporal coherence").
//
//   KS_ij = 1 - 1/(5 N_v) sum_{c=1..N_v} (M^c_ij + L^c_ij + D^c_ij + P^c_ij + I^c_ij)
//
// with five per-view dissimilarities in [0, 1]. The paper defines them in its
// Appendix B, which is not available; the definitions here are our own and
// are written out precisely in docs/keyframes.md:
//   M  sparse correspondence: 1 - Dice overlap of the feature tracks on
//      objects present at i and at j: 1 - 2 n_ij / (n_i + n_j)
//   L  semantic: 1 - weighted Jaccard of the per-class instance counts
//   D  distance: mean over matched objects of min(1, centroid shift /
//      (distance_scale * image diagonal)); an unmatched object counts 1
//   P  pose: mean over matched people of min(1, root-relative MPJPE /
//      pose_scale_m); an unmatched person counts 1 (view-independent)
//   I  shape: mean over matched objects of 1 - IoU of the silhouettes after
//      aligning their centroids; an unmatched object counts 1
// Switching a term off (KeyframeOptions::use_*) drops it and divides by the
// number of terms left instead of 5, so KS stays in [0, 1]; with all five on
// and view_median off this is exactly the paper's equation. With view_median
// (the default) KS_ij is the median over the views c of
// 1 - (M^c_ij + L^c_ij + D^c_ij + P^c_ij + I^c_ij) / 5. KS_ii = 1.
//
// Selection: frames i, j are similar when KS_ij > threshold (0.75, the
// paper's). Greedy cover (KeyframeSelectOptions): repeatedly the frame whose
// choice raises the frames' similarity to their best key-frame the most
// (ties: the earlier frame) becomes a key-frame, until every frame is
// similar to one; then each key-frame moves to the medoid of its members.
// Each frame is assigned to the key-frame it is most similar to among those
// it is similar to (its "own" key-frame), and to the temporal segment s with
// K_s <= t < K_{s+1} (frames before K_0 join segment 0); N_f^s is the number
// of frames of segment s.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/features/temporal_tracks.h"
#include "u4d/io/capture.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/poses.h"

namespace u4d {

// What the similarity looks at, for frames 0..num_frames-1 of a sequence.
struct KeyframeObservations {
  int num_frames = 0;
  // masks[view][frame]: instance masks; an empty `ids` means nothing detected.
  std::vector<std::vector<InstanceMask>> masks;
  // poses[frame]: 3D poses (may be empty: then P is 0 for every pair).
  std::vector<std::vector<Pose3d>> poses;
  // Temporal tracks (temporal_tracks.h); M uses the feature tracks only.
  std::vector<TemporalTrack> tracks;

  int NumViews() const { return static_cast<int>(masks.size()); }
  // Throws u4d::Error when masks is not [views][num_frames], a non-empty mask
  // is not CV_16UC1 or differs in size from the view's other masks, or poses
  // is neither empty nor num_frames long.
  void Check() const;
};

struct KeyframeOptions {
  double threshold = 0.75;         // frames are similar when KS > threshold (paper: 0.75)
  bool use_correspondence = true;  // term M
  bool use_semantic = true;        // term L
  bool use_distance = true;        // term D
  bool use_pose = true;            // term P
  bool use_shape = true;           // term I
  // D saturates (= 1) at a centroid shift of this fraction of the image diagonal.
  double distance_scale = 0.25;
  // P saturates at this root-relative MPJPE (metres); see docs/keyframes.md.
  double pose_scale_m = 0.3;
  // Two poses with fewer common joints (confidence > 0) count as dissimilar (P = 1).
  int min_common_joints = 8;
  // KS_ij is the median over the views of each view's own KS (1 minus the
  // mean of its terms), not the mean over the views of the paper's
  // equation: a detector that misses, merges or cuts an object in one view
  // at one frame makes that view's terms jump to 1 for the pair although
  // the scene did not change, and the median outvotes it (docs/keyframes.md).
  bool view_median = true;

  int NumTerms() const;  // the terms switched on
  void Check() const;    // throws on a threshold outside [0, 1], no term, bad scales
};

// The five per-view terms of one frame pair, each in [0, 1].
struct KeyframeTerms {
  double m = 0, l = 0, d = 0, p = 0, i = 0;
};

// The terms of frames (i, j) in `view`.
KeyframeTerms KeyframeTermsAt(const KeyframeObservations& obs, int view, int i, int j,
                              const KeyframeOptions& options = {});

// The symmetric N_f x N_f matrix KS (Eq. KS_ij), ones on the diagonal.
Eigen::MatrixXd KeyframeSimilarityMatrix(const KeyframeObservations& obs,
                                         const KeyframeOptions& options = {});

// Each term summed over the views, divided by N_v: symmetric N_f x N_f
// matrices with zeros on the diagonal. A term switched off in `options` is
// not computed (its matrix is zero). For ablations: KS for any subset of the
// terms is CombineKeyframeTerms of one computation.
struct KeyframeTermMatrices {
  Eigen::MatrixXd m, l, d, p, i;
};
KeyframeTermMatrices ComputeKeyframeTermMatrices(const KeyframeObservations& obs,
                                                 const KeyframeOptions& options = {});
// KS = 1 - (sum of the terms switched on in `options`) / options.NumTerms(),
// ones on the diagonal; equal to KeyframeSimilarityMatrix without
// view_median (the median is taken per view, before any mean).
Eigen::MatrixXd CombineKeyframeTerms(const KeyframeTermMatrices& terms,
                                     const KeyframeOptions& options = {});

struct KeyframeSelection {
  double threshold = 0.75;
  std::vector<int> keyframes;        // increasing frame indices
  std::vector<int> frame_keyframe;   // per frame: its own key-frame (a frame index)
  std::vector<int> frame_segment;    // per frame: segment s, K_s <= t < K_{s+1}
  std::vector<int> segment_lengths;  // N_f^s, one per key-frame
  Eigen::MatrixXd similarity;        // KS
};

// How key-frames are chosen among the frames (docs/keyframes.md, "Key-frame
// selection", says why the default).
enum class KeyframeCover {
  // Greedy set cover by count: the frame similar to the most uncovered frames
  // first. Kept for comparison: it picks "hub" frames similar to many frames
  // just above the threshold, whose members are not alike.
  kCount,
  // Greedy facility location: the frame whose choice raises the members'
  // similarity to their key-frame the most, sum_t max(0, KS_kt - best_t),
  // where best_t is the threshold for a frame not yet covered; until every
  // frame is covered. The default.
  kSimilarity,
};

struct KeyframeSelectOptions {
  double threshold = 0.75;  // frames are similar when KS > threshold (paper: 0.75)
  KeyframeCover cover = KeyframeCover::kSimilarity;  // how key-frames are picked
  // After the cover, each key-frame is moved to the medoid of its members
  // (the frame similar to all of them with the largest summed KS to them),
  // a key-frame left alone and similar to another key-frame is dropped, and
  // the frames are re-assigned, until nothing changes (at most this many
  // rounds; 0 = no refinement).
  int medoid_rounds = 10;

  void Check() const;  // throws on a threshold outside [0, 1] or negative rounds
};

// Key-frames covering every frame (see the top of this file and
// KeyframeSelectOptions). Throws when `similarity` is not square or empty.
KeyframeSelection SelectKeyframes(const Eigen::MatrixXd& similarity,
                                  const KeyframeSelectOptions& options);
// The same with the default options and the given threshold.
KeyframeSelection SelectKeyframes(const Eigen::MatrixXd& similarity, double threshold = 0.75);

// Key-frames chosen within each shot, the frames [shot_starts[i],
// shot_starts[i + 1]) (shot_starts increasing, the first 0): a capture cut in
// time (io/capture.h, ContinuesFrom) has no segment spanning a cut. The
// similarity across shots is set to zero. One shot gives SelectKeyframes.
KeyframeSelection SelectKeyframesInShots(Eigen::MatrixXd similarity,
                                         const std::vector<int>& shot_starts,
                                         const KeyframeSelectOptions& options);

// keyframes.json: {"format": "u4d-keyframes", "threshold", "num_frames",
// "keyframes", "frame_keyframe", "frame_segment", "segment_lengths",
// "similarity": [[...] per frame]}. Read throws naming the file on a wrong
// format, inconsistent lengths or out-of-range frames.
void WriteKeyframes(const fs::path& path, const KeyframeSelection& selection);
KeyframeSelection ReadKeyframes(const fs::path& path);

}  // namespace u4d
