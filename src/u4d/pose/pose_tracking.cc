#include "u4d/pose/pose_tracking.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "u4d/util/check.h"

namespace u4d {

void PoseTrackerOptions::Check() const {
  U4D_CHECK(max_match_distance > 0, "PoseTrackerOptions.max_match_distance must be > 0, got {}",
            max_match_distance);
  U4D_CHECK(max_missed_frames >= 0, "PoseTrackerOptions.max_missed_frames must be >= 0, got {}",
            max_missed_frames);
  U4D_CHECK(alpha > 0 && alpha <= 1, "PoseTrackerOptions.alpha must be in (0, 1], got {}", alpha);
  U4D_CHECK(beta >= 0 && beta < 2 - alpha,
            "PoseTrackerOptions.beta must be in [0, 2 - alpha), got {}", beta);
  U4D_CHECK(gate_distance > 0, "PoseTrackerOptions.gate_distance must be > 0, got {}",
            gate_distance);
  U4D_CHECK(max_gated_frames >= 0, "PoseTrackerOptions.max_gated_frames must be >= 0, got {}",
            max_gated_frames);
}

namespace {

bool Valid(const Eigen::Vector4d& j) { return j.w() > 0 && j.head<3>().allFinite(); }

double MatchDistance(const PoseTrack& t, const Pose3d& p) {
  double sum = 0;
  int n = 0;
  for (int k = 0; k < 17; ++k) {
    if (!t.init[k] || !Valid(p.joints[k])) continue;
    sum += (t.x[k] + t.v[k] - p.joints[k].head<3>()).norm();
    ++n;
  }
  return n >= 3 ? sum / n : std::numeric_limits<double>::infinity();
}

void InitJoint(PoseTrack& t, int k, const Eigen::Vector4d& z) {
  t.x[k] = z.head<3>();
  t.v[k].setZero();
  t.conf[k] = z.w();
  t.init[k] = true;
  t.joint_missed[k] = 0;
  t.gated[k] = 0;
}

Pose3d Output(const PoseTrack& t, int max_missed) {
  Pose3d out;
  out.person_id = t.id;
  for (int k = 0; k < 17; ++k) {
    if (!t.init[k] || t.joint_missed[k] > max_missed) continue;
    out.joints[k] << t.x[k], t.conf[k];
  }
  return out;
}

}  // namespace

std::vector<Pose3d> UpdatePoseTracks(PoseTrackerState& state, const std::vector<Pose3d>& poses,
                                     const PoseTrackerOptions& options) {
  options.Check();
  const int nt = static_cast<int>(state.tracks.size());
  const int np = static_cast<int>(poses.size());
  struct Pair {
    double d;
    int t, p;
  };
  std::vector<Pair> pairs;
  for (int t = 0; t < nt; ++t) {
    for (int p = 0; p < np; ++p) {
      const double d = MatchDistance(state.tracks[t], poses[p]);
      if (d <= options.max_match_distance) pairs.push_back({d, t, p});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.d < b.d; });
  std::vector<int> track_of(np, -1);
  std::vector<bool> track_used(nt, false);
  for (const Pair& pr : pairs) {
    if (track_used[pr.t] || track_of[pr.p] >= 0) continue;
    track_used[pr.t] = true;
    track_of[pr.p] = pr.t;
  }
  // Update matched tracks, age the others.
  for (int t = 0; t < nt; ++t) {
    PoseTrack& tr = state.tracks[t];
    int p = -1;
    for (int i = 0; i < np; ++i)
      if (track_of[i] == t) p = i;
    if (p < 0) {
      ++tr.missed;
      for (int k = 0; k < 17; ++k) {
        if (!tr.init[k]) continue;
        tr.x[k] += tr.v[k];
        ++tr.joint_missed[k];
      }
      continue;
    }
    tr.missed = 0;
    for (int k = 0; k < 17; ++k) {
      const Eigen::Vector4d& z = poses[p].joints[k];
      if (!tr.init[k] || tr.joint_missed[k] > options.max_missed_frames) {
        if (Valid(z)) {
          InitJoint(tr, k, z);
        } else {
          tr.init[k] = false;
        }
        continue;
      }
      const Eigen::Vector3d pred = tr.x[k] + tr.v[k];
      if (!Valid(z)) {
        tr.x[k] = pred;
        tr.conf[k] *= 0.5;
        ++tr.joint_missed[k];
        continue;
      }
      const Eigen::Vector3d r = z.head<3>() - pred;
      if (r.norm() > options.gate_distance) {
        if (++tr.gated[k] > options.max_gated_frames) {
          InitJoint(tr, k, z);
        } else {
          tr.x[k] = pred;
          tr.conf[k] *= 0.5;
        }
        continue;
      }
      tr.gated[k] = 0;
      tr.joint_missed[k] = 0;
      tr.x[k] = pred + options.alpha * r;
      tr.v[k] += options.beta * r;
      tr.conf[k] = z.w();
    }
  }
  // New tracks.
  for (int p = 0; p < np; ++p) {
    if (track_of[p] >= 0) continue;
    PoseTrack tr;
    tr.id = state.next_id++;
    for (int k = 0; k < 17; ++k) {
      tr.x[k].setZero();
      tr.v[k].setZero();
      if (Valid(poses[p].joints[k])) InitJoint(tr, k, poses[p].joints[k]);
    }
    track_of[p] = static_cast<int>(state.tracks.size());
    state.tracks.push_back(tr);
  }
  std::vector<Pose3d> out;
  out.reserve(np);
  for (int p = 0; p < np; ++p)
    out.push_back(Output(state.tracks[track_of[p]], options.max_missed_frames));
  // Drop tracks unseen for too long (after producing output: indices above stay valid).
  state.tracks.erase(
      std::remove_if(state.tracks.begin(), state.tracks.end(),
                     [&](const PoseTrack& t) { return t.missed > options.max_missed_frames; }),
      state.tracks.end());
  return out;
}

std::vector<std::vector<Pose3d>> TrackPoses(const std::vector<std::vector<Pose3d>>& frames,
                                            const PoseTrackerOptions& options) {
  PoseTrackerState state;
  std::vector<std::vector<Pose3d>> out;
  out.reserve(frames.size());
  for (const auto& f : frames) out.push_back(UpdatePoseTracks(state, f, options));
  return out;
}

}  // namespace u4d
