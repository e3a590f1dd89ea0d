#include "u4d/features/sparse_points.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>

#include <tbb/parallel_for.h>
#include <Eigen/Dense>

#include "u4d/geometry/triangulation.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

namespace u4d {

void SparseOptions::Check() const {
  U4D_CHECK(std::isfinite(max_reprojection_px) && max_reprojection_px > 0,
            "SparseOptions.max_reprojection_px must be > 0, got {}", max_reprojection_px);
  U4D_CHECK(std::isfinite(min_triangulation_angle_deg) && min_triangulation_angle_deg >= 0 &&
                min_triangulation_angle_deg < 90,
            "SparseOptions.min_triangulation_angle_deg must be in [0, 90), got {}",
            min_triangulation_angle_deg);
  U4D_CHECK(min_views >= 2, "SparseOptions.min_views must be >= 2, got {}", min_views);
  U4D_CHECK(refine_iterations >= 0, "SparseOptions.refine_iterations must be >= 0, got {}",
            refine_iterations);
  U4D_CHECK(min_links >= 1, "SparseOptions.min_links must be >= 1, got {}", min_links);
}

void SparseFrameOptions::Check() const {
  keypoints.Check();
  matching.Check();
  sparse.Check();
}

namespace {

double SquaredError(const Eigen::Vector3d& x, const std::vector<Observation>& obs) {
  double sum = 0;
  for (const Observation& o : obs) sum += (o.camera->Project(x) - o.pixel).squaredNorm();
  return sum;  // NaN when behind a camera
}

// Levenberg-Marquardt on the point's 3 coordinates, numeric Jacobian.
Eigen::Vector3d Refine(Eigen::Vector3d x, const std::vector<Observation>& obs, int iterations) {
  double cost = SquaredError(x, obs);
  if (!std::isfinite(cost)) return x;
  double lambda = 1e-3;
  const int n = static_cast<int>(obs.size());
  for (int it = 0; it < iterations; ++it) {
    Eigen::VectorXd r(2 * n);
    Eigen::MatrixXd J(2 * n, 3);
    const double h = 1e-6 * std::max(1.0, x.norm());
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d p = obs[i].camera->Project(x);
      r.segment<2>(2 * i) = p - obs[i].pixel;
      for (int c = 0; c < 3; ++c) {
        Eigen::Vector3d xp = x, xm = x;
        xp[c] += h;
        xm[c] -= h;
        J.block<2, 1>(2 * i, c) =
            (obs[i].camera->Project(xp) - obs[i].camera->Project(xm)) / (2 * h);
      }
    }
    if (!r.allFinite() || !J.allFinite()) break;
    const Eigen::Matrix3d H = J.transpose() * J;
    const Eigen::Vector3d g = J.transpose() * r;
    bool improved = false;
    for (int tries = 0; tries < 8 && !improved; ++tries) {
      Eigen::Matrix3d A = H;
      A.diagonal() += lambda * H.diagonal().cwiseMax(1e-12);
      const Eigen::Vector3d dx = A.ldlt().solve(-g);
      const Eigen::Vector3d candidate = x + dx;
      const double c = SquaredError(candidate, obs);
      if (std::isfinite(c) && c < cost) {
        const bool converged = cost - c < 1e-10 * cost + 1e-14;
        x = candidate;
        cost = c;
        lambda = std::max(lambda * 0.1, 1e-9);
        improved = true;
        if (converged) return x;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  return x;
}

double MaxRayAngleDeg(const Eigen::Vector3d& x, const std::vector<Observation>& obs) {
  double best = 0;
  for (size_t i = 0; i < obs.size(); ++i) {
    const Eigen::Vector3d a = (x - obs[i].camera->Center()).normalized();
    for (size_t j = i + 1; j < obs.size(); ++j) {
      const Eigen::Vector3d b = (x - obs[j].camera->Center()).normalized();
      best = std::max(best, std::atan2(a.cross(b).norm(), a.dot(b)));
    }
  }
  return best * 180.0 / M_PI;
}

}  // namespace

std::vector<SparsePoint> TriangulateTracks(const std::vector<Camera>& cameras,
                                           const std::vector<ViewKeypoints>& keypoints,
                                           const std::vector<Track>& tracks,
                                           const SparseOptions& options) {
  options.Check();
  U4D_CHECK(cameras.size() == keypoints.size(),
            "TriangulateTracks: {} cameras but {} keypoint sets", cameras.size(), keypoints.size());
  const int num_views = static_cast<int>(cameras.size());
  for (size_t t = 0; t < tracks.size(); ++t) {
    for (const auto& [v, k] : tracks[t]) {
      U4D_CHECK(v >= 0 && v < num_views && k >= 0 && k < keypoints[v].size(),
                "TriangulateTracks: track {} refers to (view {}, keypoint {}) out of range", t, v,
                k);
    }
  }
  std::vector<SparsePoint> result(tracks.size());
  std::vector<char> keep(tracks.size(), 0);
  tbb::parallel_for(size_t{0}, tracks.size(), [&](size_t t) {
    Track track = tracks[t];
    std::vector<Observation> obs;
    for (const auto& [v, k] : track) {
      Observation o;
      o.camera = &cameras[v];
      o.pixel = Eigen::Vector2d(keypoints[v].keypoints[k].pt.x, keypoints[v].keypoints[k].pt.y);
      obs.push_back(o);
    }
    Eigen::Vector3d x;
    while (true) {
      if (static_cast<int>(obs.size()) < options.min_views) return;
      x = TriangulateDlt(obs);
      if (!x.allFinite()) return;
      x = Refine(x, obs, options.refine_iterations);
      int worst = -1;
      double worst_error = -1;
      for (size_t i = 0; i < obs.size(); ++i) {
        double e = (obs[i].camera->Project(x) - obs[i].pixel).norm();
        if (!std::isfinite(e)) e = std::numeric_limits<double>::max();
        if (e > worst_error) {
          worst_error = e;
          worst = static_cast<int>(i);
        }
      }
      if (worst_error <= options.max_reprojection_px) break;
      obs.erase(obs.begin() + worst);
      track.erase(track.begin() + worst);
    }
    for (const Observation& o : obs) {
      if (!(o.camera->Depth(x) > 0)) return;  // cheirality
    }
    if (MaxRayAngleDeg(x, obs) < options.min_triangulation_angle_deg) return;
    SparsePoint& p = result[t];
    p.position = x;
    p.observations = track;
    for (const Observation& o : obs) p.pixels.push_back(o.pixel);
    p.reprojection_rmse = ReprojectionRmse(x, obs);
    keep[t] = 1;
  });
  std::vector<SparsePoint> out;
  for (size_t t = 0; t < tracks.size(); ++t) {
    if (keep[t]) out.push_back(std::move(result[t]));
  }
  return out;
}

int MaskIdAt(const cv::Mat& mask, const Eigen::Vector2d& pixel) {
  if (mask.empty() || !pixel.allFinite()) return 0;
  const int c = static_cast<int>(std::lround(pixel.x()));
  const int r = static_cast<int>(std::lround(pixel.y()));
  if (c < 0 || r < 0 || c >= mask.cols || r >= mask.rows) return 0;
  switch (mask.depth()) {
    case CV_8U:
      return mask.at<uint8_t>(r, c);
    case CV_16U:
      return mask.at<uint16_t>(r, c);
    case CV_16S:
      return mask.at<int16_t>(r, c);
    case CV_32S:
      return mask.at<int32_t>(r, c);
    default:
      U4D_CHECK(false, "MaskIdAt: unsupported mask type {}", mask.type());
  }
  return 0;
}

int InstanceAssociation::ObjectOf(int view, int mask_id) const {
  if (mask_id == 0 || view < 0 || view >= static_cast<int>(object_of.size())) return 0;
  const auto it = object_of[view].find(mask_id);
  return it == object_of[view].end() ? 0 : it->second;
}

namespace {

void CheckMasks(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& masks,
                const std::vector<SparsePoint>& points, const char* what) {
  U4D_CHECK(masks.size() == cameras.size(), "{}: {} masks for {} views", what, masks.size(),
            cameras.size());
  for (size_t v = 0; v < masks.size(); ++v) {
    U4D_CHECK(masks[v].empty() || (masks[v].channels() == 1 && masks[v].cols == cameras[v].width &&
                                   masks[v].rows == cameras[v].height),
              "{}: mask of view {} must be single-channel {}x{}, got {}x{} with {} channels", what,
              v, cameras[v].width, cameras[v].height, masks[v].cols, masks[v].rows,
              masks[v].channels());
  }
  for (const SparsePoint& p : points) {
    for (const auto& o : p.observations) {
      U4D_CHECK(o.first >= 0 && o.first < static_cast<int>(masks.size()),
                "{}: a point observes view {} but there are {} masks", what, o.first, masks.size());
    }
  }
}

}  // namespace

std::string ClassOf(const InstanceClasses& classes, int view, int mask_id) {
  if (view < 0 || view >= static_cast<int>(classes.size())) return "";
  const auto it = classes[view].find(mask_id);
  return it == classes[view].end() ? "" : it->second;
}

InstanceAssociation AssociateInstances(const std::vector<Camera>& cameras,
                                       const std::vector<cv::Mat>& masks,
                                       const std::vector<SparsePoint>& points,
                                       const SparseOptions& options,
                                       const InstanceClasses* classes) {
  options.Check();
  CheckMasks(cameras, masks, points, "AssociateInstances");
  U4D_CHECK(classes == nullptr || classes->size() == masks.size(),
            "AssociateInstances: classes of {} views for {} masks", classes ? classes->size() : 0,
            masks.size());
  const int num_views = static_cast<int>(masks.size());
  // Labels (view, id) -> index.
  std::map<std::pair<int, int>, int> label_index;
  std::vector<std::pair<int, int>> labels;
  std::vector<int> label_votes;
  std::map<std::pair<int, int>, int> links;  // (label a < label b) -> count
  for (const SparsePoint& p : points) {
    std::vector<int> ls;
    for (size_t i = 0; i < p.observations.size(); ++i) {
      const int v = p.observations[i].first;
      const int id = MaskIdAt(masks[v], p.pixels[i]);
      if (id == 0) continue;
      auto [it, inserted] = label_index.emplace(std::make_pair(v, id), labels.size());
      if (inserted) {
        labels.emplace_back(v, id);
        label_votes.push_back(0);
      }
      ++label_votes[it->second];
      ls.push_back(it->second);
    }
    for (size_t i = 0; i < ls.size(); ++i) {
      for (size_t j = i + 1; j < ls.size(); ++j) {
        ++links[{std::min(ls[i], ls[j]), std::max(ls[i], ls[j])}];
      }
    }
  }
  std::vector<std::tuple<int, int, int>> edges;  // count, a, b
  for (const auto& [ab, count] : links) {
    if (count >= options.min_links) edges.emplace_back(count, ab.first, ab.second);
  }
  std::sort(edges.begin(), edges.end(), [](const auto& a, const auto& b) {
    return std::get<0>(a) != std::get<0>(b) ? std::get<0>(a) > std::get<0>(b) : a < b;
  });
  const int n = static_cast<int>(labels.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::set<int>> views_of(n);
  for (int i = 0; i < n; ++i) views_of[i].insert(labels[i].first);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const auto& [count, a, b] : edges) {
    const int ra = find(a), rb = find(b);
    if (ra == rb) continue;
    bool conflict =
        classes != nullptr && ClassOf(*classes, labels[ra].first, labels[ra].second) !=
                                  ClassOf(*classes, labels[rb].first, labels[rb].second);
    for (int v : views_of[ra]) conflict = conflict || views_of[rb].count(v) > 0;
    if (conflict) continue;
    parent[ra] = rb;
    views_of[rb].insert(views_of[ra].begin(), views_of[ra].end());
  }
  // Clusters spanning at least two views become objects, by decreasing votes.
  std::map<int, int> cluster_votes;
  for (int i = 0; i < n; ++i) {
    if (views_of[find(i)].size() >= 2) cluster_votes[find(i)] += label_votes[i];
  }
  std::vector<std::pair<int, int>> order;  // (-votes, root)
  order.reserve(cluster_votes.size());
  for (const auto& [root, votes] : cluster_votes) order.emplace_back(-votes, root);
  std::sort(order.begin(), order.end());
  std::map<int, int> object_of_root;
  for (size_t k = 0; k < order.size(); ++k)
    object_of_root[order[k].second] = static_cast<int>(k) + 1;
  InstanceAssociation out;
  out.num_objects = static_cast<int>(order.size());
  out.object_of.resize(num_views);
  for (int i = 0; i < n; ++i) {
    const auto it = object_of_root.find(find(i));
    if (it != object_of_root.end()) out.object_of[labels[i].first][labels[i].second] = it->second;
  }
  return out;
}

void AssignInstances(const std::vector<cv::Mat>& masks, const InstanceAssociation& association,
                     std::vector<SparsePoint>& points, const std::vector<cv::Mat>* unknown) {
  U4D_CHECK(unknown == nullptr || unknown->size() == masks.size(),
            "AssignInstances: {} unknown masks for {} masks", unknown ? unknown->size() : 0,
            masks.size());
  for (SparsePoint& p : points) {
    std::map<int, int> votes;
    for (size_t i = 0; i < p.observations.size(); ++i) {
      const int v = p.observations[i].first;
      U4D_CHECK(v >= 0 && v < static_cast<int>(masks.size()),
                "AssignInstances: a point observes view {} but there are {} masks", v,
                masks.size());
      const int id = MaskIdAt(masks[v], p.pixels[i]);
      if (id == 0) {
        if (unknown == nullptr || MaskIdAt((*unknown)[v], p.pixels[i]) == 0) ++votes[0];
      } else if (const int object = association.ObjectOf(v, id); object > 0) {
        ++votes[object];
      }
    }
    int best = 0, best_votes = -1;
    for (const auto& [object, count] : votes) {  // ascending ids: background first
      if (count > best_votes || (count == best_votes && best == 0)) {
        best = object;
        best_votes = count;
      }
    }
    p.instance = best;
  }
}

SparseFrame ReconstructSparseFrame(const std::vector<Camera>& cameras,
                                   const std::vector<cv::Mat>& images,
                                   const std::vector<cv::Mat>& masks,
                                   const SparseFrameOptions& options) {
  options.Check();
  const size_t n = cameras.size();
  U4D_CHECK(images.size() == n && masks.size() == n,
            "ReconstructSparseFrame: {} cameras, {} images, {} masks (must be equal)", n,
            images.size(), masks.size());
  SparseFrame frame;
  Timer timer;
  frame.keypoints.resize(n);
  tbb::parallel_for(size_t{0}, n, [&](size_t v) {
    U4D_CHECK(images[v].cols == cameras[v].width && images[v].rows == cameras[v].height,
              "ReconstructSparseFrame: image of view {} is {}x{}, camera is {}x{}", v,
              images[v].cols, images[v].rows, cameras[v].width, cameras[v].height);
    cv::Mat detect_mask;
    if (options.detection_mask_dilation_px >= 0 && !masks[v].empty() &&
        cv::countNonZero(masks[v]) > 0) {  // a view without detections: whole image
      detect_mask = MaskFromInstances(masks[v], options.detection_mask_dilation_px);
    }
    frame.keypoints[v] = DetectKeypoints(images[v], detect_mask, options.keypoints);
  });
  frame.seconds_detect = timer.Seconds();
  timer.Restart();
  frame.tracks = MatchAllViews(cameras, frame.keypoints, options.matching);
  frame.seconds_match = timer.Seconds();
  timer.Restart();
  frame.points = TriangulateTracks(cameras, frame.keypoints, frame.tracks, options.sparse);
  frame.seconds_triangulate = timer.Seconds();
  timer.Restart();
  frame.association = AssociateInstances(cameras, masks, frame.points, options.sparse);
  AssignInstances(masks, frame.association, frame.points);
  frame.seconds_assign = timer.Seconds();
  return frame;
}

}  // namespace u4d
