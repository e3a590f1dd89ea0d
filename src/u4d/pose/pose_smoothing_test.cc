// SmoothTrackedPoses against known trajectories with added noise.
#include "u4d/pose/pose_smoothing.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "u4d/util/stats.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

constexpr double kFps = 25;

// Joint j of person `id` at frame t: a walk at 0.5 m/s plus, for the wrists,
// a 2 Hz, 5 cm hand shake (the fastest motion of the synthetic handshake).
Eigen::Vector3d Truth(int id, int j, int t) {
  const double s = t / kFps;
  Eigen::Vector3d p(0.5 * s + id, 0.1 * j, 0.05 * id);
  if (j == 13 || j == 16) p.y() += 0.05 * std::sin(2 * M_PI * 2.0 * s);
  return p;
}

std::vector<std::vector<Pose3d>> Sequence(int n, double noise_m, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, noise_m);
  std::vector<std::vector<Pose3d>> frames(n);
  for (int t = 0; t < n; ++t)
    for (int id : {1, 0}) {  // order differs from id order
      Pose3d p;
      p.person_id = id;
      for (int j = 0; j < 17; ++j)
        p.joints[j] << Truth(id, j, t) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)), 0.9;
      frames[t].push_back(p);
    }
  return frames;
}

// Median over people, joints and frames of the position error and of the
// frame-to-frame motion error against the truth.
void Errors(const std::vector<std::vector<Pose3d>>& frames, double* pos, double* motion) {
  std::vector<double> p, m;
  for (size_t t = 0; t < frames.size(); ++t)
    for (size_t i = 0; i < frames[t].size(); ++i) {
      const int id = frames[t][i].person_id;
      for (int j = 0; j < 17; ++j) {
        const Eigen::Vector3d x = frames[t][i].joints[j].head<3>();
        p.push_back((x - Truth(id, j, t)).norm());
        if (t + 1 < frames.size()) {
          const Eigen::Vector3d x1 = frames[t + 1][i].joints[j].head<3>();
          m.push_back(((x1 - x) - (Truth(id, j, t + 1) - Truth(id, j, t))).norm());
        }
      }
    }
  *pos = Median(p);
  *motion = Median(m);
}

// 2 cm of noise (a triangulation's): the frame-to-frame motion error must
// drop at least 3x (pure noise predicts 3.4x for a 7-sample quadratic, see
// the header; the one-sided windows at the ends and the 2 Hz shake's
// curvature cost a little of it) and the position error must drop.
TEST(PoseSmoothing, CutsTheJitterOfTheMotion) {
  const auto raw = Sequence(50, 0.02, 3);
  const auto smooth = SmoothTrackedPoses(raw, kFps);
  double pos0, mot0, pos1, mot1;
  Errors(raw, &pos0, &mot0);
  Errors(smooth, &pos1, &mot1);
  std::printf("position error %.1f -> %.1f mm, motion error %.1f -> %.1f mm\n", pos0 * 1e3,
              pos1 * 1e3, mot0 * 1e3, mot1 * 1e3);
  EXPECT_LT(mot1, mot0 / 3);
  EXPECT_LT(pos1, pos0);
  // Ids, order and confidences are kept.
  for (size_t t = 0; t < raw.size(); ++t)
    for (size_t i = 0; i < raw[t].size(); ++i) {
      EXPECT_EQ(smooth[t][i].person_id, raw[t][i].person_id);
      EXPECT_EQ(smooth[t][i].joints[3].w(), raw[t][i].joints[3].w());
    }
}

// A quadratic trajectory is reproduced exactly (the fit's degree), also at
// the ends of the sequence where the window is one-sided.
TEST(PoseSmoothing, KeepsAQuadraticExactly) {
  std::vector<std::vector<Pose3d>> frames(12);
  for (int t = 0; t < 12; ++t) {
    Pose3d p;
    p.person_id = 4;
    for (int j = 0; j < 17; ++j) p.joints[j] << 0.01 * t * t - 0.2 * t + j, 0.3 * t, 1.0 * j, 1.0;
    frames[t] = {p};
  }
  const auto out = SmoothTrackedPoses(frames, kFps);
  for (int t = 0; t < 12; ++t)
    for (int j = 0; j < 17; ++j)
      EXPECT_LT((out[t][0].joints[j] - frames[t][0].joints[j]).norm(), 1e-9) << t << " " << j;
}

// Missing joints stay missing and are not used; a person absent in a frame
// leaves a gap; too short a sequence or a zero window changes nothing.
TEST(PoseSmoothing, GapsAndShortSequences) {
  auto frames = Sequence(10, 0.0, 1);
  frames[4][0].joints[5].setZero();    // person 1's joint 5 missing at frame 4
  frames[6].erase(frames[6].begin());  // person 1 absent at frame 6
  const auto out = SmoothTrackedPoses(frames, kFps);
  EXPECT_EQ(out[4][0].joints[5], Eigen::Vector4d::Zero());
  EXPECT_EQ(out[6].size(), 1u);
  // The truth is linear for non-wrist joints: the fit keeps it.
  EXPECT_LT((out[5][0].joints[5].head<3>() - Truth(1, 5, 5)).norm(), 1e-9);

  const auto two = Sequence(2, 0.02, 2);
  const auto out2 = SmoothTrackedPoses(two, kFps);
  EXPECT_EQ(out2[1][0].joints[7], two[1][0].joints[7]);
  PoseSmoothingOptions off;
  off.window_seconds = 0;
  const auto noisy = Sequence(10, 0.02, 5);
  EXPECT_EQ(SmoothTrackedPoses(noisy, kFps, off)[5][1].joints[2], noisy[5][1].joints[2]);
}

TEST(PoseSmoothing, BadInputThrows) {
  PoseSmoothingOptions o;
  o.degree = 0;
  test_util::ExpectErrorMentions([&] { o.Check(); }, {"degree"});
  auto frames = Sequence(3, 0.0, 1);
  test_util::ExpectErrorMentions([&] { SmoothTrackedPoses(frames, 0.0); }, {"fps"});
  frames[1][1].person_id = frames[1][0].person_id;
  test_util::ExpectErrorMentions([&] { SmoothTrackedPoses(frames, kFps); },
                                 {"frame 1", "two poses with id"});
}

}  // namespace
}  // namespace u4d
