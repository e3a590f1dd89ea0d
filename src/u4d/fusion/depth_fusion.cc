#include "u4d/fusion/depth_fusion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>

#include "u4d/fusion/depth_sampling.h"
#include "u4d/fusion/hole_fill.h"
#include "u4d/util/check.h"

namespace u4d {

using fusion_internal::CheckMap;
using fusion_internal::SampleObjectDepth;

void FusionOptions::Check() const {
  U4D_CHECK(pixel_step >= 1, "FusionOptions.pixel_step must be >= 1, found {}", pixel_step);
  U4D_CHECK(max_depth_jump > 0, "FusionOptions.max_depth_jump must be > 0, found {}",
            max_depth_jump);
  U4D_CHECK(max_view_angle_deg > 0 && max_view_angle_deg <= 90,
            "FusionOptions.max_view_angle_deg must be in (0, 90], found {}", max_view_angle_deg);
  U4D_CHECK(min_agreeing_views >= 0, "FusionOptions.min_agreeing_views must be >= 0, found {}",
            min_agreeing_views);
  U4D_CHECK(consistency_tolerance > 0, "FusionOptions.consistency_tolerance must be > 0, found {}",
            consistency_tolerance);
  U4D_CHECK(min_confidence >= 0 && min_confidence <= 1,
            "FusionOptions.min_confidence must be in [0, 1], found {}", min_confidence);
  U4D_CHECK(min_points >= 1, "FusionOptions.min_points must be >= 1, found {}", min_points);
  U4D_CHECK(poisson_depth >= 4 && poisson_depth <= 12,
            "FusionOptions.poisson_depth must be in [4, 12], found {}", poisson_depth);
  U4D_CHECK(poisson_scale >= 1, "FusionOptions.poisson_scale must be >= 1, found {}",
            poisson_scale);
  U4D_CHECK(poisson_threads == -1 || poisson_threads >= 1,
            "FusionOptions.poisson_threads must be -1 or >= 1, found {}", poisson_threads);
  U4D_CHECK(density_quantile >= 0 && density_quantile < 1,
            "FusionOptions.density_quantile must be in [0, 1), found {}", density_quantile);
  U4D_CHECK(trim_distance_factor >= 0,
            "FusionOptions.trim_distance_factor must be >= 0 (0 = off), found {}",
            trim_distance_factor);
  U4D_CHECK(fill_hole_radius >= 0,
            "FusionOptions.fill_hole_radius must be >= 0 (0 = off), found {}", fill_hole_radius);
  U4D_CHECK(min_component_fraction >= 0 && min_component_fraction < 1,
            "FusionOptions.min_component_fraction must be in [0, 1), found {}",
            min_component_fraction);
  silhouette.Check();
}

bool FusedMesh::Empty() const { return !mesh || mesh->triangles_.empty(); }

namespace {

void CheckInputs(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& depths,
                 const std::vector<cv::Mat>& ids, const std::vector<cv::Mat>& images,
                 int object_id) {
  U4D_CHECK(!cameras.empty(), "FuseObject: no views given");
  U4D_CHECK(depths.size() == cameras.size() && ids.size() == cameras.size() &&
                (images.empty() || images.size() == cameras.size()),
            "FuseObject: expected one depth, instance and image map per camera ({}), found {} "
            "depths, {} instance maps, {} images",
            cameras.size(), depths.size(), ids.size(), images.size());
  U4D_CHECK(object_id >= 1 && object_id <= 65535,
            "FuseObject: object_id must be an instance id in [1, 65535], found {}", object_id);
  for (size_t v = 0; v < cameras.size(); ++v) {
    const Camera& c = cameras[v];
    c.Check(fmt::format("FuseObject: camera of view {}", v));
    CheckMap(depths[v], CV_32FC1, c.width, c.height,
             fmt::format("FuseObject: depth of view {}", v));
    CheckMap(ids[v], CV_16UC1, c.width, c.height,
             fmt::format("FuseObject: instance ids of view {}", v));
    if (!images.empty() && !images[v].empty())
      CheckMap(images[v], CV_8UC3, c.width, c.height,
               fmt::format("FuseObject: image of view {}", v));
  }
}

// World points of the object's pixels of one view (NaN elsewhere).
cv::Mat BackProject(const Camera& cam, const cv::Mat& depth, const cv::Mat& ids, int object_id) {
  cv::Mat pts(depth.size(), CV_64FC3, cv::Scalar::all(std::nan("")));
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x) {
      const float d = depth.at<float>(y, x);
      if (ids.at<uint16_t>(y, x) != object_id || !(d > 0) || !std::isfinite(d)) continue;
      const Eigen::Vector3d p = cam.Unproject(Eigen::Vector2d(x, y), d);
      pts.at<cv::Vec3d>(y, x) = cv::Vec3d(p.x(), p.y(), p.z());
    }
  return pts;
}

// Tangent of the back-projected surface along (dx, dy) at (x, y); false when
// no usable neighbour exists.
bool Tangent(const cv::Mat& pts, const cv::Mat& depth, int x, int y, int dx, int dy,
             double max_jump, Eigen::Vector3d* t) {
  auto at = [&](int xx, int yy, Eigen::Vector3d* p) {
    if (xx < 0 || yy < 0 || xx >= pts.cols || yy >= pts.rows) return false;
    const cv::Vec3d v = pts.at<cv::Vec3d>(yy, xx);
    if (std::isnan(v[0])) return false;
    if (std::abs(depth.at<float>(yy, xx) - depth.at<float>(y, x)) > max_jump) return false;
    *p = Eigen::Vector3d(v[0], v[1], v[2]);
    return true;
  };
  Eigen::Vector3d a, b, c;
  if (!at(x, y, &c)) return false;  // no point at the centre: no tangent
  const bool has_a = at(x + dx, y + dy, &a), has_b = at(x - dx, y - dy, &b);
  if (has_a && has_b) {
    *t = a - b;
  } else if (has_a) {
    *t = a - c;
  } else if (has_b) {
    *t = c - b;
  } else {
    return false;
  }
  return t->norm() > 0;
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

}  // namespace

std::vector<OrientedPoint> ObjectPoints(const std::vector<Camera>& cameras,
                                        const std::vector<cv::Mat>& depths,
                                        const std::vector<cv::Mat>& instance_ids,
                                        const std::vector<cv::Mat>& images, int object_id,
                                        const FusionOptions& options, int* num_found) {
  options.Check();
  CheckInputs(cameras, depths, instance_ids, images, object_id);
  const int n_views = static_cast<int>(cameras.size());
  const double min_cos = std::cos(options.max_view_angle_deg * M_PI / 180.0);
  std::vector<OrientedPoint> all;
  for (int v = 0; v < n_views; ++v) {
    const Camera& cam = cameras[v];
    const cv::Mat pts = BackProject(cam, depths[v], instance_ids[v], object_id);
    const Eigen::Vector3d centre = cam.Center();
    const int s = options.pixel_step;
    for (int y = 0; y < pts.rows; y += s)
      for (int x = 0; x < pts.cols; x += s) {
        const cv::Vec3d& pv = pts.at<cv::Vec3d>(y, x);
        if (std::isnan(pv[0])) continue;
        Eigen::Vector3d tx, ty;
        if (!Tangent(pts, depths[v], x, y, 1, 0, options.max_depth_jump, &tx) ||
            !Tangent(pts, depths[v], x, y, 0, 1, options.max_depth_jump, &ty))
          continue;
        OrientedPoint p;
        p.position = Eigen::Vector3d(pv[0], pv[1], pv[2]);
        p.normal = tx.cross(ty);
        if (p.normal.norm() == 0) continue;
        p.normal.normalize();
        const Eigen::Vector3d to_cam = (centre - p.position).normalized();
        if (p.normal.dot(to_cam) < 0) p.normal = -p.normal;
        p.confidence = p.normal.dot(to_cam);  // cos of the view angle, agreement below
        if (!images.empty() && !images[v].empty()) {
          const cv::Vec3b c = images[v].at<cv::Vec3b>(y, x);
          p.color = Eigen::Vector3d(c[2], c[1], c[0]) / 255.0;
        } else {
          p.color = Eigen::Vector3d::Constant(0.5);
        }
        p.view = v;
        all.push_back(p);
      }
  }
  if (num_found) *num_found = static_cast<int>(all.size());

  std::vector<OrientedPoint> kept;
  kept.reserve(all.size());
  const double tol = options.consistency_tolerance;
  for (OrientedPoint& p : all) {
    int agree = 0, conflict = 0;
    for (int w = 0; w < n_views; ++w) {
      if (w == p.view) continue;
      const Camera& cam = cameras[w];
      const Eigen::Vector2d px = cam.Project(p.position);
      if (!std::isfinite(px.x()) || !cam.InImage(px)) continue;
      const double d =
          SampleObjectDepth(depths[w], instance_ids[w], object_id, px, options.max_depth_jump);
      if (d <= 0) continue;  // the object is not seen there (hidden or outside its mask)
      const double z = cam.Depth(p.position);
      if (std::abs(z - d) <= tol) {
        ++agree;
      } else if (z < d - tol) {
        ++conflict;  // the point would float in front of what view w sees
      }
    }
    p.agreeing_views = agree;
    p.confidence *= agree + conflict > 0 ? static_cast<double>(agree) / (agree + conflict) : 0.5;
    if (options.consistency_filter && agree < options.min_agreeing_views) continue;
    if (p.normal.dot((cameras[p.view].Center() - p.position).normalized()) < min_cos) continue;
    if (p.confidence < options.min_confidence) continue;
    kept.push_back(p);
  }
  return kept;
}

FusedMesh FuseObject(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& depths,
                     const std::vector<cv::Mat>& instance_ids, const std::vector<cv::Mat>& images,
                     int object_id, const FusionOptions& options) {
  FusedMesh out;
  out.object_id = object_id;
  out.mesh = std::make_shared<open3d::geometry::TriangleMesh>();
  const std::vector<OrientedPoint> points =
      ObjectPoints(cameras, depths, instance_ids, images, object_id, options, &out.num_points);
  out.num_points_used = static_cast<int>(points.size());
  if (out.num_points_used < options.min_points) return out;

  open3d::geometry::PointCloud cloud;
  cloud.points_.reserve(points.size());
  for (const OrientedPoint& p : points) {
    cloud.points_.push_back(p.position);
    cloud.normals_.push_back(p.normal);
    cloud.colors_.push_back(p.color);
    out.mean_confidence += p.confidence;
  }
  out.mean_confidence /= points.size();
  const std::vector<double> spacing = cloud.ComputeNearestNeighborDistance();
  out.point_spacing = Quantile(spacing, 0.5);

  auto [mesh, densities] = open3d::geometry::TriangleMesh::CreateFromPointCloudPoisson(
      cloud, options.poisson_depth, 0.0f, static_cast<float>(options.poisson_scale), false,
      options.poisson_threads);
  const size_t n_before = mesh->vertices_.size();

  // Trim by density and by distance to the points.
  std::vector<bool> remove(mesh->vertices_.size(), false);
  if (options.density_quantile > 0) {
    const double cut = Quantile(densities, options.density_quantile);
    for (size_t i = 0; i < densities.size(); ++i) remove[i] = densities[i] < cut;
  }
  // Each vertex's distance to the nearest point: the distance trim, and the
  // silhouette trim's support.
  std::vector<double> nearest(mesh->vertices_.size(), std::numeric_limits<double>::infinity());
  {
    open3d::geometry::KDTreeFlann tree(cloud);
    std::vector<int> idx(1);
    std::vector<double> d2(1);
    for (size_t i = 0; i < mesh->vertices_.size(); ++i)
      if (tree.SearchKNN(mesh->vertices_[i], 1, idx, d2) >= 1) nearest[i] = std::sqrt(d2[0]);
  }
  if (options.trim_distance_factor > 0)
    for (size_t i = 0; i < nearest.size(); ++i)
      remove[i] = remove[i] || nearest[i] > options.trim_distance_factor * out.point_spacing;
  std::vector<bool> supported(nearest.size());
  for (size_t i = 0; i < nearest.size(); ++i)
    supported[i] = nearest[i] <= options.silhouette.support_factor * out.point_spacing;
  const std::vector<bool> outside = OutsideSilhouettes(mesh->vertices_, supported, cameras, depths,
                                                       instance_ids, object_id, options.silhouette);
  for (size_t i = 0; i < remove.size(); ++i) remove[i] = remove[i] || outside[i];
  mesh->RemoveVerticesByMask(remove);

  // Drop small connected components.
  if (options.min_component_fraction > 0 && !mesh->triangles_.empty()) {
    auto [cluster_of, cluster_size, cluster_area] = mesh->ClusterConnectedTriangles();
    const double min_size = options.min_component_fraction * mesh->triangles_.size();
    std::vector<bool> drop(mesh->triangles_.size());
    for (size_t t = 0; t < drop.size(); ++t) drop[t] = cluster_size[cluster_of[t]] < min_size;
    mesh->RemoveTrianglesByMask(drop);
    mesh->RemoveUnreferencedVertices();
  }
  out.vertices_trimmed = static_cast<int>(n_before - mesh->vertices_.size());
  out.holes_filled = FillHoles(options.fill_hole_radius, mesh.get());
  mesh->ComputeVertexNormals();
  out.mesh = mesh;
  return out;
}

}  // namespace u4d
