// Key-frames against ground truth (paper Sec. 2.1.3, "Long-term temporal
// coherence"): on a generated handshake (approach, handshake, release, turn
// away) poses recur: the neutral stance before and after the handshake, the
// reach and the release of the hands. The key-frames computed from KS must
// group frames whose GT 3D poses are alike.
//
// GT pose distance of frames (a, b): GtPoseDistance (keyframe_eval.h), the
// root-relative MPJPE of the people in gt/joints3d matched by person_id.
#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "u4d/eval/keyframe_eval.h"
#include "u4d/io/layout.h"
#include "u4d/keyframes/keyframe_similarity.h"
#include "u4d/synth/generate.h"
#include "u4d/testing/capture_inputs.h"
#include "u4d/util/stats.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

class KeyframeGtTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    synth::SynthOptions o = synth::SmallHandshakeOptions(4, 320, 180, 40);
    o.start_frame = 0;
    o.fps = 8;
    dir_ = test_util::RemovedAtExit(synth::WriteCaptureToTempDir("keyframes_gt_test", o));
    capture_ = ReadCapture(dir_);
    for (int f = 0; f < capture_.num_frames; ++f)
      gt_poses_.push_back(ReadPoses3d(dir_ / layout::GtJoints3d(f)));
    tracks_ = ComputeTemporalTracks(capture_, {}, TemporalTrackOptions{});
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static inline fs::path dir_;
  static inline Capture capture_;
  static inline std::vector<std::vector<Pose3d>> gt_poses_;
  static inline std::vector<TemporalTrack> tracks_;
};

struct GtComparison {
  double median_all = 0;     // over all frame pairs a < b
  double median_member = 0;  // over frames t != K(t): distance of t to its own key-frame
  double median_similar = 0, median_dissimilar = 0;  // pairs with KS > / <= threshold
  int members = 0, similar = 0, dissimilar = 0;
};

GtComparison Compare(const KeyframeSelection& sel, const std::vector<std::vector<Pose3d>>& gt) {
  const int n = static_cast<int>(gt.size());
  std::vector<double> all, member, similar, dissimilar;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      const double d = GtPoseDistance(gt[a], gt[b]);
      all.push_back(d);
      (sel.similarity(a, b) > sel.threshold ? similar : dissimilar).push_back(d);
    }
  }
  for (int t = 0; t < n; ++t)
    if (sel.frame_keyframe[t] != t)
      member.push_back(GtPoseDistance(gt[t], gt[sel.frame_keyframe[t]]));
  std::string kf, fk;
  for (int k : sel.keyframes) kf += std::to_string(k) + " ";
  for (int k : sel.frame_keyframe) fk += std::to_string(k) + " ";
  GtComparison c{Median(all),
                 Median(member),
                 Median(similar),
                 Median(dissimilar),
                 static_cast<int>(member.size()),
                 static_cast<int>(similar.size()),
                 static_cast<int>(dissimilar.size())};
  std::printf(
      "key-frames [%s]\nframe -> key-frame [%s]\nGT root-relative pose distance (median): all "
      "pairs %.4f m; member -> its key-frame %.4f m (%d members); KS-similar pairs %.4f m (%d); "
      "KS-dissimilar pairs %.4f m (%d)\n",
      kf.c_str(), fk.c_str(), c.median_all, c.median_member, c.members, c.median_similar, c.similar,
      c.median_dissimilar, c.dissimilar);
  return c;
}

// The full KS (five terms) on GT masks, GT joints and SIFT tracks, as the
// pipeline computes it, and keyframes.json read back.
TEST_F(KeyframeGtTest, KeyframesJsonListsKeyframesAndMembers) {
  const KeyframeObservations obs = ReadKeyframeObservations(capture_, true, tracks_);
  const KeyframeSelection sel = SelectKeyframes(KeyframeSimilarityMatrix(obs), 0.75);
  const fs::path path = dir_ / "keyframes.json";
  WriteKeyframes(path, sel);
  const KeyframeSelection back = ReadKeyframes(path);
  ASSERT_FALSE(back.keyframes.empty());
  EXPECT_EQ(back.keyframes, sel.keyframes);
  ASSERT_EQ(back.frame_keyframe.size(), static_cast<size_t>(capture_.num_frames));
  for (int k : back.keyframes) {
    EXPECT_EQ(back.frame_keyframe[k], k) << "a key-frame is its own key-frame";
    int members = 0;
    for (int t = 0; t < capture_.num_frames; ++t) members += back.frame_keyframe[t] == k;
    std::printf("key-frame %d: %d frames\n", k, members);
  }
  for (int t = 0; t < capture_.num_frames; ++t) {
    const int k = back.frame_keyframe[t];
    EXPECT_TRUE(std::find(back.keyframes.begin(), back.keyframes.end(), k) != back.keyframes.end())
        << "frame " << t << " lists " << k << ", not a key-frame";
    EXPECT_TRUE(k == t || back.similarity(t, k) > back.threshold) << "frame " << t;
  }
}

// KS against GT pose: the pairs KS calls similar must be closer in GT pose
// than those it calls dissimilar. This holds without tuning because P is a
// monotone function of exactly this distance and the image terms (D, I, M)
// grow with the body's change of shape; frames of the walk away (turning,
// 0.1-0.25 m from the standing frames) are both far in GT and below 0.75.
TEST_F(KeyframeGtTest, SimilarPairsAreCloserInGtPose) {
  const KeyframeObservations obs = ReadKeyframeObservations(capture_, true, tracks_);
  const GtComparison c = Compare(SelectKeyframes(KeyframeSimilarityMatrix(obs), 0.75), gt_poses_);
  ASSERT_GT(c.similar, 0);
  ASSERT_GT(c.dissimilar, 0);
  EXPECT_LT(c.median_similar, c.median_dissimilar);
  // Without the pose term (image evidence only: not circular with the GT joints).
  KeyframeOptions no_pose;
  no_pose.use_pose = false;
  const GtComparison d =
      Compare(SelectKeyframes(KeyframeSimilarityMatrix(obs, no_pose), 0.75), gt_poses_);
  EXPECT_LT(d.median_similar, d.median_dissimilar);
}

// The criterion: key-frames stand for frames whose poses recur.
// Measured with means (keyframe_eval.h) on the full KS (GT masks, GT joints,
// SIFT tracks), default selection:
//  1. members are, on average, less than half as far in GT pose from their
//     key-frame as random frame pairs are (0.5: a key-frame must represent
//     its members clearly better than an arbitrary frame of the sequence
//     would; "below chance" alone would accept a selection that barely uses
//     the similarity);
//  2. members are closer to their key-frame than with the same number of
//     key-frames placed by time alone (equal temporal segments, their middle
//     frames): the selection must gain from the image and pose evidence,
//     not only from temporal proximity (the count cover fails this,
//     docs/keyframes.md);
//  3. some frames are sent back to a key-frame more than the track window
//     (10 frames) away, i.e. to an earlier occurrence of their pose, and
//     these recurrences are closer in GT pose than random pairs (no margin:
//     they are few, and "closer than chance" is what shows a real
//     recurrence);
//  4. members are closer than with the former selection (below).
TEST_F(KeyframeGtTest, MembersAreCloserToTheirKeyframeThanRandomPairs) {
  const KeyframeObservations obs = ReadKeyframeObservations(capture_, true, tracks_);
  const KeyframeSelection sel = SelectKeyframes(KeyframeSimilarityMatrix(obs), 0.75);
  Compare(sel, gt_poses_);
  const KeyframeGtEvaluation e = EvaluateKeyframesWithGtPoses(sel, GtPoseDistanceMatrix(gt_poses_));
  std::printf(
      "mean GT pose distance: member -> key-frame %.4f m (%d members, max %.4f), random pairs "
      "%.4f m (ratio %.2f), uniform temporal key-frames %.4f m, recurrences (> 10 frames) %d at "
      "%.4f m\n",
      e.mean_member, e.members, e.max_member, e.mean_all, e.MemberRatio(), e.mean_member_uniform,
      e.recurring_members, e.mean_recurring);
  ASSERT_GT(e.members, 0);
  EXPECT_LT(e.mean_member, 0.5 * e.mean_all);
  EXPECT_LT(e.mean_member, e.mean_member_uniform);
  ASSERT_GT(e.recurring_members, 0);
  EXPECT_LT(e.mean_recurring, e.mean_all);

  // 4. The former selection (greedy cover by count, no medoids) on the same
  // KS, for the record; the default must beat it (the reason it changed).
  KeyframeSelectOptions former;
  former.cover = KeyframeCover::kCount;
  former.medoid_rounds = 0;
  const KeyframeGtEvaluation f = EvaluateKeyframesWithGtPoses(
      SelectKeyframes(sel.similarity, former), GtPoseDistanceMatrix(gt_poses_));
  std::printf("former count cover: %d key-frames, member -> key-frame %.4f m\n", f.num_keyframes,
              f.mean_member);
  EXPECT_LT(e.mean_member, f.mean_member);
}

// The detector's masks (the capture's masks/: merged, missed, cut, dilated
// instances) against the true ones: the KS from the detector's masks should
// be the KS of the true masks, since the scene is the same. A detector error
// in one view at one frame sends that view's terms to 1 for the pair; the
// median over the views (KeyframeOptions::view_median) outvotes it, the
// paper's mean does not. Without poses (image evidence only).
TEST_F(KeyframeGtTest, TheMedianOverViewsKeepsTheTrueMasksSimilarityUnderDetectorErrors) {
  KeyframeObservations truth = ReadKeyframeObservations(capture_, true, tracks_);
  KeyframeObservations detector = ReadKeyframeObservations(capture_, false, tracks_);
  truth.poses.clear();
  detector.poses.clear();
  const auto error = [&](bool median) {
    KeyframeOptions o;
    o.view_median = median;
    const Eigen::MatrixXd ks_truth = KeyframeSimilarityMatrix(truth, o);
    const Eigen::MatrixXd ks_detector = KeyframeSimilarityMatrix(detector, o);
    const int n = capture_.num_frames;
    return (ks_detector - ks_truth).cwiseAbs().sum() / (n * (n - 1));
  };
  const double mean_error = error(false), median_error = error(true);
  std::printf(
      "mean |KS(detector masks) - KS(true masks)| over frame pairs: %.4f with the mean "
      "over views, %.4f with the median\n",
      mean_error, median_error);
  EXPECT_LT(median_error, mean_error);
}

}  // namespace
}  // namespace u4d
