#include "u4d/pose/pose_smoothing.h"

#include <cmath>
#include <map>

#include <Eigen/Dense>

#include "u4d/util/check.h"

namespace u4d {

void PoseSmoothingOptions::Check() const {
  U4D_CHECK(window_seconds >= 0 && std::isfinite(window_seconds),
            "PoseSmoothingOptions.window_seconds must be >= 0, found {}", window_seconds);
  U4D_CHECK(degree >= 1, "PoseSmoothingOptions.degree must be >= 1, found {}", degree);
}

std::vector<std::vector<Pose3d>> SmoothTrackedPoses(const std::vector<std::vector<Pose3d>>& frames,
                                                    double fps,
                                                    const PoseSmoothingOptions& options) {
  options.Check();
  U4D_CHECK(fps > 0 && std::isfinite(fps), "SmoothTrackedPoses: fps must be > 0, found {}", fps);
  const int n_frames = static_cast<int>(frames.size());
  // index[id][t] = position of that person's pose in frames[t], or -1.
  std::map<int, std::vector<int>> index;
  for (int t = 0; t < n_frames; ++t)
    for (int i = 0; i < static_cast<int>(frames[t].size()); ++i) {
      std::vector<int>& at = index.try_emplace(frames[t][i].person_id, n_frames, -1).first->second;
      U4D_CHECK(at[t] < 0, "SmoothTrackedPoses: frame {} has two poses with id {}", t,
                frames[t][i].person_id);
      at[t] = i;
    }
  std::vector<std::vector<Pose3d>> out = frames;
  const int h = static_cast<int>(std::lround(options.window_seconds * fps / 2));
  if (h < 1) return out;
  for (const auto& [id, at] : index)
    for (int t = 0; t < n_frames; ++t) {
      if (at[t] < 0) continue;
      for (int j = 0; j < 17; ++j) {
        if (!(frames[t][at[t]].joints[j].w() > 0)) continue;
        std::vector<int> dt;
        std::vector<Eigen::Vector3d> x;
        for (int s = std::max(0, t - h); s <= std::min(n_frames - 1, t + h); ++s) {
          if (at[s] < 0) continue;
          const Eigen::Vector4d& q = frames[s][at[s]].joints[j];
          if (!(q.w() > 0)) continue;
          dt.push_back(s - t);
          x.push_back(q.head<3>());
        }
        const int n = static_cast<int>(dt.size());
        const int deg = std::min(options.degree, n - 2);
        if (deg < 1) continue;
        Eigen::MatrixXd A(n, deg + 1);
        Eigen::MatrixXd B(n, 3);
        for (int r = 0; r < n; ++r) {
          for (int c = 0; c <= deg; ++c) A(r, c) = std::pow(static_cast<double>(dt[r]), c);
          B.row(r) = x[r].transpose();
        }
        const Eigen::MatrixXd coef = A.colPivHouseholderQr().solve(B);
        out[t][at[t]].joints[j].head<3>() = coef.row(0).transpose();
      }
    }
  return out;
}

}  // namespace u4d
