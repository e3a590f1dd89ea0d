#include "u4d/pipeline/initial_objects.h"

#include <algorithm>
#include <set>
#include <tuple>

#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

cv::Mat Relabel(const cv::Mat& ids, const std::map<int, int>& new_id) {
  cv::Mat out = cv::Mat::zeros(ids.size(), CV_16U);
  for (int y = 0; y < ids.rows; ++y)
    for (int x = 0; x < ids.cols; ++x) {
      const auto it = new_id.find(ids.at<uint16_t>(y, x));
      if (it != new_id.end()) out.at<uint16_t>(y, x) = static_cast<uint16_t>(it->second);
    }
  return out;
}

// Per-frame object k -> linked id, updating the linker.
std::map<int, int> LinkObjects(const std::map<int, Eigen::Vector3d>& centroids,
                               ObjectLinker* linker) {
  std::vector<std::tuple<double, int, int>> pairs;  // distance, object, previous id
  for (const auto& [k, c] : centroids)
    for (const auto& [id, p] : linker->previous) {
      const double d = (c - p).norm();
      if (d <= linker->max_centroid_jump_m) pairs.emplace_back(d, k, id);
    }
  std::sort(pairs.begin(), pairs.end());
  std::map<int, int> link;
  std::set<int> taken;
  for (const auto& [d, k, id] : pairs)
    if (!link.count(k) && !taken.count(id)) link[k] = id, taken.insert(id);
  for (const auto& [k, c] : centroids)
    if (!link.count(k)) link[k] = linker->next_id++;
  linker->previous.clear();
  for (const auto& [k, c] : centroids) linker->previous[link[k]] = c;
  return link;
}

}  // namespace

FrameObjects ObjectsFromPoses(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& masks,
                              const std::vector<Pose3d>& poses, const FrameSetupOptions& options) {
  U4D_CHECK(cameras.size() == masks.size(), "ObjectsFromPoses: {} cameras but {} masks",
            cameras.size(), masks.size());
  FrameObjects out;
  out.ids.resize(masks.size());
  out.depth_ranges.resize(masks.size());
  for (size_t v = 0; v < masks.size(); ++v)
    if (!masks[v].empty())
      out.ids[v] = AssignInstancesToPeople(cameras[v], masks[v], poses, options);
  return out;
}

FrameObjects ObjectsFromSparse(const std::vector<Camera>& cameras,
                               const std::vector<cv::Mat>& images,
                               const std::vector<cv::Mat>& masks,
                               const SparseFrameOptions& sparse_options,
                               const ObjectRegionOptions& region_options, ObjectLinker* linker) {
  U4D_CHECK(linker != nullptr, "ObjectsFromSparse: no linker");
  U4D_CHECK(cameras.size() == masks.size() && cameras.size() == images.size(),
            "ObjectsFromSparse: {} cameras, {} images and {} masks", cameras.size(), images.size(),
            masks.size());
  const SparseFrame sparse = ReconstructSparseFrame(cameras, images, masks, sparse_options);
  const auto regions =
      InitialObjectRegions(cameras, masks, sparse.association, sparse.points, {}, region_options);
  // Centroid of each object's points (the per-coordinate median: robust to a
  // few wrongly assigned points).
  std::map<int, Eigen::Vector3d> centroids;
  for (int k = 1; k <= sparse.association.num_objects; ++k) {
    std::vector<double> xs[3];
    for (const SparsePoint& p : sparse.points)
      if (p.instance == k)
        for (int c = 0; c < 3; ++c) xs[c].push_back(p.position[c]);
    if (xs[0].empty()) continue;
    Eigen::Vector3d m;
    for (int c = 0; c < 3; ++c) {
      std::nth_element(xs[c].begin(), xs[c].begin() + xs[c].size() / 2, xs[c].end());
      m[c] = xs[c][xs[c].size() / 2];
    }
    centroids[k] = m;
  }
  const std::map<int, int> link = LinkObjects(centroids, linker);

  FrameObjects out;
  out.num_sparse_points = static_cast<int>(sparse.points.size());
  const int nv = static_cast<int>(cameras.size());
  out.ids.resize(nv);
  out.depth_ranges.resize(nv);
  for (const auto& [k, c] : centroids) out.centroids[link.at(k)] = c;
  for (int v = 0; v < nv; ++v) {
    if (masks[v].empty()) continue;
    std::map<int, int> new_id;  // mask id -> linked object id
    for (const auto& [mask_id, k] : sparse.association.object_of[v])
      if (link.count(k)) new_id[mask_id] = link.at(k);
    cv::Mat ids16;
    masks[v].convertTo(ids16, CV_16U);
    out.ids[v] = Relabel(ids16, new_id);
    for (const auto& object_regions : regions) {
      const ObjectRegion& r = object_regions[v];
      if (!link.count(r.instance) || !r.detected || r.depth_far <= r.depth_near) continue;
      out.depth_ranges[v][link.at(r.instance)] = {r.depth_near, r.depth_far};
    }
  }
  return out;
}

void WriteFrameObjects(const fs::path& out, const std::vector<std::string>& view_names, int frame,
                       const FrameObjects& objects) {
  U4D_CHECK(objects.ids.size() == view_names.size(), "WriteFrameObjects: {} views but {} masks",
            view_names.size(), objects.ids.size());
  nlohmann::json ranges = nlohmann::json::object();
  for (size_t v = 0; v < view_names.size(); ++v) {
    if (!objects.ids[v].empty())
      WriteImage(out / layout::SceneInitialMask(view_names[v], frame), objects.ids[v]);
    nlohmann::json view = nlohmann::json::object();
    if (v < objects.depth_ranges.size())
      for (const auto& [id, r] : objects.depth_ranges[v])
        view[std::to_string(id)] = {r.first, r.second};
    ranges[view_names[v]] = view;
  }
  nlohmann::json list = nlohmann::json::array();
  for (const auto& [id, c] : objects.centroids)
    list.push_back({{"id", id}, {"centroid", {c.x(), c.y(), c.z()}}});
  WriteJsonFileAtomic(out / layout::SceneInitialObjects(frame),
                      {{"frame", frame},
                       {"objects", list},
                       {"num_sparse_points", objects.num_sparse_points},
                       {"depth_ranges", ranges}});
}

FrameObjects ReadFrameObjects(const fs::path& out, const std::vector<std::string>& view_names,
                              int frame) {
  const fs::path path = out / layout::SceneInitialObjects(frame);
  const nlohmann::json j = ReadJsonFile(path);
  const std::string ctx = path.string();
  FrameObjects objects;
  objects.num_sparse_points = static_cast<int>(
      JsonInteger(JsonGet<nlohmann::json>(j, "num_sparse_points", ctx), ctx, "num_sparse_points"));
  for (const nlohmann::json& o : JsonGet<nlohmann::json>(j, "objects", ctx)) {
    const auto c = JsonGet<std::vector<double>>(o, "centroid", ctx);
    U4D_CHECK(c.size() == 3, "{}: a centroid must have 3 numbers", ctx);
    objects.centroids[static_cast<int>(JsonInteger(JsonGet<nlohmann::json>(o, "id", ctx), ctx,
                                                   "id"))] = Eigen::Vector3d(c[0], c[1], c[2]);
  }
  const nlohmann::json ranges = JsonGet<nlohmann::json>(j, "depth_ranges", ctx);
  for (const std::string& name : view_names) {
    const fs::path png = out / layout::SceneInitialMask(name, frame);
    objects.ids.push_back(fs::exists(png) ? ReadLabelImage(png) : cv::Mat());
    std::map<int, std::pair<double, double>> view;
    for (const auto& [id, r] : JsonGet<nlohmann::json>(ranges, name, ctx).items()) {
      U4D_CHECK(r.is_array() && r.size() == 2,
                "{}: depth range of object {} in {} must be [near, far]", ctx, id, name);
      view[std::stoi(id)] = {JsonNumber(r[0], ctx, "near"), JsonNumber(r[1], ctx, "far")};
    }
    objects.depth_ranges.push_back(view);
  }
  return objects;
}

}  // namespace u4d
