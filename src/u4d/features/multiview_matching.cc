#include "u4d/features/multiview_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <tbb/parallel_for.h>
#include <Eigen/Dense>
#include <opencv2/core.hpp>

#include "u4d/geometry/epipolar.h"
#include "u4d/util/check.h"

namespace u4d {

void MatchingOptions::Check() const {
  U4D_CHECK(std::isfinite(ratio) && ratio > 0 && ratio <= 1,
            "MatchingOptions.ratio must be in (0, 1], got {}", ratio);
  U4D_CHECK(std::isfinite(max_epipolar_px) && max_epipolar_px > 0,
            "MatchingOptions.max_epipolar_px must be > 0, got {}", max_epipolar_px);
  U4D_CHECK(std::isfinite(max_descriptor_distance) && max_descriptor_distance > 0,
            "MatchingOptions.max_descriptor_distance must be > 0, got {}", max_descriptor_distance);
  U4D_CHECK(
      std::isfinite(max_pair_angle_deg) && max_pair_angle_deg > 0 && max_pair_angle_deg <= 180,
      "MatchingOptions.max_pair_angle_deg must be in (0, 180], got {}", max_pair_angle_deg);
  U4D_CHECK(neighbour_views >= 0, "MatchingOptions.neighbour_views must be >= 0, got {}",
            neighbour_views);
  U4D_CHECK(min_track_views >= 2, "MatchingOptions.min_track_views must be >= 2, got {}",
            min_track_views);
}

namespace {

void CheckDescriptors(const ViewKeypoints& k, const char* which) {
  U4D_CHECK(k.descriptors.rows == k.size() &&
                (k.size() == 0 || (k.descriptors.type() == CV_32F && k.descriptors.cols == 128)),
            "MatchViewPair: keypoints {} need one CV_32F 128-column descriptor per keypoint "
            "(got {} keypoints, {}x{} type {})",
            which, k.size(), k.descriptors.rows, k.descriptors.cols, k.descriptors.type());
}

std::vector<Eigen::Vector2d> Undistorted(const Camera& camera, const ViewKeypoints& k) {
  std::vector<Eigen::Vector2d> out(k.size());
  for (int i = 0; i < k.size(); ++i) {
    out[i] = UndistortPixel(camera, Eigen::Vector2d(k.keypoints[i].pt.x, k.keypoints[i].pt.y));
  }
  return out;
}

}  // namespace

PairMatches MatchViewPair(const Camera& camera_a, const Camera& camera_b,
                          const ViewKeypoints& keypoints_a, const ViewKeypoints& keypoints_b,
                          const MatchingOptions& options) {
  options.Check();
  CheckDescriptors(keypoints_a, "a");
  CheckDescriptors(keypoints_b, "b");
  PairMatches out;
  const int na = keypoints_a.size();
  const int nb = keypoints_b.size();
  if (na == 0 || nb == 0) return out;

  // Squared descriptor distances |a|^2 + |b|^2 - 2 a.b.
  cv::Mat dot;
  cv::gemm(keypoints_a.descriptors, keypoints_b.descriptors, 1.0, cv::noArray(), 0.0, dot,
           cv::GEMM_2_T);
  std::vector<float> norm_a(na), norm_b(nb);
  for (int i = 0; i < na; ++i)
    norm_a[i] = keypoints_a.descriptors.row(i).dot(keypoints_a.descriptors.row(i));
  for (int j = 0; j < nb; ++j)
    norm_b[j] = keypoints_b.descriptors.row(j).dot(keypoints_b.descriptors.row(j));

  const Eigen::Matrix3d F = FundamentalFromCameras(camera_a, camera_b);
  const std::vector<Eigen::Vector2d> ua = Undistorted(camera_a, keypoints_a);
  const std::vector<Eigen::Vector2d> ub = Undistorted(camera_b, keypoints_b);

  // Squared descriptor distances, and which pairs pass the epipolar gate.
  cv::Mat dist(na, nb, CV_32F);
  cv::Mat gated(na, nb, CV_8U);
  for (int i = 0; i < na; ++i) {
    const Eigen::Vector3d line = F * ua[i].homogeneous();
    const double scale = std::hypot(line.x(), line.y());
    const float* d = dot.ptr<float>(i);
    float* out_row = dist.ptr<float>(i);
    uint8_t* gate_row = gated.ptr<uint8_t>(i);
    for (int j = 0; j < nb; ++j) {
      out_row[j] = std::max(0.f, norm_a[i] + norm_b[j] - 2 * d[j]);
      gate_row[j] =
          scale > 0 && std::abs(line.dot(ub[j].homogeneous())) <= options.max_epipolar_px * scale;
    }
  }
  constexpr float kInf = std::numeric_limits<float>::infinity();
  // Best epipolar-consistent feature of view a for each feature of view b.
  std::vector<int> best_of_b(nb, -1);
  std::vector<float> best_dist_b(nb, kInf);
  for (int i = 0; i < na; ++i) {
    const float* row = dist.ptr<float>(i);
    const uint8_t* gate_row = gated.ptr<uint8_t>(i);
    for (int j = 0; j < nb; ++j) {
      if (gate_row[j] && row[j] < best_dist_b[j]) {
        best_dist_b[j] = row[j];
        best_of_b[j] = i;
      }
    }
  }
  const float ratio2 = static_cast<float>(options.ratio * options.ratio);
  const float max_d2 =
      static_cast<float>(options.max_descriptor_distance * options.max_descriptor_distance);
  for (int i = 0; i < na; ++i) {
    const float* row = dist.ptr<float>(i);
    const uint8_t* gate_row = gated.ptr<uint8_t>(i);
    float best = kInf;
    int best_j = -1;
    for (int j = 0; j < nb; ++j) {
      if (gate_row[j] && row[j] < best) {
        best = row[j];
        best_j = j;
      }
    }
    if (best_j < 0 || best > max_d2) continue;
    // Ratio test against the nearest OTHER feature anywhere in view b: a lone
    // candidate on the epipolar line must still be distinctive.
    float second = kInf;
    for (int j = 0; j < nb; ++j) {
      if (j != best_j) second = std::min(second, row[j]);
    }
    if (best > ratio2 * second) continue;
    if (options.mutual && best_of_b[best_j] != i) continue;
    out.matches.emplace_back(i, best_j);
  }
  return out;
}

std::vector<Track> LinkTracks(const std::vector<PairMatches>& pairs,
                              const std::vector<int>& num_keypoints,
                              const MatchingOptions& options) {
  options.Check();
  const int num_views = static_cast<int>(num_keypoints.size());
  std::vector<int> offset(num_views + 1, 0);
  for (int v = 0; v < num_views; ++v) {
    U4D_CHECK(num_keypoints[v] >= 0, "LinkTracks: num_keypoints[{}] is negative", v);
    offset[v + 1] = offset[v] + num_keypoints[v];
  }
  std::vector<int> parent(offset[num_views]);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  };
  for (const PairMatches& p : pairs) {
    U4D_CHECK(p.view_a >= 0 && p.view_a < num_views && p.view_b >= 0 && p.view_b < num_views &&
                  p.view_a != p.view_b,
              "LinkTracks: bad view pair ({}, {}) for {} views", p.view_a, p.view_b, num_views);
    for (const auto& [ka, kb] : p.matches) {
      U4D_CHECK(ka >= 0 && ka < num_keypoints[p.view_a] && kb >= 0 && kb < num_keypoints[p.view_b],
                "LinkTracks: match ({}, {}) out of range in view pair ({}, {})", ka, kb, p.view_a,
                p.view_b);
      const int ra = find(offset[p.view_a] + ka);
      const int rb = find(offset[p.view_b] + kb);
      if (ra != rb) parent[ra] = rb;
    }
  }
  // Group features by root.
  std::vector<int> track_of_root(parent.size(), -1);
  std::vector<Track> groups;
  for (int v = 0; v < num_views; ++v) {
    for (int k = 0; k < num_keypoints[v]; ++k) {
      const int r = find(offset[v] + k);
      if (track_of_root[r] < 0) {
        track_of_root[r] = static_cast<int>(groups.size());
        groups.emplace_back();
      }
      groups[track_of_root[r]].emplace_back(v, k);
    }
  }
  std::vector<Track> tracks;
  for (Track& g : groups) {
    if (static_cast<int>(g.size()) < options.min_track_views) continue;
    bool consistent = true;
    for (size_t i = 1; i < g.size(); ++i) {
      if (g[i].first == g[i - 1].first) consistent = false;  // sorted by view
    }
    if (consistent) tracks.push_back(std::move(g));
  }
  return tracks;
}

double OpticalAxisAngleDeg(const Camera& a, const Camera& b) {
  // The optical axis in world coordinates is the third row of world-from-cam^T.
  const Eigen::Vector3d za = a.cam_from_world.rotation.row(2).transpose();
  const Eigen::Vector3d zb = b.cam_from_world.rotation.row(2).transpose();
  return std::atan2(za.cross(zb).norm(), za.dot(zb)) * 180.0 / M_PI;
}

std::vector<std::pair<int, int>> SelectViewPairs(const std::vector<Camera>& cameras,
                                                 const MatchingOptions& options) {
  options.Check();
  const int n = static_cast<int>(cameras.size());
  std::vector<std::vector<char>> use(n, std::vector<char>(n, options.neighbour_views == 0));
  if (options.neighbour_views > 0) {
    for (int a = 0; a < n; ++a) {
      std::vector<std::pair<double, int>> by_angle;
      for (int b = 0; b < n; ++b) {
        if (b != a) by_angle.emplace_back(OpticalAxisAngleDeg(cameras[a], cameras[b]), b);
      }
      std::sort(by_angle.begin(), by_angle.end());
      for (int k = 0; k < std::min<int>(options.neighbour_views, by_angle.size()); ++k) {
        use[a][by_angle[k].second] = use[by_angle[k].second][a] = 1;
      }
    }
  }
  std::vector<std::pair<int, int>> pairs;
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      if (use[a][b] && OpticalAxisAngleDeg(cameras[a], cameras[b]) <= options.max_pair_angle_deg) {
        pairs.emplace_back(a, b);
      }
    }
  }
  return pairs;
}

std::vector<Track> MatchAllViews(const std::vector<Camera>& cameras,
                                 const std::vector<ViewKeypoints>& keypoints,
                                 const MatchingOptions& options) {
  options.Check();
  U4D_CHECK(cameras.size() == keypoints.size(), "MatchAllViews: {} cameras but {} keypoint sets",
            cameras.size(), keypoints.size());
  const int n = static_cast<int>(cameras.size());
  std::vector<PairMatches> pairs;
  for (const auto& [a, b] : SelectViewPairs(cameras, options)) {
    pairs.emplace_back();
    pairs.back().view_a = a;
    pairs.back().view_b = b;
  }
  tbb::parallel_for(size_t{0}, pairs.size(), [&](size_t i) {
    const int a = pairs[i].view_a, b = pairs[i].view_b;
    pairs[i] = MatchViewPair(cameras[a], cameras[b], keypoints[a], keypoints[b], options);
    pairs[i].view_a = a;
    pairs[i].view_b = b;
  });
  std::vector<int> counts(n);
  for (int v = 0; v < n; ++v) counts[v] = keypoints[v].size();
  return LinkTracks(pairs, counts, options);
}

}  // namespace u4d
