#include "u4d/features/object_regions.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {

void ObjectRegionOptions::Check() const {
  silhouette.Check();
  U4D_CHECK(percentile_near >= 0 && percentile_near <= percentile_far && percentile_far <= 1,
            "ObjectRegionOptions: need 0 <= percentile_near <= percentile_far <= 1, got {} and {}",
            percentile_near, percentile_far);
  U4D_CHECK(std::isfinite(depth_margin_m) && depth_margin_m >= 0,
            "ObjectRegionOptions.depth_margin_m must be >= 0, got {}", depth_margin_m);
  U4D_CHECK(min_points >= 1, "ObjectRegionOptions.min_points must be >= 1, got {}", min_points);
  U4D_CHECK(std::isfinite(joint_depth_margin_m) && joint_depth_margin_m >= 0,
            "ObjectRegionOptions.joint_depth_margin_m must be >= 0, got {}", joint_depth_margin_m);
  U4D_CHECK(std::isfinite(limb_radius_m) && limb_radius_m >= 0,
            "ObjectRegionOptions.limb_radius_m must be >= 0, got {}", limb_radius_m);
  U4D_CHECK(std::isfinite(min_joint_confidence),
            "ObjectRegionOptions.min_joint_confidence must be finite");
  U4D_CHECK(hull_near_m > 0 && hull_far_m > hull_near_m && std::isfinite(hull_far_m),
            "ObjectRegionOptions: need 0 < hull_near_m < hull_far_m, got {} and {}", hull_near_m,
            hull_far_m);
  U4D_CHECK(hull_depth_steps >= 2, "ObjectRegionOptions.hull_depth_steps must be >= 2, got {}",
            hull_depth_steps);
  U4D_CHECK(hull_max_pixels >= 1, "ObjectRegionOptions.hull_max_pixels must be >= 1, got {}",
            hull_max_pixels);
}

std::string ToString(DepthSource source) {
  switch (source) {
    case DepthSource::kSparsePoints:
      return "sparse_points";
    case DepthSource::kJoints:
      return "joints";
    case DepthSource::kVisualHull:
      return "visual_hull";
    case DepthSource::kNone:
      return "none";
  }
  return "?";
}

namespace {

bool JointValid(const Pose3d& pose, int j, const ObjectRegionOptions& options) {
  const Eigen::Vector4d& q = pose.joints[j];
  return q.allFinite() && q[3] >= options.min_joint_confidence && q[3] > 0;
}

// The CV_8U region of `object` in view v from the initial masks.
cv::Mat ObjectMask(const cv::Mat& mask, int view, int object,
                   const InstanceAssociation& association, int width, int height) {
  cv::Mat out = cv::Mat::zeros(height, width, CV_8U);
  if (mask.empty() || view >= static_cast<int>(association.object_of.size())) return out;
  for (const auto& [id, obj] : association.object_of[view]) {
    if (obj != object) continue;
    cv::Mat ids;
    mask.convertTo(ids, CV_32S);
    out.setTo(255, ids == id);
  }
  return out;
}

double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double pos = p * (v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

void CheckInputs(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& masks,
                 const char* what) {
  U4D_CHECK(masks.size() == cameras.size(), "{}: {} masks for {} views", what, masks.size(),
            cameras.size());
  for (size_t v = 0; v < masks.size(); ++v) {
    U4D_CHECK(masks[v].empty() || (masks[v].channels() == 1 && masks[v].cols == cameras[v].width &&
                                   masks[v].rows == cameras[v].height),
              "{}: mask of view {} must be single-channel {}x{}, got {}x{}", what, v,
              cameras[v].width, cameras[v].height, masks[v].cols, masks[v].rows);
  }
}

}  // namespace

std::vector<int> AssociatePoses(const std::vector<Camera>& cameras,
                                const std::vector<cv::Mat>& masks,
                                const InstanceAssociation& association,
                                const std::vector<Pose3d>& poses,
                                const ObjectRegionOptions& options) {
  options.Check();
  CheckInputs(cameras, masks, "AssociatePoses");
  std::vector<int> out(poses.size(), 0);
  for (size_t p = 0; p < poses.size(); ++p) {
    std::vector<int> votes(association.num_objects + 1, 0);
    for (size_t v = 0; v < cameras.size(); ++v) {
      for (int j = 0; j < 17; ++j) {
        if (!JointValid(poses[p], j, options)) continue;
        const Eigen::Vector2d px = cameras[v].Project(poses[p].joints[j].head<3>());
        const int obj = association.ObjectOf(static_cast<int>(v), MaskIdAt(masks[v], px));
        if (obj > 0 && obj <= association.num_objects) ++votes[obj];
      }
    }
    const auto best = std::max_element(votes.begin() + 1, votes.end());
    if (best != votes.end() && *best > 0) out[p] = static_cast<int>(best - votes.begin());
  }
  return out;
}

std::vector<std::vector<ObjectRegion>> InitialObjectRegions(const std::vector<Camera>& cameras,
                                                            const std::vector<cv::Mat>& masks,
                                                            const InstanceAssociation& association,
                                                            const std::vector<SparsePoint>& points,
                                                            const std::vector<Pose3d>& poses,
                                                            const ObjectRegionOptions& options) {
  options.Check();
  CheckInputs(cameras, masks, "InitialObjectRegions");
  const int num_views = static_cast<int>(cameras.size());
  const int num_objects = association.num_objects;
  const std::vector<int> pose_object = AssociatePoses(cameras, masks, association, poses, options);
  std::vector<const Pose3d*> pose_of(num_objects + 1, nullptr);
  for (size_t p = 0; p < poses.size(); ++p) {
    if (pose_object[p] > 0 && pose_of[pose_object[p]] == nullptr)
      pose_of[pose_object[p]] = &poses[p];
  }
  std::vector<std::vector<ObjectRegion>> regions(num_objects, std::vector<ObjectRegion>(num_views));
  // Initial regions.
  for (int o = 1; o <= num_objects; ++o) {
    for (int v = 0; v < num_views; ++v) {
      ObjectRegion& r = regions[o - 1][v];
      r.instance = o;
      r.view = v;
      r.mask = ObjectMask(masks[v], v, o, association, cameras[v].width, cameras[v].height);
      r.detected = cv::countNonZero(r.mask) > 0;
    }
  }
  // Human-pose constraint (uses the initial regions of the other objects).
  for (int o = 1; o <= num_objects; ++o) {
    const Pose3d* pose = pose_of[o];
    if (pose == nullptr) continue;
    for (int v = 0; v < num_views; ++v) {
      const Camera& cam = cameras[v];
      ObjectRegion& r = regions[o - 1][v];
      cv::Mat added = cv::Mat::zeros(r.mask.size(), CV_8U);
      for (const auto& [a, b] : H36m17Bones()) {
        if (!JointValid(*pose, a, options) || !JointValid(*pose, b, options)) continue;
        const Eigen::Vector3d pa = pose->joints[a].head<3>(), pb = pose->joints[b].head<3>();
        const Eigen::Vector2d xa = cam.Project(pa), xb = cam.Project(pb);
        if (!xa.allFinite() || !xb.allFinite()) continue;
        const bool outside = MaskIdAt(r.mask, xa) == 0 || MaskIdAt(r.mask, xb) == 0;
        if (!outside) continue;
        const double depth = 0.5 * (cam.Depth(pa) + cam.Depth(pb));
        const int radius =
            std::max(1, static_cast<int>(std::lround(options.limb_radius_m * cam.K(0, 0) / depth)));
        cv::line(added, cv::Point(std::lround(xa.x()), std::lround(xa.y())),
                 cv::Point(std::lround(xb.x()), std::lround(xb.y())), 255, 2 * radius + 1,
                 cv::LINE_8);
        cv::circle(added, cv::Point(std::lround(xa.x()), std::lround(xa.y())), radius, 255, -1);
        cv::circle(added, cv::Point(std::lround(xb.x()), std::lround(xb.y())), radius, 255, -1);
      }
      for (int other = 1; other <= num_objects; ++other) {
        if (other != o) added.setTo(0, regions[other - 1][v].mask);
      }
      added.setTo(0, r.mask);
      r.pose_added_pixels = cv::countNonZero(added);
      r.mask |= added;
    }
  }
  // Depth ranges.
  std::vector<std::vector<std::vector<double>>> depths(num_objects,
                                                       std::vector<std::vector<double>>(num_views));
  for (const SparsePoint& p : points) {
    if (p.instance < 1 || p.instance > num_objects) continue;
    for (const auto& [v, k] : p.observations) {
      if (v >= 0 && v < num_views)
        depths[p.instance - 1][v].push_back(cameras[v].Depth(p.position));
    }
  }
  for (int o = 1; o <= num_objects; ++o) {
    for (int v = 0; v < num_views; ++v) {
      ObjectRegion& r = regions[o - 1][v];
      const Camera& cam = cameras[v];
      const std::vector<double>& d = depths[o - 1][v];
      r.num_points = static_cast<int>(d.size());
      if (r.num_points >= options.min_points) {
        r.depth_near = Percentile(d, options.percentile_near) - options.depth_margin_m;
        r.depth_far = Percentile(d, options.percentile_far) + options.depth_margin_m;
        r.depth_source = DepthSource::kSparsePoints;
      } else if (pose_of[o] != nullptr) {
        double lo = 1e300, hi = -1e300;
        for (int j = 0; j < 17; ++j) {
          if (!JointValid(*pose_of[o], j, options)) continue;
          const double z = cam.Depth(pose_of[o]->joints[j].head<3>());
          lo = std::min(lo, z);
          hi = std::max(hi, z);
        }
        if (hi >= lo) {
          r.depth_near = lo - options.joint_depth_margin_m;
          r.depth_far = hi + options.joint_depth_margin_m;
          r.depth_source = DepthSource::kJoints;
        }
      }
      if (r.depth_source == DepthSource::kNone && r.detected) {
        std::vector<cv::Point> pixels;
        cv::findNonZero(r.mask, pixels);
        const size_t stride = std::max<size_t>(1, pixels.size() / options.hull_max_pixels);
        double lo = 1e300, hi = -1e300;
        const double ratio = std::log(options.hull_far_m / options.hull_near_m);
        for (size_t i = 0; i < pixels.size(); i += stride) {
          const Eigen::Vector2d px(pixels[i].x, pixels[i].y);
          for (int s = 0; s < options.hull_depth_steps; ++s) {
            const double z =
                options.hull_near_m * std::exp(ratio * s / (options.hull_depth_steps - 1));
            const Eigen::Vector3d x = cam.Unproject(px, z);
            bool inside = true;
            for (int w = 0; w < num_views && inside; ++w) {
              if (w == v || !regions[o - 1][w].detected) continue;
              const Eigen::Vector2d q = cameras[w].Project(x);
              if (!q.allFinite()) continue;
              if (cameras[w].InImage(q) && MaskIdAt(regions[o - 1][w].mask, q) == 0) inside = false;
            }
            if (inside) {
              lo = std::min(lo, z);
              hi = std::max(hi, z);
            }
          }
        }
        if (hi >= lo) {
          r.depth_near = lo - options.depth_margin_m;
          r.depth_far = hi + options.depth_margin_m;
          r.depth_source = DepthSource::kVisualHull;
        }
      }
      if (r.depth_source == DepthSource::kNone) {
        r.depth_near = options.hull_near_m;
        r.depth_far = options.hull_far_m;
      }
      r.depth_near = std::max(r.depth_near, 1e-3);
    }
  }
  return regions;
}

}  // namespace u4d
