// Tests of multi-view association and triangulation (multiview_pose.h):
// exact synthetic projections (noise-free: the answer is known to rounding),
// then a generated capture with detector-like 2D keypoints and GT joints.
#include "u4d/pose/multiview_pose.h"

#include <unistd.h>

#include <map>
#include <set>

#include <gtest/gtest.h>

#include "u4d/io/capture.h"
#include "u4d/io/layout.h"
#include "u4d/pose/pose_tracking.h"
#include "u4d/synth/generate.h"
#include "u4d/synth/rig.h"
#include "u4d/util/check.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

std::vector<Camera> RingCameras(int n, int width, int height) {
  std::vector<Camera> cams;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    cams.push_back(synth::MakeLookAtCamera(
        Eigen::Vector3d(4.5 * std::cos(a), 1.6, 4.5 * std::sin(a)), Eigen::Vector3d(0, 1, 0),
        Eigen::Vector3d(0, 1, 0), width, height, 60));
  }
  return cams;
}

// A COCO-17 "person" (plausible layout, y up) standing at (x, 0, z).
std::array<Eigen::Vector3d, 17> Person(double x, double z) {
  const double y[17] = {1.65, 1.7, 1.7,  1.68, 1.68, 1.45, 1.45, 1.15, 1.15,
                        0.9,  0.9, 0.95, 0.95, 0.5,  0.5,  0.08, 0.08};
  const double dx[17] = {0,    0.03,  -0.03, 0.08, -0.08, 0.2,  -0.2, 0.25, -0.25,
                         0.28, -0.28, 0.1,   -0.1, 0.1,   -0.1, 0.1,  -0.1};
  std::array<Eigen::Vector3d, 17> p;
  for (int k = 0; k < 17; ++k) p[k] = Eigen::Vector3d(x + dx[k], y[k], z + (k == 0 ? 0.1 : 0.0));
  return p;
}

Pose2d Project(const std::array<Eigen::Vector3d, 17>& pts, const Camera& cam) {
  Pose2d p;
  for (int k = 0; k < 17; ++k) p.keypoints[k] << cam.Project(pts[k]), 0.9;
  p.score = 0.9;
  return p;
}

TEST(MultiViewPose, MirrorIsAnInvolutionThatSwapsSides) {
  Keypoints2d k;
  for (int i = 0; i < 17; ++i) k[i] = Eigen::Vector3d(i, 0, 1);
  const Keypoints2d m = MirrorCoco17(k);
  EXPECT_EQ(m[coco17::kNose].x(), coco17::kNose);
  EXPECT_EQ(m[coco17::kLeftWrist].x(), coco17::kRightWrist);
  EXPECT_EQ(m[coco17::kRightAnkle].x(), coco17::kLeftAnkle);
  const Keypoints2d mm = MirrorCoco17(m);
  for (int i = 0; i < 17; ++i) EXPECT_EQ(mm[i], k[i]);
}

TEST(MultiViewPose, ExactProjectionsOfTwoPeopleAreAssociatedAndTriangulated) {
  const std::vector<Camera> cams = RingCameras(4, 640, 360);
  const auto a = Person(-0.5, 0.2), b = Person(0.6, -0.3);
  std::vector<std::vector<Pose2d>> poses(4);
  for (int v = 0; v < 4; ++v) {
    // Different detection order per view, a swapped person in view 2 and a
    // gross outlier keypoint in view 1.
    Pose2d pa = Project(a, cams[v]), pb = Project(b, cams[v]);
    if (v == 2) pa.keypoints = MirrorCoco17(pa.keypoints);
    if (v == 1) pb.keypoints[coco17::kLeftWrist].head<2>() += Eigen::Vector2d(60, -40);
    if (v % 2)
      poses[v] = {pb, pa};
    else
      poses[v] = {pa, pb};
  }
  const std::vector<MultiViewPerson> people = EstimateMultiViewPoses(poses, cams);
  ASSERT_EQ(people.size(), 2u);
  for (const MultiViewPerson& p : people) {
    for (int v = 0; v < 4; ++v) EXPECT_GE(p.detections[v], 0) << "view " << v;
    // Which truth: the one the pelvis is closest to.
    const auto& truth =
        (p.coco[coco17::kLeftHip].head<3>() - a[coco17::kLeftHip]).norm() < 0.3 ? a : b;
    for (int k = 0; k < 17; ++k) {
      ASSERT_GT(p.coco[k].w(), 0) << "joint " << k;
      // Exact data: only rounding remains (1e-6 m is far above double
      // rounding and far below any real error).
      EXPECT_LT((p.coco[k].head<3>() - truth[k]).norm(), 1e-6) << "joint " << k;
    }
    if (&truth == &a) {
      EXPECT_TRUE(p.mirrored[2]);
      EXPECT_FALSE(p.mirrored[0]);
    }
  }
}

TEST(MultiViewPose, BadInputThrows) {
  const std::vector<Camera> cams = RingCameras(2, 320, 180);
  EXPECT_THROW(TriangulatePoses({{}, {}, {}}, cams), Error);
  MultiViewPoseOptions o;
  o.min_views = 1;
  EXPECT_THROW(TriangulatePoses({{}, {}}, cams, o), Error);
}

// Generated handshake capture: 6 views at 320x180, detector-like keypoints
// (2 px noise, misses, outliers, left/right swaps), GT joints.
class SyntheticPoseTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test_util::RemovedAtExit(synth::WriteCaptureToTempDir(
        "pose_test", synth::SmallHandshakeOptions(6, 320, 180, kFrames)));
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static constexpr int kFrames = 10;
  static inline fs::path dir_;
};

TEST_F(SyntheticPoseTest, MpjpeOnLimbJointsAndStableIds) {
  const Capture capture = ReadCapture(dir_);
  ASSERT_EQ(capture.num_frames, kFrames);
  // Joints whose definition is the same in the synthetic GT and in
  // H36m17FromCoco17: hips, knees, ankles, shoulders, elbows, wrists (the GT
  // head is the top of the head and its neck the base of the head, while
  // COCO-built head/neck are the ear centre and mid thorax-head).
  const int kCompared[12] = {h36m17::kRightHip,      h36m17::kRightKnee,  h36m17::kRightAnkle,
                             h36m17::kLeftHip,       h36m17::kLeftKnee,   h36m17::kLeftAnkle,
                             h36m17::kLeftShoulder,  h36m17::kLeftElbow,  h36m17::kLeftWrist,
                             h36m17::kRightShoulder, h36m17::kRightElbow, h36m17::kRightWrist};
  PoseTrackerState tracker;
  double raw_sum = 0, tracked_sum = 0;
  int raw_n = 0, tracked_n = 0;
  std::map<int, std::set<int>> track_ids_of_gt;
  for (int f = 0; f < kFrames; ++f) {
    std::vector<std::vector<Pose2d>> poses;
    std::vector<Camera> cams;
    for (const CaptureView& v : capture.views) {
      cams.push_back(v.CameraAt(f));
      poses.push_back(ReadPoses2d(dir_ / layout::Poses2d(v.name, f)));
    }
    const std::vector<Pose3d> raw = TriangulatePoses(poses, cams);
    const std::vector<Pose3d> tracked = UpdatePoseTracks(tracker, raw);
    const std::vector<Pose3d> gt = ReadPoses3d(dir_ / layout::GtJoints3d(f));
    ASSERT_EQ(gt.size(), 2u);
    EXPECT_EQ(raw.size(), 2u) << "frame " << f;
    for (const Pose3d& g : gt) {
      // Nearest prediction by mean compared-joint distance.
      auto nearest = [&](const std::vector<Pose3d>& pred, double* sum, int* n) {
        int best = -1;
        double best_d = 1e9;
        for (size_t i = 0; i < pred.size(); ++i) {
          double d = 0;
          int c = 0;
          for (int k : kCompared) {
            if (pred[i].joints[k].w() <= 0 || g.joints[k].w() <= 0) continue;
            d += (pred[i].joints[k].head<3>() - g.joints[k].head<3>()).norm();
            ++c;
          }
          if (c > 0 && d / c < best_d) {
            best_d = d / c;
            best = static_cast<int>(i);
          }
        }
        if (best < 0 || best_d > 0.5) return -1;
        for (int k : kCompared) {
          if (pred[best].joints[k].w() <= 0 || g.joints[k].w() <= 0) continue;
          *sum += (pred[best].joints[k].head<3>() - g.joints[k].head<3>()).norm();
          ++*n;
        }
        return best;
      };
      const int r = nearest(raw, &raw_sum, &raw_n);
      const int t = nearest(tracked, &tracked_sum, &tracked_n);
      EXPECT_GE(r, 0) << "GT person " << g.person_id << " not found in frame " << f;
      ASSERT_GE(t, 0) << "GT person " << g.person_id << " not tracked in frame " << f;
      track_ids_of_gt[g.person_id].insert(tracked[t].person_id);
    }
  }
  // Every compared joint of both people in every frame, most of them found.
  EXPECT_GT(raw_n, 0.9 * kFrames * 2 * 12);
  const double raw_mpjpe = raw_sum / raw_n, tracked_mpjpe = tracked_sum / tracked_n;
  std::printf("synthetic MPJPE over %d limb joints: raw %.1f mm, tracked %.1f mm\n", raw_n,
              1000 * raw_mpjpe, 1000 * tracked_mpjpe);
  // Expected error: sigma 2 px at depth ~4.5 m with f = 160 / tan(30 deg) =
  // 277 px is 3.2 cm per view and axis; 6 views 60 deg apart see each
  // horizontal axis from ~3 views (1.9 cm), the vertical from all 6 (1.3 cm):
  // ~2.9 cm RMS in 3D. Keypoints occluded in the handshake have twice the
  // noise and fewer views, so the bound is 4.5 cm (1.5x); one wrong
  // association or unhandled left/right swap moves ~12 joints by 10-40 cm
  // and exceeds it. (Measured: raw 34.0 mm, tracked 27.3 mm. With 4 views
  // the opposite camera pairs are degenerate for 2-view joints, and one
  // frame's swapped view is not caught: raw 52 mm.)
  EXPECT_LT(raw_mpjpe, 0.045);
  EXPECT_LT(tracked_mpjpe, 0.045);
  // Stable identities: each GT person always has the same track id, and the
  // two people have different ones.
  ASSERT_EQ(track_ids_of_gt.size(), 2u);
  for (const auto& [gt_id, ids] : track_ids_of_gt) EXPECT_EQ(ids.size(), 1u) << "GT " << gt_id;
  EXPECT_NE(*track_ids_of_gt.begin()->second.begin(), *track_ids_of_gt.rbegin()->second.begin());
}

}  // namespace
}  // namespace u4d
