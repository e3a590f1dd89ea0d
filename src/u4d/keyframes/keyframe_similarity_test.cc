// Key-frame similarity KS_ij and key-frame selection (paper Sec. 2.1.3)
// against sequences with known structure: per-term values computed by hand,
// a sequence whose pose recurs, and a generated handshake capture with GT.
#include "u4d/keyframes/keyframe_similarity.h"

#include <unistd.h>

#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/synth/rig.h"
#include "u4d/testing/capture_inputs.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

InstanceMask Mask(int w, int h, const std::vector<std::pair<int, cv::Rect>>& boxes,
                  const std::string& label = "person") {
  InstanceMask m;
  m.ids = cv::Mat::zeros(h, w, CV_16UC1);
  for (const auto& [id, box] : boxes) {
    m.ids(box).setTo(id);
    m.instances.push_back({id, label, 1.0});
  }
  return m;
}

KeyframeObservations TwoFrames(InstanceMask a, InstanceMask b) {
  KeyframeObservations obs;
  obs.num_frames = 2;
  obs.masks = {{std::move(a), std::move(b)}};
  return obs;
}

// ---- Each term on inputs with a value known by hand ----

TEST(KeyframeTermsTest, ShiftedSquareHasDistanceButNoShapeChange) {
  // 200x150 image, diagonal 250 px; D saturates at 0.25 * 250 = 62.5 px.
  const auto obs =
      TwoFrames(Mask(200, 150, {{1, {20, 20, 30, 30}}}), Mask(200, 150, {{1, {45, 20, 30, 30}}}));
  const KeyframeTerms t = KeyframeTermsAt(obs, 0, 0, 1);
  EXPECT_NEAR(t.d, 25.0 / 62.5, 1e-9);
  EXPECT_NEAR(t.i, 0.0, 1e-9);  // identical shape once centroids are aligned
  EXPECT_NEAR(t.l, 0.0, 1e-9);
  EXPECT_NEAR(t.p, 0.0, 1e-9);  // no poses given
  EXPECT_NEAR(t.m, 1.0, 1e-9);  // no tracks: no evidence of correspondence
  EXPECT_EQ(KeyframeTermsAt(obs, 0, 1, 1).d, 0.0);
}

TEST(KeyframeTermsTest, ShapeIsOneMinusAlignedIoU) {
  // 20x20 square vs 40x20 rectangle with the same centre: IoU = 400 / 800.
  const auto obs =
      TwoFrames(Mask(200, 150, {{1, {50, 50, 20, 20}}}), Mask(200, 150, {{1, {40, 50, 40, 20}}}));
  EXPECT_NEAR(KeyframeTermsAt(obs, 0, 0, 1).i, 0.5, 1e-9);
}

TEST(KeyframeTermsTest, SemanticIsJaccardOfClassCounts) {
  // {person, person} vs {person}: 1 - 1/2; the missing person also counts 1 in D and I.
  const auto obs = TwoFrames(Mask(200, 150, {{1, {10, 10, 20, 20}}, {2, {100, 10, 20, 20}}}),
                             Mask(200, 150, {{1, {10, 10, 20, 20}}}));
  const KeyframeTerms t = KeyframeTermsAt(obs, 0, 0, 1);
  EXPECT_NEAR(t.l, 0.5, 1e-9);
  EXPECT_NEAR(t.d, 0.5, 1e-9);
  EXPECT_NEAR(t.i, 0.5, 1e-9);
  const auto cars = TwoFrames(Mask(200, 150, {{1, {10, 10, 20, 20}}}, "car"),
                              Mask(200, 150, {{1, {10, 10, 20, 20}}}, "person"));
  EXPECT_NEAR(KeyframeTermsAt(cars, 0, 0, 1).l, 1.0, 1e-9);
}

TEST(KeyframeTermsTest, CorrespondenceIsOneMinusDiceOfTracks) {
  auto obs =
      TwoFrames(Mask(200, 150, {{1, {10, 10, 50, 50}}}), Mask(200, 150, {{1, {10, 10, 50, 50}}}));
  // Frame 0 has 4 tracks, frame 1 has 4; 2 are shared: 1 - 2*2/8 = 0.5.
  auto track = [](std::vector<int> frames) {
    TemporalTrack t;
    t.view = 0;
    t.instance = 1;
    for (int f : frames) t.points.push_back({f, Eigen::Vector2d(20, 20)});
    return t;
  };
  obs.tracks = {track({0, 1}), track({0, 1}), track({0}), track({0}), track({1}), track({1})};
  TemporalTrack joint = track({0});
  joint.from_joint = true;  // joint tracks are not counted
  obs.tracks.push_back(joint);
  EXPECT_NEAR(KeyframeTermsAt(obs, 0, 0, 1).m, 0.5, 1e-9);
}

Pose3d StandingPose(int id, bool arms_up_knee_raised) {
  Pose3d p;
  p.person_id = id;
  using namespace h36m17;
  auto set = [&](int j, double x, double y, double z) { p.joints[j] = {x, y, z, 1.0}; };
  set(kPelvis, 0, 1.0, 0);
  set(kRightHip, -0.1, 1.0, 0);
  set(kRightKnee, -0.1, 0.55, 0);
  set(kRightAnkle, -0.1, 0.1, 0);
  set(kLeftHip, 0.1, 1.0, 0);
  set(kLeftKnee, 0.1, 0.55, 0);
  set(kLeftAnkle, 0.1, 0.1, 0);
  set(kSpine, 0, 1.25, 0);
  set(kThorax, 0, 1.5, 0);
  set(kNeck, 0, 1.6, 0);
  set(kHead, 0, 1.72, 0);
  set(kLeftShoulder, 0.2, 1.5, 0);
  set(kRightShoulder, -0.2, 1.5, 0);
  if (!arms_up_knee_raised) {
    set(kLeftElbow, 0.22, 1.22, 0);
    set(kLeftWrist, 0.24, 0.95, 0);
    set(kRightElbow, -0.22, 1.22, 0);
    set(kRightWrist, -0.24, 0.95, 0);
  } else {
    set(kLeftElbow, 0.25, 1.78, 0);
    set(kLeftWrist, 0.27, 2.05, 0);
    set(kRightElbow, -0.25, 1.78, 0);
    set(kRightWrist, -0.27, 2.05, 0);
    set(kRightKnee, -0.1, 0.85, 0.35);
    set(kRightAnkle, -0.1, 0.45, 0.4);
  }
  return p;
}

TEST(KeyframeTermsTest, PoseIsSaturatedRootRelativeMpjpe) {
  KeyframeObservations obs = TwoFrames(InstanceMask{}, InstanceMask{});
  Pose3d a = StandingPose(1, false), b = a;
  for (auto& j : b.joints) j.head<3>() += Eigen::Vector3d(1.0, 0, 0.5);  // translation only
  obs.poses = {{a}, {b}};
  EXPECT_NEAR(KeyframeTermsAt(obs, 0, 0, 1).p, 0.0, 1e-9);
  b = a;
  for (int j = 1; j < 17; ++j) b.joints[j].x() += 0.15;  // 16 of 17 joints moved 0.15 m
  obs.poses = {{a}, {b}};
  EXPECT_NEAR(KeyframeTermsAt(obs, 0, 0, 1).p, 16 * 0.15 / 17 / 0.3, 1e-9);
  obs.poses = {{a}, {}};  // the person is gone: fully dissimilar
  EXPECT_NEAR(KeyframeTermsAt(obs, 0, 0, 1).p, 1.0, 1e-9);
}

// ---- A sequence whose pose recurs ----
// Frames 0-3 pose A (arms down), 4-7 pose B (arms up, knee raised), 8-11 pose
// A again, with 5 mm joint noise, seen by two cameras. Silhouettes are the
// skeleton's bones drawn 10 px thick; feature tracks are points on the bones,
// one track per bone point and per stretch of frames in which its bone keeps
// its configuration (what exhaustive matching within the window would link:
// local appearance only recurs when the bone's pose recurs).
struct RecurringSequence {
  KeyframeObservations obs;
  std::vector<bool> pose_b;  // per frame
};

RecurringSequence MakeRecurringSequence() {
  const int n = 12, w = 320, h = 240;
  const std::vector<std::pair<int, int>> bones = {
      {0, 1}, {1, 2},  {2, 3},  {0, 4},   {4, 5},   {5, 6},  {0, 7},   {7, 8},
      {8, 9}, {9, 10}, {8, 11}, {11, 12}, {12, 13}, {8, 14}, {14, 15}, {15, 16}};
  std::vector<Camera> cams;
  for (double deg : {90.0, 40.0}) {
    const double a = deg * M_PI / 180;
    cams.push_back(synth::MakeLookAtCamera({4 * std::cos(a), 1.2, 4 * std::sin(a)}, {0, 1.0, 0},
                                           {0, 1, 0}, w, h, 60.0));
  }
  RecurringSequence seq;
  seq.obs.num_frames = n;
  seq.obs.masks.resize(cams.size());
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.005);
  const Pose3d a = StandingPose(1, false), b = StandingPose(1, true);
  for (int f = 0; f < n; ++f) {
    const bool is_b = f >= 4 && f < 8;
    seq.pose_b.push_back(is_b);
    Pose3d p = is_b ? b : a;
    for (auto& j : p.joints) j.head<3>() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    seq.obs.poses.push_back({p});
    for (size_t v = 0; v < cams.size(); ++v) {
      InstanceMask m;
      m.ids = cv::Mat::zeros(h, w, CV_16UC1);
      m.instances = {{1, "person", 1.0}};
      for (const auto& [j0, j1] : bones) {
        const Eigen::Vector2d p0 = cams[v].Project(p.joints[j0].head<3>());
        const Eigen::Vector2d p1 = cams[v].Project(p.joints[j1].head<3>());
        cv::line(m.ids, cv::Point(p0.x(), p0.y()), cv::Point(p1.x(), p1.y()), cv::Scalar(1), 10);
      }
      const Eigen::Vector2d head = cams[v].Project(p.joints[h36m17::kHead].head<3>());
      cv::circle(m.ids, cv::Point(head.x(), head.y()), 12, cv::Scalar(1), cv::FILLED);
      seq.obs.masks[v].push_back(m);
    }
  }
  // Feature tracks: 4 points per bone; a bone that differs between A and B
  // gets one track over the A frames and one over the B frames.
  for (size_t v = 0; v < cams.size(); ++v) {
    for (const auto& [j0, j1] : bones) {
      const bool moves =
          (a.joints[j0] - b.joints[j0]).norm() + (a.joints[j1] - b.joints[j1]).norm() > 0;
      for (int s = 1; s <= 4; ++s) {
        for (int group = 0; group < (moves ? 2 : 1); ++group) {
          TemporalTrack t;
          t.view = static_cast<int>(v);
          t.instance = 1;
          for (int f = 0; f < n; ++f) {
            if (moves && seq.pose_b[f] != (group == 1)) continue;
            const Pose3d& p = seq.obs.poses[f][0];
            const Eigen::Vector3d x = p.joints[j0].head<3>() +
                                      s / 5.0 * (p.joints[j1].head<3>() - p.joints[j0].head<3>());
            t.points.push_back({f, cams[v].Project(x)});
          }
          seq.obs.tracks.push_back(t);
        }
      }
    }
  }
  return seq;
}

TEST(KeyframeRecurrenceTest, RecurringPoseIsSimilarDifferentPoseIsNot) {
  const RecurringSequence seq = MakeRecurringSequence();
  const Eigen::MatrixXd ks = KeyframeSimilarityMatrix(seq.obs);
  std::printf("KS(1,9) recurrence %.3f, KS(1,5) different %.3f, KS(5,6) same %.3f\n", ks(1, 9),
              ks(1, 5), ks(5, 6));
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < 12; ++j) {
      if (seq.pose_b[i] == seq.pose_b[j]) {
        EXPECT_GT(ks(i, j), 0.75) << i << "," << j;
      } else {
        EXPECT_LT(ks(i, j), 0.75) << i << "," << j;
      }
    }
  }
  const KeyframeSelection sel = SelectKeyframes(ks, 0.75);
  ASSERT_EQ(sel.keyframes.size(), 2u);
  // One key-frame per pose; the recurrence (frames 8-11) goes back to pose A's key-frame.
  EXPECT_NE(seq.pose_b[sel.keyframes[0]], seq.pose_b[sel.keyframes[1]]);
  for (int t = 0; t < 12; ++t) {
    EXPECT_EQ(seq.pose_b[sel.frame_keyframe[t]], seq.pose_b[t]) << "frame " << t;
  }
}

// A "hub" frame similar to every frame just above the threshold, and two
// tight groups of frames (KS 0.95 inside a group, 0.5 across). The count cover
// takes the hub (it covers the most frames) and leaves both groups under a
// key-frame they are barely similar to; the similarity cover gives each group
// a key-frame of its own (which also covers the hub).
TEST(KeyframeSelectionTest, SimilarityCoverAvoidsHubFrames) {
  const int n = 9, hub = 4;
  Eigen::MatrixXd ks = Eigen::MatrixXd::Constant(n, n, 0.5);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      if (a == b)
        ks(a, b) = 1;
      else if (a == hub || b == hub)
        ks(a, b) = 0.76;
      else if ((a < hub) == (b < hub))
        ks(a, b) = 0.95;
    }
  }
  KeyframeSelectOptions count;
  count.cover = KeyframeCover::kCount;
  count.medoid_rounds = 0;
  EXPECT_EQ(SelectKeyframes(ks, count).keyframes, std::vector<int>{hub});
  const KeyframeSelection sel = SelectKeyframes(ks, 0.75);
  // One key-frame per group; the hub is similar to both and joins one.
  ASSERT_EQ(sel.keyframes.size(), 2u);
  EXPECT_LT(sel.keyframes[0], hub);
  EXPECT_GT(sel.keyframes[1], hub);
  for (int t = 0; t < n; ++t) {
    if (t != hub) {
      EXPECT_EQ(sel.frame_keyframe[t] < hub, t < hub) << "frame " << t;
    }
  }
  KeyframeSelectOptions bad;
  bad.medoid_rounds = -1;
  EXPECT_THROW(SelectKeyframes(ks, bad), Error);
}

// Frames 0-5 all alike, cut in two shots at frame 3: no segment spans the
// cut, each shot has its own key-frame, the similarity across is zero; one
// shot is SelectKeyframes itself.
TEST(KeyframeSelectionTest, NoSegmentSpansACut) {
  const int n = 6, cut = 3;
  const Eigen::MatrixXd ks = Eigen::MatrixXd::Constant(n, n, 0.9);
  EXPECT_EQ(SelectKeyframes(ks, 0.75).keyframes.size(), 1u);
  const KeyframeSelection sel = SelectKeyframesInShots(ks, {0, cut}, KeyframeSelectOptions{});
  ASSERT_EQ(sel.keyframes.size(), 2u);
  EXPECT_LT(sel.keyframes[0], cut);
  EXPECT_GE(sel.keyframes[1], cut);
  EXPECT_EQ(sel.segment_lengths, (std::vector<int>{cut, n - cut}));
  for (int t = 0; t < n; ++t) {
    EXPECT_EQ(sel.frame_segment[t], t < cut ? 0 : 1) << "frame " << t;
    EXPECT_EQ(sel.frame_keyframe[t] < cut, t < cut) << "frame " << t;
    for (int u = 0; u < n; ++u)
      EXPECT_EQ(sel.similarity(t, u), (t < cut) == (u < cut) ? ks(t, u) : 0.0);
  }
  const KeyframeSelection one = SelectKeyframesInShots(ks, {0}, KeyframeSelectOptions{});
  EXPECT_EQ(one.keyframes, SelectKeyframes(ks, 0.75).keyframes);
  EXPECT_EQ(one.frame_segment, SelectKeyframes(ks, 0.75).frame_segment);
  EXPECT_THROW(SelectKeyframesInShots(ks, {1, 3}, KeyframeSelectOptions{}), Error);
  EXPECT_THROW(SelectKeyframesInShots(ks, {0, 3, 3}, KeyframeSelectOptions{}), Error);
  EXPECT_THROW(SelectKeyframesInShots(ks, {0, n}, KeyframeSelectOptions{}), Error);
}

// ---- A generated handshake with GT masks, GT joints and SIFT tracks ----

class KeyframeCaptureTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    synth::SynthOptions o = synth::SmallHandshakeOptions(2, 320, 180, 48);
    o.start_frame = 0;  // from the approach through the handshake
    o.fps = 8;          // the whole 6 s script (approach, handshake, stepping apart)
    dir_ = test_util::RemovedAtExit(synth::WriteCaptureToTempDir("keyframes_test", o));
    const Capture capture = ReadCapture(dir_);
    std::vector<std::vector<Pose3d>> poses;
    for (int f = 0; f < capture.num_frames; ++f)
      poses.push_back(ReadPoses3d(dir_ / layout::GtJoints3d(f)));
    obs_ = ReadKeyframeObservations(capture, true,
                                    ComputeTemporalTracks(capture, poses, TemporalTrackOptions{}));
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static inline fs::path dir_;
  static inline KeyframeObservations obs_;
};

TEST_F(KeyframeCaptureTest, SelectionCoversEveryFrameAndRoundTrips) {
  const KeyframeSelection sel = SelectKeyframes(KeyframeSimilarityMatrix(obs_), 0.75);
  ASSERT_FALSE(sel.keyframes.empty());
  int total = 0;
  for (int n : sel.segment_lengths) total += n;
  EXPECT_EQ(total, obs_.num_frames);
  for (int t = 0; t < obs_.num_frames; ++t) {
    const int k = sel.frame_keyframe[t];
    EXPECT_TRUE(k == t || sel.similarity(t, k) > 0.75) << "frame " << t;
    EXPECT_LE(sel.keyframes[sel.frame_segment[t]], std::max(t, sel.keyframes[0]));
  }
  // Neighbouring frames (1/8 s apart) stay similar: a person moves < 0.2 m and
  // changes pose little in 1/8 s, so every term stays well below its saturation.
  for (int t = 0; t + 1 < obs_.num_frames; ++t) EXPECT_GT(sel.similarity(t, t + 1), 0.75);
  const fs::path path = dir_ / "keyframes.json";
  WriteKeyframes(path, sel);
  const KeyframeSelection back = ReadKeyframes(path);
  EXPECT_EQ(back.keyframes, sel.keyframes);
  EXPECT_EQ(back.frame_keyframe, sel.frame_keyframe);
  EXPECT_EQ(back.frame_segment, sel.frame_segment);
  EXPECT_LT((back.similarity - sel.similarity).cwiseAbs().maxCoeff(), 1e-9);
  WriteTextFileAtomic(path, R"({"format": "u4d-keyframes", "threshold": 0.75, "num_frames": 2,
    "keyframes": [5], "frame_keyframe": [0, 0], "frame_segment": [0, 0],
    "segment_lengths": [2], "similarity": [[1, 0], [0, 1]]})");
  EXPECT_THROW(ReadKeyframes(path), Error);  // key-frame 5 of 2 frames
}

// The term matrices recombine into exactly KeyframeSimilarityMatrix with
// the paper's mean over the views, for every subset used by the ablation.
TEST_F(KeyframeCaptureTest, CombinedTermsEqualTheSimilarityMatrix) {
  const KeyframeTermMatrices terms = ComputeKeyframeTermMatrices(obs_);
  for (int off = 0; off < 2; ++off) {
    KeyframeOptions o;
    o.view_median = false;
    o.use_shape = off == 0;
    const double diff =
        (CombineKeyframeTerms(terms, o) - KeyframeSimilarityMatrix(obs_, o)).cwiseAbs().maxCoeff();
    EXPECT_LT(diff, 1e-12);
  }
}

// Ablation: what switching off each term changes (printed; the assertion is
// only the direction that follows from the definition: dropping a term that
// is >= the mean of the others can only raise KS).
TEST_F(KeyframeCaptureTest, AblationOfTheFiveTerms) {
  const char* names[] = {"all", "-M", "-L", "-D", "-P", "-I"};
  for (int off = 0; off < 6; ++off) {
    KeyframeOptions o;
    if (off == 1) o.use_correspondence = false;
    if (off == 2) o.use_semantic = false;
    if (off == 3) o.use_distance = false;
    if (off == 4) o.use_pose = false;
    if (off == 5) o.use_shape = false;
    const Eigen::MatrixXd ks = KeyframeSimilarityMatrix(obs_, o);
    const KeyframeSelection sel = SelectKeyframes(ks, o.threshold);
    std::string kf, len;
    for (int k : sel.keyframes) kf += std::to_string(k) + " ";
    for (int n : sel.segment_lengths) len += std::to_string(n) + " ";
    std::printf("%-4s mean KS %.3f  key-frames [%s] segment lengths [%s]\n", names[off], ks.mean(),
                kf.c_str(), len.c_str());
  }
  KeyframeOptions no_m;
  no_m.use_correspondence = false;
  // Within one view the M term is the largest for far-apart frames (tracks
  // live within the 10-frame window), so dropping it raises far-apart KS.
  const Eigen::MatrixXd all = KeyframeSimilarityMatrix(obs_),
                        without = KeyframeSimilarityMatrix(obs_, no_m);
  EXPECT_GT(without(0, obs_.num_frames - 1), all(0, obs_.num_frames - 1));
}

TEST(KeyframeOptionsTest, RejectsBadInput) {
  KeyframeOptions o;
  o.use_correspondence = o.use_semantic = o.use_distance = o.use_pose = o.use_shape = false;
  EXPECT_THROW(o.Check(), Error);
  o = {};
  o.threshold = 1.5;
  EXPECT_THROW(o.Check(), Error);
  KeyframeObservations obs;
  obs.num_frames = 3;
  obs.masks = {{InstanceMask{}}};  // 1 mask for 3 frames
  EXPECT_THROW(KeyframeSimilarityMatrix(obs), Error);
  EXPECT_THROW(SelectKeyframes(Eigen::MatrixXd(2, 3)), Error);
}

}  // namespace
}  // namespace u4d
