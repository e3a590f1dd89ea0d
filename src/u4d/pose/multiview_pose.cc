#include "u4d/pose/multiview_pose.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "u4d/geometry/epipolar.h"
#include "u4d/geometry/triangulation.h"
#include "u4d/util/check.h"

namespace u4d {

void MultiViewPoseOptions::Check() const {
  U4D_CHECK(min_keypoint_confidence >= 0 && min_keypoint_confidence <= 1,
            "MultiViewPoseOptions.min_keypoint_confidence must be in [0, 1], got {}",
            min_keypoint_confidence);
  U4D_CHECK(max_epipolar_distance > 0 && std::isfinite(max_epipolar_distance),
            "MultiViewPoseOptions.max_epipolar_distance must be positive, got {}",
            max_epipolar_distance);
  U4D_CHECK(min_shared_keypoints >= 1,
            "MultiViewPoseOptions.min_shared_keypoints must be >= 1, got {}", min_shared_keypoints);
  U4D_CHECK(min_views >= 2, "MultiViewPoseOptions.min_views must be >= 2, got {}", min_views);
  U4D_CHECK(max_reprojection_error > 0 && std::isfinite(max_reprojection_error),
            "MultiViewPoseOptions.max_reprojection_error must be positive, got {}",
            max_reprojection_error);
  U4D_CHECK(mirror_gain >= 0 && mirror_gain <= 1,
            "MultiViewPoseOptions.mirror_gain must be in [0, 1], got {}", mirror_gain);
  U4D_CHECK(min_triangulation_angle_deg >= 0 && min_triangulation_angle_deg < 90,
            "MultiViewPoseOptions.min_triangulation_angle_deg must be in [0, 90), got {}",
            min_triangulation_angle_deg);
  U4D_CHECK(min_joints >= 1 && min_joints <= 17,
            "MultiViewPoseOptions.min_joints must be in [1, 17], got {}", min_joints);
}

Keypoints2d MirrorCoco17(const Keypoints2d& keypoints) {
  Keypoints2d out;
  for (int k = 0; k < coco17::kNumKeypoints; ++k) out[k] = keypoints[Coco17Mirror(k)];
  return out;
}

namespace {

constexpr double kNoAffinity = std::numeric_limits<double>::infinity();

void CheckInputs(const std::vector<std::vector<Pose2d>>& poses, const std::vector<Camera>& cameras,
                 const MultiViewPoseOptions& options) {
  options.Check();
  U4D_CHECK(poses.size() == cameras.size(),
            "multi-view pose: {} views of detections but {} cameras", poses.size(), cameras.size());
  for (size_t v = 0; v < cameras.size(); ++v) cameras[v].Check(fmt::format("camera of view {}", v));
}

// Undistorted keypoints of every detection, with the confidence.
using UndistortedPose = std::array<Eigen::Vector3d, 17>;

UndistortedPose Undistort(const Keypoints2d& keypoints, const Camera& camera, double min_conf) {
  UndistortedPose out;
  for (int k = 0; k < 17; ++k) {
    const Eigen::Vector3d& p = keypoints[k];
    if (p.z() >= min_conf && p.z() > 0 && p.head<2>().allFinite()) {
      out[k] << UndistortPixel(camera, p.head<2>()), p.z();
    } else {
      out[k].setZero();
    }
  }
  return out;
}

UndistortedPose MirrorUndistorted(const UndistortedPose& p) {
  UndistortedPose out;
  out[0] = p[0];
  for (int k = 1; k < 17; ++k) out[k] = p[(k % 2 == 1) ? k + 1 : k - 1];
  return out;
}

// Mean symmetric epipolar distance; kNoAffinity with too few shared keypoints.
double PairDistance(const Eigen::Matrix3d& f_ab, const UndistortedPose& a, const UndistortedPose& b,
                    int min_shared) {
  const Eigen::Matrix3d f_ba = f_ab.transpose();
  double sum = 0;
  int n = 0;
  for (int k = 0; k < 17; ++k) {
    if (a[k].z() <= 0 || b[k].z() <= 0) continue;
    sum += 0.5 * (EpipolarDistance(f_ab, a[k].head<2>(), b[k].head<2>()) +
                  EpipolarDistance(f_ba, b[k].head<2>(), a[k].head<2>()));
    ++n;
  }
  return n >= min_shared ? sum / n : kNoAffinity;
}

struct Node {
  int view, det;
};

// Sine of the angle between the rays from `x` to the two camera centres: 0
// for parallel or opposite rays, where depth along them is unconstrained.
double RaySine(const Eigen::Vector3d& x, const Camera& a, const Camera& b) {
  const Eigen::Vector3d ra = (a.Center() - x).normalized(), rb = (b.Center() - x).normalized();
  return ra.cross(rb).norm();
}

// Per-joint robust triangulation. Returns (x, y, z, conf) and the mean
// inlier reprojection error through `error` (NaN when missing).
Eigen::Vector4d TriangulateJoint(const std::vector<Observation>& obs,
                                 const std::vector<double>& conf, double threshold_px,
                                 double min_sine, double* error) {
  *error = std::numeric_limits<double>::quiet_NaN();
  const int n = static_cast<int>(obs.size());
  if (n < 2) return Eigen::Vector4d::Zero();
  std::vector<int> best_inliers;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const Eigen::Vector3d x = TriangulateDlt({obs[i], obs[j]});
      if (!x.allFinite() || RaySine(x, *obs[i].camera, *obs[j].camera) < min_sine) continue;
      std::vector<int> inliers;
      double cost = 0;
      for (int k = 0; k < n; ++k) {
        if (obs[k].camera->Depth(x) <= 0) continue;
        const double e = (obs[k].camera->Project(x) - obs[k].pixel).norm();
        if (std::isfinite(e) && e <= threshold_px) {
          inliers.push_back(k);
          cost += e;
        }
      }
      if (inliers.size() > best_inliers.size() ||
          (inliers.size() == best_inliers.size() && cost < best_cost)) {
        best_inliers = inliers;
        best_cost = cost;
      }
    }
  }
  if (best_inliers.size() < 2) return Eigen::Vector4d::Zero();
  std::vector<Observation> in;
  double conf_sum = 0;
  for (int k : best_inliers) {
    in.push_back(obs[k]);
    conf_sum += conf[k];
  }
  const Eigen::Vector3d x = TriangulateDlt(in);
  if (!x.allFinite()) return Eigen::Vector4d::Zero();
  double best_sine = 0;
  for (size_t i = 0; i < in.size(); ++i)
    for (size_t j = i + 1; j < in.size(); ++j)
      best_sine = std::max(best_sine, RaySine(x, *in[i].camera, *in[j].camera));
  if (best_sine < min_sine) return Eigen::Vector4d::Zero();
  double err = 0;
  for (const Observation& o : in) {
    if (o.camera->Depth(x) <= 0) return Eigen::Vector4d::Zero();
    err += (o.camera->Project(x) - o.pixel).norm();
  }
  *error = err / in.size();
  return Eigen::Vector4d(x.x(), x.y(), x.z(), std::clamp(conf_sum / in.size(), 0.0, 1.0));
}

// Triangulates all COCO joints of one cluster with the given (possibly
// mirrored) keypoints per view; views without a detection are empty.
std::array<Eigen::Vector4d, 17> TriangulateCluster(const std::vector<const Keypoints2d*>& kps,
                                                   const std::vector<Camera>& cameras,
                                                   const MultiViewPoseOptions& options,
                                                   double* mean_error) {
  std::array<Eigen::Vector4d, 17> out;
  double err_sum = 0;
  int err_n = 0;
  for (int k = 0; k < 17; ++k) {
    std::vector<Observation> obs;
    std::vector<double> conf;
    double threshold = 0;
    for (size_t v = 0; v < kps.size(); ++v) {
      if (kps[v] == nullptr) continue;
      const Eigen::Vector3d& p = (*kps[v])[k];
      if (p.z() <= 0 || p.z() < options.min_keypoint_confidence || !p.head<2>().allFinite())
        continue;
      Observation o;
      o.camera = &cameras[v];
      o.pixel = p.head<2>();
      o.weight = p.z();
      obs.push_back(o);
      conf.push_back(p.z());
      threshold = std::max(threshold, options.max_reprojection_error * cameras[v].width);
    }
    double e = 0;
    out[k] = TriangulateJoint(obs, conf, threshold,
                              std::sin(options.min_triangulation_angle_deg * M_PI / 180), &e);
    if (out[k].w() > 0) {
      err_sum += e;
      ++err_n;
    }
  }
  *mean_error = err_n > 0 ? err_sum / err_n : std::numeric_limits<double>::quiet_NaN();
  return out;
}

// Mean reprojection error of `kp` against the 3D joints (those valid in both).
double ViewError(const Keypoints2d& kp, const std::array<Eigen::Vector4d, 17>& joints,
                 const Camera& camera, double min_conf, int* count) {
  double sum = 0;
  int n = 0;
  for (int k = 0; k < 17; ++k) {
    if (joints[k].w() <= 0 || kp[k].z() <= 0 || kp[k].z() < min_conf) continue;
    const Eigen::Vector3d x = joints[k].head<3>();
    if (camera.Depth(x) <= 0) continue;
    const double e = (camera.Project(x) - kp[k].head<2>()).norm();
    if (!std::isfinite(e)) continue;
    sum += e;
    ++n;
  }
  *count = n;
  return n > 0 ? sum / n : std::numeric_limits<double>::infinity();
}

}  // namespace

std::vector<std::vector<int>> AssociatePoses(const std::vector<std::vector<Pose2d>>& poses,
                                             const std::vector<Camera>& cameras,
                                             const MultiViewPoseOptions& options) {
  CheckInputs(poses, cameras, options);
  const int num_views = static_cast<int>(poses.size());
  std::vector<Node> nodes;
  std::vector<UndistortedPose> und, und_mirror;
  for (int v = 0; v < num_views; ++v) {
    for (int d = 0; d < static_cast<int>(poses[v].size()); ++d) {
      nodes.push_back({v, d});
      und.push_back(Undistort(poses[v][d].keypoints, cameras[v], options.min_keypoint_confidence));
      und_mirror.push_back(MirrorUndistorted(und.back()));
    }
  }
  const int n = static_cast<int>(nodes.size());
  // Pairwise distances between detections of different views.
  std::vector<std::vector<Eigen::Matrix3d>> fundamental(num_views,
                                                        std::vector<Eigen::Matrix3d>(num_views));
  for (int a = 0; a < num_views; ++a)
    for (int b = 0; b < num_views; ++b)
      if (a != b) fundamental[a][b] = FundamentalFromCameras(cameras[a], cameras[b]);
  Eigen::MatrixXd dist = Eigen::MatrixXd::Constant(n, n, kNoAffinity);
  struct Edge {
    double d;
    int i, j;
  };
  std::vector<Edge> edges;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const int va = nodes[i].view, vb = nodes[j].view;
      if (va == vb) continue;
      const Eigen::Matrix3d& f = fundamental[va][vb];  // x_b^T F x_a = 0
      const double d =
          std::min(PairDistance(f, und[i], und[j], options.min_shared_keypoints),
                   PairDistance(f, und[i], und_mirror[j], options.min_shared_keypoints));
      const double threshold =
          options.max_epipolar_distance * 0.5 * (cameras[va].width + cameras[vb].width);
      // Distances are stored relative to their threshold so that views of
      // different sizes compare.
      dist(i, j) = dist(j, i) = d / threshold;
      if (d < threshold) edges.push_back({d / threshold, i, j});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.d < y.d; });
  // Greedy average-linkage merging with at most one detection per view.
  std::vector<int> cluster_of(n);
  std::iota(cluster_of.begin(), cluster_of.end(), 0);
  std::vector<std::vector<int>> members(n);
  for (int i = 0; i < n; ++i) members[i] = {i};
  for (const Edge& e : edges) {
    const int ca = cluster_of[e.i], cb = cluster_of[e.j];
    if (ca == cb) continue;
    bool conflict = false;
    for (int x : members[ca])
      for (int y : members[cb]) conflict |= nodes[x].view == nodes[y].view;
    if (conflict) continue;
    double sum = 0;
    int cnt = 0;
    for (int x : members[ca]) {
      for (int y : members[cb]) {
        if (std::isfinite(dist(x, y))) {
          sum += dist(x, y);
          ++cnt;
        }
      }
    }
    if (cnt == 0 || sum / cnt >= 1.0) continue;
    for (int y : members[cb]) {
      cluster_of[y] = ca;
      members[ca].push_back(y);
    }
    members[cb].clear();
  }
  std::vector<std::vector<int>> clusters;
  for (int c = 0; c < n; ++c) {
    if (static_cast<int>(members[c].size()) < options.min_views) continue;
    std::vector<int> per_view(num_views, -1);
    for (int x : members[c]) per_view[nodes[x].view] = nodes[x].det;
    clusters.push_back(per_view);
  }
  return clusters;
}

std::vector<MultiViewPerson> EstimateMultiViewPoses(const std::vector<std::vector<Pose2d>>& poses,
                                                    const std::vector<Camera>& cameras,
                                                    const MultiViewPoseOptions& options) {
  const std::vector<std::vector<int>> clusters = AssociatePoses(poses, cameras, options);
  const int num_views = static_cast<int>(poses.size());
  std::vector<MultiViewPerson> people;
  for (const std::vector<int>& cluster : clusters) {
    MultiViewPerson person;
    person.detections = cluster;
    person.mirrored.assign(num_views, false);
    std::vector<Keypoints2d> own(num_views), mirror(num_views);
    std::vector<const Keypoints2d*> kps(num_views, nullptr);
    for (int v = 0; v < num_views; ++v) {
      if (cluster[v] < 0) continue;
      own[v] = poses[v][cluster[v]].keypoints;
      mirror[v] = MirrorCoco17(own[v]);
      kps[v] = &own[v];
    }
    double error = 0;
    if (options.mirror_gain > 0) {
      // Greedy leave-one-out mirroring: judge every view against the
      // skeleton of the other views; flip the view with the largest gain;
      // repeat until no view gains.
      for (int iter = 0; iter < num_views; ++iter) {
        int best_v = -1;
        double best_ratio = options.mirror_gain;
        for (int v = 0; v < num_views; ++v) {
          if (kps[v] == nullptr) continue;
          std::vector<const Keypoints2d*> others = kps;
          others[v] = nullptr;
          int n_others = 0;
          for (const Keypoints2d* k : others) n_others += k != nullptr;
          if (n_others < 2) continue;
          const auto joints = TriangulateCluster(others, cameras, options, &error);
          const Keypoints2d& alt = person.mirrored[v] ? own[v] : mirror[v];
          int n_cur = 0, n_alt = 0;
          const double e_cur =
              ViewError(*kps[v], joints, cameras[v], options.min_keypoint_confidence, &n_cur);
          const double e_alt =
              ViewError(alt, joints, cameras[v], options.min_keypoint_confidence, &n_alt);
          if (n_alt >= options.min_shared_keypoints && e_alt < best_ratio * e_cur) {
            best_ratio = e_alt / e_cur;
            best_v = v;
          }
        }
        if (best_v < 0) break;
        person.mirrored[best_v] = !person.mirrored[best_v];
        kps[best_v] = person.mirrored[best_v] ? &mirror[best_v] : &own[best_v];
      }
    }
    person.coco = TriangulateCluster(kps, cameras, options, &error);
    int valid = 0;
    for (const Eigen::Vector4d& j : person.coco) valid += j.w() > 0;
    if (valid < options.min_joints) continue;
    person.reprojection_error = error;
    person.pose.joints = H36m17FromCoco17(person.coco);
    person.pose.person_id = -1;
    people.push_back(std::move(person));
  }
  return people;
}

std::vector<Pose3d> TriangulatePoses(const std::vector<std::vector<Pose2d>>& poses,
                                     const std::vector<Camera>& cameras,
                                     const MultiViewPoseOptions& options) {
  std::vector<Pose3d> out;
  for (const MultiViewPerson& p : EstimateMultiViewPoses(poses, cameras, options))
    out.push_back(p.pose);
  return out;
}

}  // namespace u4d
