#include "u4d/eval/keyframe_eval.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "u4d/util/check.h"
#include "u4d/util/stats.h"

namespace u4d {
namespace {

double Mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / v.size();
}

}  // namespace

double GtPoseDistance(const std::vector<Pose3d>& a, const std::vector<Pose3d>& b) {
  double sum = 0;
  int people = 0;
  for (const Pose3d& pa : a) {
    for (const Pose3d& pb : b) {
      if (pa.person_id != pb.person_id) continue;
      if (pa.joints[h36m17::kPelvis].w() <= 0 || pb.joints[h36m17::kPelvis].w() <= 0) continue;
      const Eigen::Vector3d ra = pa.joints[h36m17::kPelvis].head<3>();
      const Eigen::Vector3d rb = pb.joints[h36m17::kPelvis].head<3>();
      double d = 0;
      int n = 0;
      for (int j = 0; j < h36m17::kNumJoints; ++j) {
        if (pa.joints[j].w() <= 0 || pb.joints[j].w() <= 0) continue;
        d += ((pa.joints[j].head<3>() - ra) - (pb.joints[j].head<3>() - rb)).norm();
        ++n;
      }
      if (n < 8) continue;
      sum += d / n;
      ++people;
    }
  }
  return people ? sum / people : std::numeric_limits<double>::quiet_NaN();
}

Eigen::MatrixXd GtPoseDistanceMatrix(const std::vector<std::vector<Pose3d>>& gt_poses) {
  const int n = static_cast<int>(gt_poses.size());
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) d(a, b) = d(b, a) = GtPoseDistance(gt_poses[a], gt_poses[b]);
  }
  return d;
}

KeyframeGtEvaluation EvaluateKeyframesWithGtPoses(const KeyframeSelection& selection,
                                                  const Eigen::MatrixXd& gt, int recurrence_gap) {
  const int n = static_cast<int>(gt.rows());
  U4D_CHECK(gt.cols() == n && static_cast<int>(selection.frame_keyframe.size()) == n,
            "EvaluateKeyframesWithGtPoses: {} frames in the selection, GT is {}x{}",
            selection.frame_keyframe.size(), gt.rows(), gt.cols());
  std::vector<double> all, member, uniform, recurring;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      if (std::isfinite(gt(a, b))) all.push_back(gt(a, b));
    }
  }
  for (int t = 0; t < n; ++t) {
    const int k = selection.frame_keyframe[t];
    if (k != t && std::isfinite(gt(t, k))) {
      member.push_back(gt(t, k));
      if (std::abs(t - k) > recurrence_gap) recurring.push_back(gt(t, k));
    }
  }
  const int nk = std::max<int>(1, static_cast<int>(selection.keyframes.size()));
  for (int t = 0; t < n; ++t) {
    const int seg = static_cast<int>(static_cast<long>(t) * nk / n);
    const int lo = static_cast<int>((static_cast<long>(seg) * n + nk - 1) / nk);
    const int hi = static_cast<int>((static_cast<long>(seg + 1) * n + nk - 1) / nk);  // exclusive
    const int k = (lo + hi - 1) / 2;
    if (k != t && std::isfinite(gt(t, k))) uniform.push_back(gt(t, k));
  }
  KeyframeGtEvaluation e;
  e.num_keyframes = static_cast<int>(selection.keyframes.size());
  e.members = static_cast<int>(member.size());
  e.mean_all = Mean(all);
  e.median_all = Median(all);
  e.mean_member = Mean(member);
  e.median_member = Median(member);
  e.max_member = member.empty() ? 0 : *std::max_element(member.begin(), member.end());
  e.mean_member_uniform = Mean(uniform);
  e.recurring_members = static_cast<int>(recurring.size());
  e.mean_recurring = Mean(recurring);
  return e;
}

}  // namespace u4d
