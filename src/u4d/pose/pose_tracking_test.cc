// Tests of pose_tracking.h against known synthetic trajectories.
#include "u4d/pose/pose_tracking.h"

#include <unistd.h>

#include <random>

#include <gtest/gtest.h>

#include "u4d/io/layout.h"
#include "u4d/pose/given_poses.h"
#include "u4d/util/check.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

Pose3d PoseAt(const Eigen::Vector3d& root) {
  Pose3d p;
  for (int k = 0; k < 17; ++k) p.joints[k] << root + Eigen::Vector3d(0, 0.1 * k, 0), 1.0;
  return p;
}

TEST(PoseTracking, TwoWalkersKeepTheirIdsWhateverTheInputOrder) {
  std::vector<std::vector<Pose3d>> frames;
  for (int f = 0; f < 30; ++f) {
    // Walk towards each other at 1.4 m/s (25 fps), passing 0.8 m apart.
    const Pose3d a = PoseAt(Eigen::Vector3d(-1.5 + 0.056 * f, 0, 0));
    const Pose3d b = PoseAt(Eigen::Vector3d(1.5 - 0.056 * f, 0, 0.8));
    frames.push_back(f % 3 == 0 ? std::vector<Pose3d>{b, a} : std::vector<Pose3d>{a, b});
  }
  frames[10].pop_back();  // one person missing for a frame
  const auto tracked = TrackPoses(frames);
  int id_a = -1, id_b = -1;
  for (int f = 0; f < 30; ++f) {
    for (const Pose3d& p : tracked[f]) {
      const double x_truth_a = -1.5 + 0.056 * f;
      const bool is_a = std::abs(p.joints[0].z()) < 0.4;
      int& id = is_a ? id_a : id_b;
      if (id < 0) id = p.person_id;
      EXPECT_EQ(p.person_id, id) << "frame " << f;
      // Constant velocity: the alpha-beta filter has no steady-state lag;
      // after the first frames it tracks exactly (1 mm: rounding only).
      if (is_a && f > 15) {
        EXPECT_NEAR(p.joints[0].x(), x_truth_a, 1e-3) << "frame " << f;
      }
    }
  }
  EXPECT_NE(id_a, id_b);
}

TEST(PoseTracking, SmoothingReducesNoiseAndGatesOutliers) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.02);  // 2 cm, a triangulation's noise
  std::vector<std::vector<Pose3d>> frames;
  for (int f = 0; f < 60; ++f) {
    Pose3d p = PoseAt(Eigen::Vector3d::Zero());
    for (auto& j : p.joints) j.head<3>() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    if (f == 40) p.joints[5].x() += 0.8;  // one wrong joint (e.g. a limb swap)
    frames.push_back({p});
  }
  const auto tracked = TrackPoses(frames);
  double raw = 0, smooth = 0;
  for (int f = 10; f < 60; ++f) {
    ASSERT_EQ(tracked[f].size(), 1u);
    for (int k = 0; k < 17; ++k) {
      const Eigen::Vector3d truth(0, 0.1 * k, 0);
      raw += (frames[f][0].joints[k].head<3>() - truth).squaredNorm();
      smooth += (tracked[f][0].joints[k].head<3>() - truth).squaredNorm();
    }
  }
  // A static joint with alpha 0.7, beta 0.3 keeps ~70% of the noise variance
  // (steady-state alpha-beta gain); assert at least a 15% reduction. The
  // outlier frame alone would add 0.64 m^2 to the raw sum.
  EXPECT_LT(smooth, 0.85 * raw);
  EXPECT_LT((tracked[40][0].joints[5].head<3>() - Eigen::Vector3d(0, 0.5, 0)).norm(), 0.1);
}

TEST(PoseTracking, BadOptionsThrow) {
  PoseTrackerOptions o;
  o.alpha = 0;
  EXPECT_THROW(o.Check(), Error);
  PoseTrackerState s;
  EXPECT_THROW(UpdatePoseTracks(s, {}, o), Error);
}

TEST(GivenPoses, PassThroughKeepsPosesAndIdsAndNamesMissingFiles) {
  const fs::path dir = test_util::FreshTestDir("given_poses_test", "poses");
  Pose3d p = PoseAt(Eigen::Vector3d(1, 2, 3));
  p.person_id = 7;
  fs::create_directories((dir / layout::Poses3d(0)).parent_path());
  WritePoses3d(dir / layout::Poses3d(0), {p});
  const auto frames = ReadGivenPoses3d(dir, 2, /*allow_missing=*/true);
  ASSERT_EQ(frames.size(), 2u);
  ASSERT_EQ(frames[0].size(), 1u);
  EXPECT_TRUE(frames[1].empty());
  EXPECT_EQ(frames[0][0].person_id, 7);
  for (int k = 0; k < 17; ++k)
    EXPECT_LT((frames[0][0].joints[k] - p.joints[k]).norm(), 1e-9) << "joint " << k;
  try {
    ReadGivenPoses3d(dir, 2);
    ADD_FAILURE() << "a missing frame file must throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("000001"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace u4d
