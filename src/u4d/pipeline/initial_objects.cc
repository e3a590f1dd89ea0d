#include "u4d/pipeline/initial_objects.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <tuple>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include "u4d/features/silhouette_points.h"
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

// (distance, per-frame object, track id) of the pairs that may be one
// object: alike labels, and within the centroid jump (continuous frames);
// after a cut, every pair whose colours are known (UnambiguousPairs then
// keeps those within the appearance distance that no rival comes near).
using LinkPairs = std::vector<std::tuple<double, int, int>>;
LinkPairs CandidatePairs(const std::map<int, Eigen::Vector3d>& centroids,
                         const std::map<int, ObjectAppearance>& appearances,
                         const std::function<std::string(int)>& label_of,
                         const ObjectLinker& linker) {
  LinkPairs pairs;
  for (const auto& [k, c] : centroids)
    for (const auto& [id, track] : linker.tracks) {
      if (track.label != label_of(k)) continue;
      if (linker.after_cut) {
        const auto a = appearances.find(k);
        if (a == appearances.end() || track.appearance.pixels <= 0) continue;
        pairs.emplace_back(AppearanceDistance(a->second, track.appearance), k, id);
      } else {
        const double d = (c - track.position).norm();
        if (d <= linker.options.max_centroid_jump_m * (1 + track.missing))
          pairs.emplace_back(d, k, id);
      }
    }
  return pairs;
}

// The pairs of an appearance link (after a cut) within `max_distance` that
// no rival comes near: every other pair of the same object or of the same
// track is at least `margin` farther (ObjectLinkOptions; 0 = all of them).
LinkPairs UnambiguousPairs(const LinkPairs& pairs, double max_distance, double margin) {
  LinkPairs kept;
  for (const auto& [d, k, id] : pairs) {
    if (d > max_distance) continue;
    const bool rivalled = margin > 0 && std::any_of(pairs.begin(), pairs.end(), [&](const auto& o) {
                            const auto& [e, other_k, other_id] = o;
                            return (other_k == k) != (other_id == id) && e < d + margin;
                          });
    if (!rivalled) kept.emplace_back(d, k, id);
  }
  return kept;
}

// Mask id k is object k in every view where it occurs.
InstanceAssociation IdentityAssociation(const std::vector<cv::Mat>& masks) {
  InstanceAssociation a;
  a.object_of.resize(masks.size());
  for (size_t v = 0; v < masks.size(); ++v) {
    if (masks[v].empty()) continue;
    cv::Mat ids;
    masks[v].convertTo(ids, CV_32S);
    std::set<int> present;  // one set lookup per run of equal ids, not per pixel
    int last = 0;
    for (auto it = ids.begin<int>(); it != ids.end<int>(); ++it)
      if (*it > 0 && *it != last) present.insert(last = *it);
    for (const int id : present) {
      a.object_of[v][id] = id;
      a.num_objects = std::max(a.num_objects, id);
    }
  }
  return a;
}

// The class of each associated object: that of its instances (alike when
// AssociateInstances was given the classes).
std::map<int, std::string> ObjectLabels(const InstanceAssociation& association,
                                        const InstanceClasses* classes) {
  std::map<int, std::string> out;
  if (classes == nullptr) return out;
  for (size_t v = 0; v < association.object_of.size(); ++v)
    for (const auto& [id, object] : association.object_of[v])
      out.emplace(object, ClassOf(*classes, static_cast<int>(v), id));
  return out;
}

// Instances of a view not associated with an object join the object most
// of their silhouette points are associated with in the other views (with
// classes: among the objects of the instance's class).
void AttachFragments(const std::vector<cv::Mat>& masks, const std::vector<SparsePoint>& points,
                     const InstanceClasses* classes, InstanceAssociation* association) {
  const std::map<int, std::string> object_labels = ObjectLabels(*association, classes);
  auto alike = [&](int view, int id, int object) {
    return classes == nullptr || ClassOf(*classes, view, id) == object_labels.at(object);
  };
  std::map<std::pair<int, int>, std::map<int, int>> votes;  // (view, id) -> object -> count
  for (const SparsePoint& p : points) {
    std::vector<std::pair<int, int>> labels;
    std::set<int> objects;
    for (size_t i = 0; i < p.observations.size(); ++i) {
      const int v = p.observations[i].first;
      const int id = MaskIdAt(masks[v], p.pixels[i]);
      if (id == 0) continue;
      if (const int o = association->ObjectOf(v, id))
        objects.insert(o);
      else
        labels.emplace_back(v, id);
    }
    for (const auto& label : labels)
      for (int o : objects)
        if (alike(label.first, label.second, o)) ++votes[label][o];
  }
  for (const auto& [label, by_object] : votes) {
    const auto best =
        std::max_element(by_object.begin(), by_object.end(),
                         [](const auto& a, const auto& b) { return a.second < b.second; });
    association->object_of[label.first][label.second] = best->first;
  }
}

}  // namespace

std::map<int, int> LinkObjects(const std::map<int, Eigen::Vector3d>& centroids,
                               const std::map<int, ObjectAppearance>& appearances,
                               const std::map<int, std::string>& labels, ObjectLinker* linker) {
  auto label_of = [&](int k) {
    const auto it = labels.find(k);
    return it == labels.end() ? std::string() : it->second;
  };
  LinkPairs pairs = CandidatePairs(centroids, appearances, label_of, *linker);
  if (linker->after_cut)
    pairs = UnambiguousPairs(pairs, linker->options.max_appearance_distance,
                             linker->options.min_appearance_margin);
  std::sort(pairs.begin(), pairs.end());
  std::map<int, int> link;
  std::set<int> taken;
  for (const auto& [d, k, id] : pairs)
    if (!link.count(k) && !taken.count(id)) link[k] = id, taken.insert(id);
  for (const auto& [k, c] : centroids)
    if (!link.count(k)) link[k] = linker->next_id++;
  for (auto it = linker->tracks.begin(); it != linker->tracks.end();)
    it =
        ++it->second.missing > linker->options.max_missing_frames ? linker->tracks.erase(it) : ++it;
  for (const auto& [k, c] : centroids) {
    ObjectLinker::Track& track = linker->tracks[link[k]];
    const auto a = appearances.find(k);
    const ObjectAppearance seen = a == appearances.end() ? ObjectAppearance{} : a->second;
    track = {c, MeanAppearance(track.appearance, seen), 0, label_of(k)};
  }
  linker->after_cut = false;
  return link;
}

void CutLinker(ObjectLinker* linker) {
  if (!linker->keep_appearance || linker->options.max_appearance_distance <= 0)
    linker->tracks.clear();
  linker->after_cut = !linker->tracks.empty();
}

void ObjectLinkOptions::Check() const {
  U4D_CHECK(max_centroid_jump_m > 0 && std::isfinite(max_centroid_jump_m),
            "ObjectLinkOptions.max_centroid_jump_m must be finite and > 0, got {}",
            max_centroid_jump_m);
  U4D_CHECK(max_missing_frames >= 0, "ObjectLinkOptions.max_missing_frames must be >= 0, got {}",
            max_missing_frames);
  U4D_CHECK(max_appearance_distance >= 0 && std::isfinite(max_appearance_distance),
            "ObjectLinkOptions.max_appearance_distance must be finite and >= 0, got {}",
            max_appearance_distance);
  U4D_CHECK(min_appearance_margin >= 0 && std::isfinite(min_appearance_margin),
            "ObjectLinkOptions.min_appearance_margin must be finite and >= 0, got {}",
            min_appearance_margin);
}

cv::Mat KeepGivenPixels(const cv::Mat& given, const cv::Mat& named) {
  U4D_CHECK(given.type() == CV_16UC1 && named.type() == CV_16UC1 && given.size() == named.size(),
            "KeepGivenPixels: the given and named masks must be CV_16U of one size");
  std::map<int, std::map<int, int>> votes;  // given instance -> named id -> pixels
  for (int y = 0; y < given.rows; ++y)
    for (int x = 0; x < given.cols; ++x)
      if (const int i = given.at<uint16_t>(y, x))
        if (const int id = named.at<uint16_t>(y, x)) ++votes[i][id];
  std::map<int, int> majority;
  for (const auto& [i, by_id] : votes)
    majority[i] = std::max_element(by_id.begin(), by_id.end(), [](const auto& a, const auto& b) {
                    return a.second < b.second;
                  })->first;
  cv::Mat out = named.clone();
  for (int y = 0; y < given.rows; ++y)
    for (int x = 0; x < given.cols; ++x) {
      uint16_t& id = out.at<uint16_t>(y, x);
      const auto it = majority.find(given.at<uint16_t>(y, x));
      if (id == 0 && it != majority.end()) id = static_cast<uint16_t>(it->second);
    }
  return out;
}

std::vector<cv::Mat> GroundPeopleFromDetections(const std::vector<Camera>& cameras,
                                                const std::vector<cv::Mat>& masks,
                                                const InitOptions& options,
                                                std::vector<Eigen::Vector3d>* people) {
  U4D_CHECK(cameras.size() == masks.size(), "GroundPeopleFromDetections: {} cameras but {} masks",
            cameras.size(), masks.size());
  std::vector<cv::Mat> ids(masks.size());
  bool any = false;
  for (size_t v = 0; v < masks.size(); ++v) {
    if (masks[v].empty()) {
      ids[v] = cv::Mat::zeros(cameras[v].height, cameras[v].width, CV_16UC1);
    } else {
      masks[v].convertTo(ids[v], CV_16U);
      any = any || cv::countNonZero(ids[v]) > 0;
    }
  }
  if (!any) return masks;  // nobody seen: the previous people are kept for the next frame
  OccupancyMap map;
  std::vector<cv::Mat> named = SeparatePeopleOnGround(cameras, ids, options, &map, *people,
                                                      /*instances_are_people=*/true);
  people->assign(map.positions.begin() + std::min<size_t>(1, map.positions.size()),
                 map.positions.end());
  for (size_t v = 0; v < masks.size(); ++v)
    named[v] = masks[v].empty() ? cv::Mat() : KeepGivenPixels(ids[v], named[v]);
  return named;
}

std::vector<std::optional<PeoplePositions>> PeopleFromTheNextFrame(
    int num_frames, const std::function<PeoplePositions(int, PeoplePositions)>& ground_step) {
  std::vector<PeoplePositions> found(num_frames);
  for (int k = 0; k < num_frames; ++k)
    found[k] = ground_step(k, k > 0 ? found[k - 1] : PeoplePositions());
  std::vector<std::optional<PeoplePositions>> hints(num_frames);
  for (int k = num_frames - 2; k >= 0; --k) {
    if (found[k].size() >= found[k + 1].size()) continue;
    PeoplePositions again = ground_step(k, found[k + 1]);
    if (again.size() <= found[k].size()) continue;
    hints[k] = found[k + 1];
    found[k] = std::move(again);
  }
  return hints;
}

FrameObjects ObjectsFromPoses(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& masks,
                              const std::vector<Pose3d>& poses, const FrameSetupOptions& options) {
  U4D_CHECK(cameras.size() == masks.size(), "ObjectsFromPoses: {} cameras but {} masks",
            cameras.size(), masks.size());
  FrameObjects out;
  out.ids.resize(masks.size());
  out.depth_ranges.resize(masks.size());
  tbb::parallel_for(size_t{0}, masks.size(), [&](size_t v) {
    if (!masks[v].empty())
      out.ids[v] = AssignInstancesToPeople(cameras[v], masks[v], poses, options);
  });
  return out;
}

FrameObjects ObjectsFromSparse(const std::vector<Camera>& cameras,
                               const std::vector<cv::Mat>& images,
                               const std::vector<cv::Mat>& masks,
                               const SparseFrameOptions& sparse_options,
                               const ObjectRegionOptions& region_options, ObjectLinker* linker,
                               bool ids_alike_across_views, const DetectorContext& detector) {
  const InstanceClasses* classes = detector.classes;
  U4D_CHECK(linker != nullptr, "ObjectsFromSparse: no linker");
  U4D_CHECK(cameras.size() == masks.size() && cameras.size() == images.size(),
            "ObjectsFromSparse: {} cameras, {} images and {} masks", cameras.size(), images.size(),
            masks.size());
  SparseFrame sparse = ReconstructSparseFrame(cameras, images, masks, sparse_options);
  std::vector<SparsePoint> evidence = sparse.points;
  for (SparsePoint& p :
       SilhouettePoints(cameras, masks, region_options.silhouette, detector.unknown))
    evidence.push_back(std::move(p));
  if (ids_alike_across_views) {
    sparse.association = IdentityAssociation(masks);
  } else {
    sparse.association =
        AssociateInstances(cameras, masks, evidence, sparse_options.sparse, classes);
    AttachFragments(masks, evidence, classes, &sparse.association);
  }
  AssignInstances(masks, sparse.association, sparse.points, detector.unknown);
  AssignInstances(masks, sparse.association, evidence, detector.unknown);
  // Depth ranges from the feature points (accurate) where a view has enough
  // of them, else from the visual hull.
  const auto regions =
      InitialObjectRegions(cameras, masks, sparse.association, sparse.points, {}, region_options);
  // Centroid of each object's feature and silhouette points (the
  // per-coordinate median: robust to a few wrongly assigned points).
  std::map<int, Eigen::Vector3d> centroids;
  for (int k = 1; k <= sparse.association.num_objects; ++k) {
    std::vector<double> xs[3];
    for (const SparsePoint& p : evidence)
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
  std::map<int, ObjectAppearance> appearances;
  if (linker->keep_appearance) {
    std::vector<cv::Mat> object_masks(masks.size());  // per view, per-frame object k
    for (size_t v = 0; v < masks.size(); ++v) {
      if (masks[v].empty()) continue;
      cv::Mat ids16;
      masks[v].convertTo(ids16, CV_16U);
      object_masks[v] = Relabel(ids16, sparse.association.object_of[v]);
    }
    appearances = ObjectAppearances(images, object_masks);
  }
  const std::map<int, int> link =
      LinkObjects(centroids, appearances, ObjectLabels(sparse.association, classes), linker);

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
      // An object not detected in this view may be merged with another
      // there, or missed: it gets its depth range all the same, and the
      // solve looks for it where the other views put it
      // (joint/hull_support.h).
      if (!link.count(r.instance)) continue;
      double near = r.depth_near, far = r.depth_far;
      bool usable = r.depth_source == DepthSource::kSparsePoints;
      if (!usable) {
        // The silhouette points bound the object far better than rays that
        // leave the other views' images (object_regions.h's visual hull).
        std::vector<double> z;
        for (const SparsePoint& p : evidence)
          if (p.instance == r.instance)
            for (const auto& o : p.observations)
              if (o.first == v) z.push_back(cameras[v].Depth(p.position));
        if (static_cast<int>(z.size()) >= region_options.min_points) {
          std::sort(z.begin(), z.end());
          const auto at = [&](double q) { return z[static_cast<size_t>(q * (z.size() - 1))]; };
          near = std::max(0.05, at(region_options.percentile_near) - region_options.depth_margin_m);
          far = at(region_options.percentile_far) + region_options.depth_margin_m;
          usable = true;
        }
      }
      if (usable && far > near) out.depth_ranges[v][link.at(r.instance)] = {near, far};
    }
    // An object seen in this view without a usable depth range (no point
    // of it projects here) is not reconstructed in this view: its pixels
    // go back to the background of the initial labels.
    for (int y = 0; y < out.ids[v].rows; ++y)
      for (int x = 0; x < out.ids[v].cols; ++x) {
        uint16_t& id = out.ids[v].at<uint16_t>(y, x);
        if (id && !out.depth_ranges[v].count(id)) id = 0;
      }
  }
  return out;
}

FrameObjects WithOtherObjects(FrameObjects people, const std::vector<Camera>& cameras,
                              const std::vector<cv::Mat>& images,
                              const std::vector<cv::Mat>& people_masks,
                              const std::vector<cv::Mat>& other_masks,
                              const SparseFrameOptions& sparse_options,
                              const ObjectRegionOptions& region_options, ObjectLinker* linker,
                              const InstanceClasses* other_classes) {
  const bool any_other = std::any_of(other_masks.begin(), other_masks.end(), [](const cv::Mat& m) {
    return !m.empty() && cv::countNonZero(m) > 0;
  });
  if (!any_other) return people;
  const FrameObjects others =
      ObjectsFromSparse(cameras, images, other_masks, sparse_options, region_options, linker,
                        /*ids_alike_across_views=*/false, {other_classes, &people_masks});
  FrameObjects out = std::move(people);
  for (const auto& [id, c] : others.centroids) out.centroids[id] = c;
  out.num_sparse_points += others.num_sparse_points;
  out.depth_ranges.resize(std::max(out.depth_ranges.size(), others.depth_ranges.size()));
  for (size_t v = 0; v < others.depth_ranges.size(); ++v)
    for (const auto& [id, r] : others.depth_ranges[v]) out.depth_ranges[v][id] = r;
  for (size_t v = 0; v < out.ids.size(); ++v) {
    if (others.ids[v].empty() || cv::countNonZero(others.ids[v]) == 0) continue;
    if (out.ids[v].empty()) out.ids[v] = cv::Mat::zeros(others.ids[v].size(), CV_16U);
    others.ids[v].copyTo(out.ids[v], out.ids[v] == 0);
  }
  return out;
}

FrameObjects ObjectsFromPosesAndOthers(
    const std::vector<Camera>& cameras, const std::vector<cv::Mat>& images,
    const std::vector<cv::Mat>& people_masks, const std::vector<cv::Mat>& other_masks,
    const std::vector<Pose3d>& poses, const FrameSetupOptions& frame_options,
    const SparseFrameOptions& sparse_options, const ObjectRegionOptions& region_options,
    ObjectLinker* linker, const InstanceClasses* other_classes) {
  return WithOtherObjects(ObjectsFromPoses(cameras, people_masks, poses, frame_options), cameras,
                          images, people_masks, other_masks, sparse_options, region_options, linker,
                          other_classes);
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
                       {"depth_ranges", ranges},
                       {"classes", ClassVotesToJson(objects.class_votes)}});
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
  if (j.contains("classes")) objects.class_votes = ClassVotesFromJson(j["classes"], ctx);
  const nlohmann::json ranges = JsonGet<nlohmann::json>(j, "depth_ranges", ctx);
  for (const std::string& name : view_names) {
    const fs::path png = out / layout::SceneInitialMask(name, frame);
    objects.ids.push_back(fs::exists(png) ? ReadLabelImage(png) : cv::Mat());
    std::map<int, std::pair<double, double>> view;
    const nlohmann::json view_ranges = JsonGet<nlohmann::json>(ranges, name, ctx);
    for (auto it = view_ranges.begin(); it != view_ranges.end(); ++it) {
      const nlohmann::json& r = it.value();
      U4D_CHECK(r.is_array() && r.size() == 2,
                "{}: depth range of object {} in {} must be [near, far]", ctx, it.key(), name);
      view[std::stoi(it.key())] = {JsonNumber(r[0], ctx, "near"), JsonNumber(r[1], ctx, "far")};
    }
    objects.depth_ranges.push_back(view);
  }
  return objects;
}

}  // namespace u4d
