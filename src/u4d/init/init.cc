// InitOptions and the whole unsupervised chain (init.h).
#include <algorithm>
#include <cmath>
#include <set>

#include <tbb/parallel_for.h>

#include "u4d/init/init.h"
#include "u4d/init/init_internal.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

std::vector<cv::Mat> SplitAll(const std::vector<cv::Mat>& images, const std::vector<cv::Mat>& fg,
                              const std::vector<std::vector<PersonBox>>& boxes,
                              const InitOptions& options) {
  const int nv = static_cast<int>(images.size());
  std::vector<cv::Mat> ids(nv);
  tbb::parallel_for(0, nv,
                    [&](int v) { ids[v] = SplitInstances(images[v], fg[v], boxes[v], options); });
  return ids;
}

// Step 6 where enough calibrated views exist, else step 4 per view.
std::vector<cv::Mat> Instances(const std::vector<Camera>& cameras,
                               const std::vector<cv::Mat>& images, const std::vector<cv::Mat>& fg,
                               const std::vector<std::vector<PersonBox>>& boxes,
                               const InitOptions& options) {
  if (UsesGroundOccupancy(options, static_cast<int>(cameras.size())))
    return SeparatePeopleOnGround(cameras, SplitAll(images, fg, boxes, options), options);
  return SplitAll(images, fg, boxes, options);
}

// Step 4b: when some view fills boxes, the boxes of the people that two
// views' boxes (down to views_hog_threshold) place on the floor, plus each
// view's own boxes whose centre none of those holds.
std::vector<std::vector<PersonBox>> BoxesFromViews(const std::vector<Camera>& cameras,
                                                   const std::vector<cv::Mat>& images,
                                                   const std::vector<cv::Mat>& fg,
                                                   const std::vector<std::vector<PersonBox>>& boxes,
                                                   const InitOptions& options) {
  const int nv = static_cast<int>(images.size());
  bool fills = false;
  for (int v = 0; v < nv; ++v) fills = fills || FillsBoxes(fg[v], options);
  if (!options.people.boxes_from_views || cameras.size() < 2 || !fills) return boxes;
  InitOptions low = options;
  low.people.hog_threshold =
      std::min(options.people.hog_threshold, options.people.views_hog_threshold);
  std::vector<std::vector<PersonBox>> candidates(nv);
  tbb::parallel_for(0, nv, [&](int v) { candidates[v] = DetectPeople(images[v], low); });
  std::vector<std::vector<PersonBox>> out =
      BoxesOfPeople(cameras, PeopleFromBoxes(cameras, candidates, options), options);
  for (int v = 0; v < nv; ++v) {
    const size_t confirmed = out[v].size();
    for (const PersonBox& b : boxes[v]) {
      const cv::Point centre(b.box.x + b.box.width / 2, b.box.y + b.box.height / 2);
      bool held = false;
      for (size_t k = 0; k < confirmed; ++k) held = held || out[v][k].box.contains(centre);
      if (!held) out[v].push_back(b);
    }
  }
  return out;
}

}  // namespace

bool UsesGroundOccupancy(const InitOptions& options, int num_cameras) {
  return options.ground.enabled && num_cameras >= std::max(2, options.ground.occupancy_min_views);
}

void ForegroundOptions::Check() const {
  U4D_CHECK(threshold_sigmas > 0, "ForegroundOptions.threshold_sigmas must be > 0, found {}",
            threshold_sigmas);
  U4D_CHECK(min_noise_sigma >= 0, "ForegroundOptions.min_noise_sigma must be >= 0, found {}",
            min_noise_sigma);
  U4D_CHECK(
      shadow_min_ratio > 0 && shadow_min_ratio <= shadow_max_ratio && shadow_max_ratio < 1,
      "ForegroundOptions.shadow_min_ratio/shadow_max_ratio must satisfy 0 < min <= max < 1, found "
      "{} and {}",
      shadow_min_ratio, shadow_max_ratio);
  U4D_CHECK(shadow_chroma_sigmas >= 0,
            "ForegroundOptions.shadow_chroma_sigmas must be >= 0, found {}", shadow_chroma_sigmas);
  U4D_CHECK(morph_radius_px >= 0, "ForegroundOptions.morph_radius_px must be >= 0, found {}",
            morph_radius_px);
  U4D_CHECK(min_blob_fraction >= 0 && min_blob_fraction < 1,
            "ForegroundOptions.min_blob_fraction must be in [0, 1), found {}", min_blob_fraction);
}

void CrossViewOptions::Check() const {
  U4D_CHECK(consistency_max_side >= 16,
            "CrossViewOptions.consistency_max_side must be >= 16, found {}", consistency_max_side);
  U4D_CHECK(step_px > 0.05 && step_px <= 10,
            "CrossViewOptions.step_px must be in (0.05, 10], found {}", step_px);
  U4D_CHECK(min_depth_m > 0, "CrossViewOptions.min_depth_m must be > 0, found {}", min_depth_m);
  U4D_CHECK(max_depth_m == 0 || max_depth_m > min_depth_m,
            "CrossViewOptions.max_depth_m must be 0 (auto) or > min_depth_m ({}), found {}",
            min_depth_m, max_depth_m);
  U4D_CHECK(min_view_fraction > 0 && min_view_fraction <= 1,
            "CrossViewOptions.min_view_fraction must be in (0, 1], found {}", min_view_fraction);
  U4D_CHECK(min_views_seeing >= 1, "CrossViewOptions.min_views_seeing must be >= 1, found {}",
            min_views_seeing);
  U4D_CHECK(consistency_dilation_px >= 0,
            "CrossViewOptions.consistency_dilation_px must be >= 0, found {}",
            consistency_dilation_px);
  U4D_CHECK(min_consistent_fraction >= 0 && min_consistent_fraction <= 1,
            "CrossViewOptions.min_consistent_fraction must be in [0, 1], found {}",
            min_consistent_fraction);
}

void PeopleOptions::Check() const {
  U4D_CHECK(min_person_height_px >= 16,
            "PeopleOptions.min_person_height_px must be >= 16, found {}", min_person_height_px);
  U4D_CHECK(hog_max_side >= 128, "PeopleOptions.hog_max_side must be >= 128, found {}",
            hog_max_side);
  U4D_CHECK(profile_valley_ratio > 0 && profile_valley_ratio < 1,
            "PeopleOptions.profile_valley_ratio must be in (0, 1), found {}", profile_valley_ratio);
  U4D_CHECK(min_instance_fraction >= 0 && min_instance_fraction < 1,
            "PeopleOptions.min_instance_fraction must be in [0, 1), found {}",
            min_instance_fraction);
  U4D_CHECK(grabcut_iterations >= 0, "PeopleOptions.grabcut_iterations must be >= 0, found {}",
            grabcut_iterations);
  U4D_CHECK(group_radius_px >= 0, "PeopleOptions.group_radius_px must be >= 0, found {}",
            group_radius_px);
  U4D_CHECK(box_min_coverage >= 0 && box_min_coverage <= 1,
            "PeopleOptions.box_min_coverage must be in [0, 1], found {}", box_min_coverage);
  U4D_CHECK(grabcut_box_iterations >= 1,
            "PeopleOptions.grabcut_box_iterations must be >= 1, found {}", grabcut_box_iterations);
  U4D_CHECK(grabcut_max_side >= 16, "PeopleOptions.grabcut_max_side must be >= 16, found {}",
            grabcut_max_side);
  U4D_CHECK(foot_max_gap_m > 0, "PeopleOptions.foot_max_gap_m must be > 0, found {}",
            foot_max_gap_m);
  U4D_CHECK(floor_tolerance_m > 0, "PeopleOptions.floor_tolerance_m must be > 0, found {}",
            floor_tolerance_m);
  U4D_CHECK(person_radius_m > 0, "PeopleOptions.person_radius_m must be > 0, found {}",
            person_radius_m);
  U4D_CHECK(person_height_m > 0, "PeopleOptions.person_height_m must be > 0, found {}",
            person_height_m);
}

void StillOptions::Check() const {
  U4D_CHECK(still_grabcut_iterations >= 0,
            "StillOptions.still_grabcut_iterations must be >= 0, found {}",
            still_grabcut_iterations);
  U4D_CHECK(envelope_dilation >= 0 && envelope_dilation < 1,
            "StillOptions.envelope_dilation must be in [0, 1), found {}", envelope_dilation);
  U4D_CHECK(envelope_ring > 0 && envelope_ring < 1,
            "StillOptions.envelope_ring must be in (0, 1), found {}", envelope_ring);
  U4D_CHECK(ghost_edge_ratio > 0, "StillOptions.ghost_edge_ratio must be > 0, found {}",
            ghost_edge_ratio);
  U4D_CHECK(still_max_side >= 32, "StillOptions.still_max_side must be >= 32, found {}",
            still_max_side);
}

void GroundOptions::Check() const {
  U4D_CHECK(occupancy_min_views >= 2, "GroundOptions.occupancy_min_views must be >= 2, found {}",
            occupancy_min_views);
  U4D_CHECK(occupancy_max_side >= 16, "GroundOptions.occupancy_max_side must be >= 16, found {}",
            occupancy_max_side);
  U4D_CHECK(occupancy_cells >= 8 && occupancy_cells <= 1024,
            "GroundOptions.occupancy_cells must be in [8, 1024], found {}", occupancy_cells);
  U4D_CHECK(occupancy_extent > 0, "GroundOptions.occupancy_extent must be > 0, found {}",
            occupancy_extent);
  U4D_CHECK(min_column_height_m >= 0, "GroundOptions.min_column_height_m must be >= 0, found {}",
            min_column_height_m);
  U4D_CHECK(min_lone_height_m >= min_column_height_m && min_lone_height_m <= min_person_height_m,
            "GroundOptions.min_lone_height_m must be in [min_column_height_m, min_person_height_m] "
            "= [{}, {}], found {}",
            min_column_height_m, min_person_height_m, min_lone_height_m);
  U4D_CHECK(previous_radius_m >= 0 && std::isfinite(previous_radius_m),
            "GroundOptions.previous_radius_m must be finite and >= 0, found {}", previous_radius_m);
  U4D_CHECK(min_person_height_m >= min_column_height_m,
            "GroundOptions.min_person_height_m must be >= min_column_height_m ({}), found {}",
            min_column_height_m, min_person_height_m);
  U4D_CHECK(person_smoothing_m >= 0, "GroundOptions.person_smoothing_m must be >= 0, found {}",
            person_smoothing_m);
  U4D_CHECK(person_saddle_ratio > 0 && person_saddle_ratio <= 1,
            "GroundOptions.person_saddle_ratio must be in (0, 1], found {}", person_saddle_ratio);
  U4D_CHECK(min_exclusive_share >= 0 && min_exclusive_share <= 1,
            "GroundOptions.min_exclusive_share must be in [0, 1], found {}", min_exclusive_share);
  U4D_CHECK(min_split_share > 0 && min_split_share <= 1,
            "GroundOptions.min_split_share must be in (0, 1], found {}", min_split_share);
  U4D_CHECK(instance_split_view_share >= 0 && instance_split_view_share <= 1,
            "GroundOptions.instance_split_view_share must be in [0, 1], found {}",
            instance_split_view_share);
  U4D_CHECK(min_split_exclusive_share >= 0 && min_split_exclusive_share <= 1,
            "GroundOptions.min_split_exclusive_share must be in [0, 1], found {}",
            min_split_exclusive_share);
  U4D_CHECK(occupancy_fill_fraction >= 0 && occupancy_fill_fraction < 1,
            "GroundOptions.occupancy_fill_fraction must be in [0, 1), found {}",
            occupancy_fill_fraction);
}

void InitOptions::Check() const {
  foreground.Check();
  cross_view.Check();
  people.Check();
  still.Check();
  ground.Check();
}

std::vector<cv::Mat> UnsupervisedInstanceMasks(const std::vector<Camera>& cameras,
                                               const std::vector<cv::Mat>& images_t,
                                               const std::vector<BackgroundModel>& backgrounds,
                                               const InitOptions& options,
                                               const std::vector<ChromaKey>& keys) {
  options.Check();
  const int nv = static_cast<int>(images_t.size());
  U4D_CHECK(nv >= 1, "UnsupervisedInstanceMasks: no images given");
  U4D_CHECK(backgrounds.size() == images_t.size(),
            "UnsupervisedInstanceMasks: {} backgrounds for {} images", backgrounds.size(),
            images_t.size());
  U4D_CHECK(cameras.empty() || cameras.size() == images_t.size(),
            "UnsupervisedInstanceMasks: {} cameras for {} images (give one per view or none)",
            cameras.size(), images_t.size());
  U4D_CHECK(keys.empty() || keys.size() == images_t.size(),
            "UnsupervisedInstanceMasks: {} chroma keys for {} images (give one per view or none)",
            keys.size(), images_t.size());
  const auto keyed = [&](int v) { return !keys.empty() && keys[v].keyed; };
  for (int v = 0; v < nv; ++v) {
    U4D_CHECK(!images_t[v].empty(), "UnsupervisedInstanceMasks: image of view {} is empty", v);
    if (!cameras.empty()) {
      U4D_CHECK(images_t[v].cols == cameras[v].width && images_t[v].rows == cameras[v].height,
                "UnsupervisedInstanceMasks: image of view {} is {}x{}, its camera {}x{}", v,
                images_t[v].cols, images_t[v].rows, cameras[v].width, cameras[v].height);
    }
  }
  std::vector<cv::Mat> fg(nv), filled(nv);
  std::vector<std::vector<PersonBox>> boxes(nv);
  // Views in parallel; HOG and OpenCV's filters are themselves parallel.
  tbb::parallel_for(0, nv, [&](int v) {
    fg[v] = keyed(v) ? CleanMask(ChromaKeyMask(images_t[v], keys[v]), options)
                     : ForegroundMask(images_t[v], backgrounds[v], options);
    if (options.people.use_hog) boxes[v] = DetectPeople(images_t[v], options);
  });
  if (options.people.use_hog) boxes = BoxesFromViews(cameras, images_t, fg, boxes, options);
  tbb::parallel_for(0, nv, [&](int v) {
    if (options.people.use_hog) fg[v] = AddDetectedPeople(images_t[v], fg[v], boxes[v], options);
    if (options.still.remove_ghosts && !keyed(v))
      fg[v] = RemoveGhosts(images_t[v], fg[v], backgrounds[v], options);
    if (options.still.still_grabcut_iterations > 0)
      filled[v] = keyed(v) ? fg[v] : FillStillSubjects(images_t[v], fg[v], backgrounds[v], options);
  });
  if (options.still.still_grabcut_iterations > 0) {
    if (options.cross_view.enabled && cameras.size() >= 2 && options.still.carve_still_fill) {
      // Components are kept or dropped as a whole (step 3); of the pixels
      // step 5 added, only those the other views confirm stay.
      InitOptions carve = options;
      carve.cross_view.carve_pixels = true;
      const std::vector<cv::Mat> kept = CrossViewConsistentMasks(cameras, filled, options);
      const std::vector<cv::Mat> confirmed = CrossViewConsistentMasks(cameras, filled, carve);
      for (int v = 0; v < nv; ++v) fg[v] = kept[v] & (fg[v] | confirmed[v]);
      return Instances(cameras, images_t, fg, boxes, options);
    }
    fg = filled;
  }
  if (options.cross_view.enabled && cameras.size() >= 2)
    fg = CrossViewConsistentMasks(cameras, fg, options);
  return Instances(cameras, images_t, fg, boxes, options);
}

InstanceMask ToInstanceMask(const cv::Mat& ids) {
  U4D_CHECK(!ids.empty() && ids.type() == CV_16UC1,
            "ToInstanceMask: expected a non-empty CV_16UC1 id image");
  InstanceMask m;
  m.ids = ids;
  std::set<int> present;
  for (int y = 0; y < ids.rows; ++y) {
    const uint16_t* p = ids.ptr<uint16_t>(y);
    for (int x = 0; x < ids.cols; ++x)
      if (p[x]) present.insert(p[x]);
  }
  for (const int id : present) m.instances.push_back({id, "person", 1.0});
  return m;
}

}  // namespace u4d
