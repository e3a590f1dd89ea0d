// Sparse temporal tracks (paper Sec. 2.1.3) against the exact GT of a
// synthetic capture: track points must follow the GT forward flow.
#include "u4d/features/temporal_tracks.h"

#include <unistd.h>

#include <map>
#include <set>

#include <gtest/gtest.h>

#include "u4d/eval/track_metrics.h"
#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/testing/capture_inputs.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

class TemporalTracksTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test_util::RemovedAtExit(synth::WriteCaptureToTempDir(
        "temporal_tracks_test", synth::SmallHandshakeOptions(3, 480, 270, 6)));
    capture_ = ReadCapture(dir_);
    for (int f = 0; f < capture_.num_frames; ++f) {
      poses_.push_back(ReadPoses3d(dir_ / layout::GtJoints3d(f)));
    }
    tracks_ = ComputeTemporalTracks(capture_, poses_, TemporalTrackOptions{}, 0, -1, &stats_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static inline fs::path dir_;
  static inline Capture capture_;
  static inline std::vector<std::vector<Pose3d>> poses_;
  static inline std::vector<TemporalTrack> tracks_;
  static inline TrackStats stats_;
};

// The target: >= 95% of the tracked displacements agree with the GT
// flow to within 2 px (composed for non-consecutive frames). 2 px is the
// target's own tolerance; SIFT localisation on these renders is well below it.
TEST_F(TemporalTracksTest, TracksFollowGroundTruthFlow) {
  const TrackPrecision p = EvaluateTracksWithGtFlow(capture_, tracks_, 2.0);
  std::printf("evaluated %ld pairs (%ld consecutive), precision %.4f (consecutive %.4f)\n",
              p.evaluated, p.consecutive_evaluated, p.Precision(),
              p.consecutive_evaluated
                  ? static_cast<double>(p.consecutive_correct) / p.consecutive_evaluated
                  : 0.0);
  ASSERT_GT(p.evaluated, 200);  // enough pairs for the share to mean something
  EXPECT_GE(p.Precision(), 0.95);
}

// Every person gets a non-trivial number of feature tracks in every view where
// it is visible. The object of a track is taken from the GT instances (the
// majority GT id under its points), so merged or missed initial masks do not
// blur the count. The floor of 15 is an order of magnitude below the paper's
// per-object track counts, low enough for a person ~100 px tall at 480x270.
TEST_F(TemporalTracksTest, EveryObjectHasTracks) {
  std::map<std::pair<int, int>, int> per_object;  // (view, GT instance) -> feature tracks
  int background = 0, on_object = 0;
  for (const TemporalTrack& t : tracks_) {
    if (t.from_joint) continue;
    EXPECT_GE(t.points.size(), 2u);
    for (size_t q = 1; q < t.points.size(); ++q)
      EXPECT_LT(t.points[q - 1].first, t.points[q].first);
    std::map<int, int> votes;
    for (const auto& [frame, px] : t.points) {
      const cv::Mat ids =
          ReadLabelImage(dir_ / layout::GtInstances(capture_.views[t.view].name, frame));
      ++votes[ids.at<uint16_t>(static_cast<int>(std::lround(px.y())),
                               static_cast<int>(std::lround(px.x())))];
    }
    const int id = std::max_element(votes.begin(), votes.end(), [](auto& a, auto& b) {
                     return a.second < b.second;
                   })->first;
    if (id == 0) {
      ++background;
    } else {
      ++on_object;
      ++per_object[{t.view, id}];
    }
  }
  for (const auto& [key, n] : per_object) {
    std::printf("view %d GT instance %d: %d tracks\n", key.first, key.second, n);
  }
  std::printf("tracks on people %d, on the background (dilation band) %d\n", on_object, background);
  for (int v = 0; v < capture_.NumViews(); ++v) {
    for (int id = 1; id <= 2; ++id) {
      EXPECT_GE((per_object[{v, id}]), 15) << "view " << v << " person " << id;
    }
  }
  EXPECT_GT(on_object, background);
}

// The symmetry test removes one-way matches that the ratio test alone keeps.
TEST_F(TemporalTracksTest, SymmetryTestRemovesOneWayMatches) {
  std::printf("frame pairs %d, one-way %ld, symmetric %ld, dropped components %d\n",
              stats_.frame_pairs, stats_.one_way_matches, stats_.symmetric_matches,
              stats_.dropped_components);
  EXPECT_GT(stats_.one_way_matches, stats_.symmetric_matches);
  EXPECT_GT(stats_.symmetric_matches, 0);
  // Without the test, the one-way tracks are no more precise.
  TemporalTrackOptions one_way;
  one_way.symmetry_test = false;
  one_way.add_joint_tracks = false;
  TrackStats s;
  const auto tracks = ComputeTemporalTracks(capture_, {}, one_way, 0, -1, &s);
  EXPECT_EQ(s.one_way_matches, s.symmetric_matches);  // nothing removed when switched off
  EXPECT_EQ(s.one_way_matches, stats_.one_way_matches);
  const double p_one = EvaluateTracksWithGtFlow(capture_, tracks, 2.0).Precision();
  const double p_sym = EvaluateTracksWithGtFlow(capture_, tracks_, 2.0).Precision();
  std::printf("precision one-way %.4f, symmetric %.4f\n", p_one, p_sym);
  EXPECT_GE(p_sym, p_one);
}

// Joint tracks: one per (person, joint) and view, each point exactly the
// projection of the GT joint at that frame.
TEST_F(TemporalTracksTest, JointTracksAreProjectedJoints) {
  int n = 0;
  for (const TemporalTrack& t : tracks_) {
    if (!t.from_joint) continue;
    ++n;
    ASSERT_GE(t.joint, 0);
    for (const auto& [frame, px] : t.points) {
      const Pose3d* pose = nullptr;
      for (const Pose3d& p : poses_[frame]) pose = p.person_id == t.person_id ? &p : pose;
      ASSERT_NE(pose, nullptr);
      const Eigen::Vector2d expected =
          capture_.views[t.view].CameraAt(frame).Project(pose->joints[t.joint].head<3>());
      EXPECT_LT((expected - px).norm(), 1e-9);
    }
  }
  // 2 people x 17 joints x views, minus joints outside an image.
  EXPECT_GE(n, 2 * 17 * capture_.NumViews() - 4);
  EXPECT_LE(n, 2 * 17 * capture_.NumViews());
}

TEST(TemporalTrackOptionsTest, RejectsBadValues) {
  TemporalTrackOptions o;
  o.window = 0;
  EXPECT_THROW(o.Check(), Error);
  o = {};
  o.ratio = 1.5;
  EXPECT_THROW(o.Check(), Error);
  EXPECT_THROW(DetectFrameFeatures(cv::Mat(), cv::Mat(), TemporalTrackOptions{}), Error);
  EXPECT_THROW(DetectFrameFeatures(cv::Mat(10, 10, CV_8UC3), cv::Mat(5, 5, CV_16UC1),
                                   TemporalTrackOptions{}),
               Error);
}

// Matching identical frames finds only identity matches, both ways.
TEST(TemporalTracksUnitTest, IdenticalFramesMatchThemselves) {
  cv::Mat image(120, 160, CV_8UC3);
  cv::randu(image, 0, 255);
  const FrameFeatures f = DetectFrameFeatures(image, cv::Mat(), TemporalTrackOptions{});
  ASSERT_GT(f.keypoints.size(), 20u);
  MatchCounts counts;
  const auto matches = MatchFrameFeatures(f, f, TemporalTrackOptions{}, &counts);
  EXPECT_GT(matches.size(), f.keypoints.size() / 2);
  for (const cv::DMatch& m : matches) EXPECT_EQ(m.queryIdx, m.trainIdx);
}

}  // namespace
}  // namespace u4d
