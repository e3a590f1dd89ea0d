#include "u4d/joint/frame_setup.h"

#include <algorithm>
#include <limits>
#include <map>
#include <set>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

cv::Mat Resize(const cv::Mat& image, const Camera& working, int interpolation) {
  if (image.empty() || (image.cols == working.width && image.rows == working.height)) return image;
  cv::Mat out;
  cv::resize(image, out, cv::Size(working.width, working.height), 0, 0, interpolation);
  return out;
}

// Each view's objects' regions grow by their leave-one-out visual hull from
// the other views' initial labels (hull_support.h); the map goes to E_sem.
// Every object claims the others' pixels (a box the detector merged with its
// holder in this view, a person merged with the one in front); the supported
// pixels are no colour sample of the other, nor of the background (below).
// An object whose region stays empty (not in this view's labels, and not
// found in its image) leaves the view.
void AddHullSupport(const std::vector<Camera>& cameras, const HullSupportOptions& options,
                    std::vector<JointViewInput>* inputs) {
  std::vector<cv::Mat> labels;
  for (const JointViewInput& in : *inputs) labels.push_back(in.initial_labels);
  for (size_t v = 0; v < inputs->size(); ++v) {
    JointViewInput& in = (*inputs)[v];
    std::vector<HullObject> objects;
    for (const JointObject& obj : in.objects) {
      std::vector<int> others;
      for (const JointObject& other : in.objects)
        if (other.id != obj.id) others.push_back(other.id);
      objects.push_back({obj.id, obj.depth_near, obj.depth_far, others});
    }
    if (objects.empty()) continue;
    in.hull_support = HullSupport(cameras, labels, static_cast<int>(v), objects, options);
    if (options.confirm) {
      // The object the other views put at a pixel the view gives to another
      // may take it (a merged instance split wrongly).
      cv::Mat seen;
      in.hull_confirmed = HullConfirmation(cameras, labels, static_cast<int>(v), objects, options,
                                           &seen, &in.hull_confirmed_alone);
      for (JointObject& obj : in.objects) obj.region |= seen == obj.id;
    }
    for (JointObject& obj : in.objects) obj.region |= in.hull_support == obj.id;
    std::erase_if(in.objects,
                  [](const JointObject& obj) { return cv::countNonZero(obj.region) == 0; });
    // The pixels the other views support are no colour sample of the label
    // the view's masks give them: not of another object it claims (a box the
    // detector merged with its holder), and not of the background (a part
    // the mask lacks). A part the mask lacks at t is likely lacking at t−1
    // and t+1 too (the same detector), so their background pixels there give
    // no sample either.
    const cv::Mat supported = in.hull_support != 0;
    for (LabelledImage& li : in.appearance_training) {
      if (li.other_view || li.labels.size() != supported.size()) continue;
      const bool at_t = &li == &in.appearance_training.front();
      li.labels = li.labels.clone();
      li.labels.setTo(kUnsampledLabel, at_t ? supported : supported & (li.labels == 0));
    }
    if (!options.colour_samples) continue;
    // E_a: those well inside the support are samples of their object.
    cv::Mat inner;
    cv::erode(in.hull_support, inner, cv::Mat::ones(3, 3, CV_8U));
    in.markers.resize(in.num_labels);
    for (int y = 0; y < inner.rows; ++y)
      for (int x = 0; x < inner.cols; ++x)
        if (const int o = inner.at<uint16_t>(y, x); o > 0 && o < in.num_labels)
          in.markers[o].emplace_back(x, y);
  }
}

// E_a's colour models of a view's objects also learn from the objects'
// pixels in the other views at t (images of the view's size), which see the
// same clothes: FrameSetupOptions::colour_from_other_views. In a view where
// the detector merged two people, or where a merged instance was split along
// the wrong line, the view's own samples of both are mixed, while most other
// views hold them apart. With one object in the view there is nothing to
// mix, and the other views' masks would lend only their own detector's
// errors (floor, furniture), so then the object keeps its own samples. An
// object the view's labels at t lack (missed, or
// merged into another object there) has no sample of its own at all, so it
// always borrows (E_a would forbid it), and where it is merged into another
// object the view's labels at t−1 and t+1 likely hold it in that object too
// (the same detector): their object pixels where its hull support lies at t
// give no colour sample.
void BorrowColourSamples(bool all_objects, std::vector<JointViewInput>* inputs) {
  for (JointViewInput& in : *inputs) {
    std::vector<int> borrowers;
    for (const JointObject& obj : in.objects) {
      const bool present = cv::countNonZero(in.initial_labels == obj.id) > 0;
      if (!present || (all_objects && in.objects.size() > 1)) borrowers.push_back(obj.id);
      if (present || in.hull_support.empty()) continue;
      const cv::Mat supported = in.hull_support == obj.id;
      for (LabelledImage& li : in.appearance_training) {
        if (li.other_view || li.labels.size() != supported.size() ||
            li.labels.data == in.appearance_training.front().labels.data)
          continue;
        li.labels = li.labels.clone();
        li.labels.setTo(kUnsampledLabel, supported & (li.labels != 0));
      }
    }
    if (borrowers.empty()) continue;
    for (const JointViewInput& other : *inputs) {
      if (&other == &in || other.initial_labels.size() != in.initial_labels.size()) continue;
      cv::Mat labels(other.initial_labels.size(), CV_16U, cv::Scalar(kUnsampledLabel));
      for (const int id : borrowers) labels.setTo(id, other.initial_labels == id);
      if (cv::countNonZero(labels != kUnsampledLabel) == 0) continue;
      in.appearance_training.push_back(
          {other.images_t[other.ref_view], labels, /*other_view=*/true});
    }
  }
}

// E_a's samples in a view whose labels (at t, t−1 or t+1) swapped two
// objects give no colour of either there (label_costs.h DropSwappedSamples).
// The objects' colours to compare with are those the other views give them
// at t: a swap in the view itself at t then shows too. With no other view
// holding two of the objects, the view's own labels at t are the reference
// for its neighbouring frames. Each view's histograms at t are computed
// once; a view's reference is the sum of the others' (whole counts: exact).
void DropSwappedColourSamples(int num_labels, std::vector<JointViewInput>* inputs) {
  std::vector<ColourHistograms> at_t;
  for (const JointViewInput& in : *inputs)
    at_t.push_back(ObjectColourHistograms({in.appearance_training.front()}, num_labels));
  for (size_t v = 0; v < inputs->size(); ++v) {
    ColourHistograms reference(num_labels);
    for (size_t u = 0; u < inputs->size(); ++u) {
      if (u == v) continue;
      for (int l = 1; l < num_labels; ++l) {
        const cv::Mat& h = at_t[u][l];
        if (h.empty()) continue;
        if (reference[l].empty())
          reference[l] = h.clone();
        else
          reference[l] += h;
      }
    }
    std::vector<LabelledImage>& training = (*inputs)[v].appearance_training;
    if (std::count_if(reference.begin() + 1, reference.end(),
                      [](const cv::Mat& h) { return !h.empty(); }) >= 2) {
      DropSwappedSamples(reference, &training);
      continue;
    }
    std::vector<LabelledImage> neighbours(training.begin() + 1, training.end());
    DropSwappedSamples(at_t[v], &neighbours);
    std::copy(neighbours.begin(), neighbours.end(), training.begin() + 1);
  }
}

}  // namespace

void FrameSetupOptions::Check() const {
  U4D_CHECK(working_width >= 16, "FrameSetupOptions.working_width must be >= 16, got {}",
            working_width);
  U4D_CHECK(depth_margin_m > 0, "FrameSetupOptions.depth_margin_m must be > 0");
  U4D_CHECK(min_joints_inside >= 1, "FrameSetupOptions.min_joints_inside must be >= 1");
  U4D_CHECK(flow_window_px > 0 && flow_window_px % 2 == 1,
            "FrameSetupOptions.flow_window_px must be odd and positive, got {}", flow_window_px);
  U4D_CHECK(flow_median_px >= 0, "FrameSetupOptions.flow_median_px must be >= 0, got {}",
            flow_median_px);
  U4D_CHECK(flow_fill_radius_px >= 0, "FrameSetupOptions.flow_fill_radius_px must be >= 0, got {}",
            flow_fill_radius_px);
  U4D_CHECK(flow_variational_iterations >= 0,
            "FrameSetupOptions.flow_variational_iterations must be >= 0, got {}",
            flow_variational_iterations);
  pose.Check();
  hull.Check();
}

cv::Mat AssignInstancesToPeople(const Camera& camera, const cv::Mat& mask_ids,
                                const std::vector<Pose3d>& poses,
                                const FrameSetupOptions& options) {
  U4D_CHECK(mask_ids.type() == CV_16UC1 && mask_ids.cols == camera.width &&
                mask_ids.rows == camera.height,
            "AssignInstancesToPeople: mask must be CV_16U {}x{}", camera.width, camera.height);
  // The people's capsules (pose_prior.h, z-buffered: a person in front claims
  // the pixels it covers), for the visibility of joints and for splitting.
  PosePriorMap capsules;
  if (options.split_merged && poses.size() >= 2) {
    std::vector<PersonPose> people;
    for (const Pose3d& pose : poses) {
      U4D_CHECK(pose.person_id >= 1, "AssignInstancesToPeople: person ids must be >= 1");
      PersonPose person;
      person.object_id = pose.person_id;
      person.at_t = pose;
      people.push_back(person);
    }
    capsules = RenderPosePrior(camera, camera, cv::Mat::zeros(mask_ids.size(), CV_8UC3), people,
                               options.pose);
  }
  // votes[instance][person] = joints of the person inside the instance;
  // visible[instance][person] = those not hidden by another person's capsules.
  std::map<int, std::map<int, int>> votes, visible;
  for (const Pose3d& pose : poses) {
    U4D_CHECK(pose.person_id >= 1, "AssignInstancesToPeople: person ids must be >= 1");
    for (const Eigen::Vector4d& j : pose.joints) {
      if (j.w() < options.min_joint_confidence) continue;
      const Eigen::Vector2d x = camera.Project(j.head<3>());
      if (!x.allFinite() || !camera.InImage(x)) continue;
      const int px = static_cast<int>(std::lround(x.x())),
                py = static_cast<int>(std::lround(x.y()));
      const int id = mask_ids.at<uint16_t>(py, px);
      if (id == 0) continue;
      ++votes[id][pose.person_id];
      if (!capsules.object.empty() && capsules.object.at<uint16_t>(py, px) == pose.person_id)
        ++visible[id][pose.person_id];
    }
  }
  std::map<int, int> object_of;
  std::map<int, std::vector<int>> merged_people;  // instance -> the people it merges
  for (const auto& [instance, people] : votes) {
    const auto best =
        std::max_element(people.begin(), people.end(),
                         [](const auto& a, const auto& b) { return a.second < b.second; });
    if (best->second >= options.min_joints_inside) object_of[instance] = best->first;
    std::vector<int> merged;
    for (const auto& [person, n] : visible[instance])
      if (n >= options.min_joints_inside) merged.push_back(person);
    if (merged.size() >= 2) merged_people[instance] = merged;
  }
  cv::Mat labels = cv::Mat::zeros(mask_ids.size(), CV_16U);
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) {
      const auto it = object_of.find(mask_ids.at<uint16_t>(y, x));
      if (it != object_of.end()) labels.at<uint16_t>(y, x) = static_cast<uint16_t>(it->second);
    }
  if (merged_people.empty()) return labels;
  // A merged instance: each pixel goes to the person whose (visible) capsules
  // cover it, or else to the person whose capsules are nearest in the image.
  std::map<int, cv::Mat> distance;  // person -> pixel distance to its capsules
  for (const auto& [instance, people] : merged_people)
    for (int person : people)
      if (!distance.count(person)) {
        const cv::Mat outside = capsules.object != person;  // 255 outside its capsules
        cv::distanceTransform(outside, distance[person], cv::DIST_L2, cv::DIST_MASK_PRECISE);
      }
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) {
      const auto it = merged_people.find(mask_ids.at<uint16_t>(y, x));
      if (it == merged_people.end()) continue;
      int best = it->second.front();
      float best_d = std::numeric_limits<float>::infinity();
      for (int person : it->second) {
        const float d = distance[person].at<float>(y, x);
        if (d < best_d) best_d = d, best = person;
      }
      labels.at<uint16_t>(y, x) = static_cast<uint16_t>(best);
    }
  return labels;
}

std::vector<JointViewInput> MakeJointViewInputs(const JointFrameData& data,
                                                const FrameSetupOptions& options, double* scale) {
  options.Check();
  const int nv = static_cast<int>(data.cameras_t.size());
  U4D_CHECK(nv >= 2, "MakeJointViewInputs: need >= 2 views, got {}", nv);
  U4D_CHECK(
      static_cast<int>(data.images_t.size()) == nv && static_cast<int>(data.masks_t.size()) == nv,
      "MakeJointViewInputs: {} cameras but {} images and {} masks at t", nv, data.images_t.size(),
      data.masks_t.size());
  const bool has_next = !data.images_t1.empty();
  U4D_CHECK(!has_next || (static_cast<int>(data.images_t1.size()) == nv &&
                          static_cast<int>(data.cameras_t1.size()) == nv),
            "MakeJointViewInputs: images and cameras at t+1 must cover all {} views", nv);
  const double s =
      std::min(1.0, static_cast<double>(options.working_width) / data.cameras_t[0].width);
  if (scale) *scale = s;

  std::vector<Camera> cams_t(nv), cams_t1;
  std::vector<cv::Mat> images_t(nv), images_t1, images_prev(nv);
  for (int v = 0; v < nv; ++v) {
    cams_t[v] = ScaledCamera(data.cameras_t[v], s);
    images_t[v] = Resize(data.images_t[v], cams_t[v], cv::INTER_AREA);
    if (v < static_cast<int>(data.images_prev.size()))
      images_prev[v] = Resize(data.images_prev[v], cams_t[v], cv::INTER_AREA);
  }
  if (has_next) {
    cams_t1.resize(nv);
    images_t1.resize(nv);
    for (int v = 0; v < nv; ++v) {
      cams_t1[v] = ScaledCamera(data.cameras_t1[v], s);
      images_t1[v] = Resize(data.images_t1[v], cams_t1[v], cv::INTER_AREA);
    }
  }
  const bool by_poses = !data.poses_t.empty();
  U4D_CHECK(by_poses || (data.masks_are_object_ids &&
                         static_cast<int>(data.object_depth_ranges.size()) == nv),
            "MakeJointViewInputs: without poses the masks must hold object ids and every one "
            "of the {} views needs its object depth ranges",
            nv);
  int num_labels = 1;
  for (const Pose3d& p : data.poses_t) num_labels = std::max(num_labels, p.person_id + 1);
  for (const auto& ranges : data.object_depth_ranges)
    for (const auto& [id, range] : ranges) {
      U4D_CHECK(id >= 1 && id < 65536, "MakeJointViewInputs: object id {} out of [1, 65535]", id);
      U4D_CHECK(range.first > 0 && range.second > range.first,
                "MakeJointViewInputs: object {} has the bad depth range [{}, {}]", id, range.first,
                range.second);
      num_labels = std::max(num_labels, id + 1);
    }
  std::vector<PersonPose> people;
  std::set<int> person_ids;
  for (const Pose3d& p : data.poses_t) {
    person_ids.insert(p.person_id);
    PersonPose person;
    person.object_id = p.person_id;
    person.at_t = p;
    for (const Pose3d& q : data.poses_t1)
      if (q.person_id == p.person_id) person.at_t1 = q, person.has_t1 = has_next;
    people.push_back(person);
  }

  // `poses`: those of the masks' frame (t's for t−1, which has none).
  auto labels_at = [&](const std::vector<cv::Mat>& masks, const std::vector<Camera>& full_cams,
                       int v, const Camera& working, const std::vector<Pose3d>& poses) -> cv::Mat {
    if (v >= static_cast<int>(masks.size()) || masks[v].empty()) return {};
    const cv::Mat ids = data.masks_are_object_ids
                            ? masks[v]
                            : AssignInstancesToPeople(full_cams[v], masks[v], poses, options);
    return Resize(ids, working, cv::INTER_NEAREST);
  };

  std::vector<JointViewInput> inputs(nv);
  tbb::parallel_for(0, nv, [&](int v) {
    JointViewInput& in = inputs[v];
    in.ref_view = v;
    in.cameras_t = cams_t;
    in.cameras_t1 = cams_t1;
    in.images_t = images_t;
    in.images_t1 = images_t1;
    in.num_labels = num_labels;
    in.people = people;
    const Camera& cam = cams_t[v];
    in.initial_labels = labels_at(data.masks_t, data.cameras_t, v, cam, data.poses_t);
    if (in.initial_labels.empty())
      in.initial_labels = cv::Mat::zeros(cam.height, cam.width, CV_16U);
    if (v < static_cast<int>(data.scores_t.size()) && !data.scores_t[v].empty())
      in.label_scores = LabelScores(in.initial_labels,
                                    Resize(data.scores_t[v], cam, cv::INTER_NEAREST), num_labels);
    in.appearance_training.push_back({images_t[v], in.initial_labels});
    if (!images_prev[v].empty()) {
      const cv::Mat prev = labels_at(data.masks_prev, data.cameras_t, v, cam, data.poses_t);
      if (!prev.empty()) in.appearance_training.push_back({images_prev[v], prev});
    }
    if (has_next) {
      const cv::Mat next = labels_at(data.masks_t1, data.cameras_t1, v, cams_t1[v],
                                     data.poses_t1.empty() ? data.poses_t : data.poses_t1);
      if (!next.empty()) in.appearance_training.push_back({images_t1[v], next});
    }
    if (v < static_cast<int>(data.sparse.size()))
      for (const SparseMotion& sm : data.sparse[v]) {
        SparseMotion scaled = sm;
        scaled.pixel = s * (sm.pixel.array() + 0.5).matrix() - Eigen::Vector2d::Constant(0.5);
        scaled.displacement = s * sm.displacement;
        in.sparse.push_back(scaled);
      }
    // People: instances plus capsules; depth ranges from the joints.
    const PosePriorMap capsules = by_poses ? RenderPosePrior(cam, has_next ? cams_t1[v] : cam,
                                                             images_t[v], people, options.pose)
                                           : PosePriorMap{};
    for (const PersonPose& person : people) {
      JointObject obj;
      obj.id = person.object_id;
      obj.region = (in.initial_labels == obj.id) | (capsules.object == obj.id);
      double zmin = 1e30, zmax = 0;
      for (const Eigen::Vector4d& j : person.at_t.joints) {
        if (j.w() < options.min_joint_confidence) continue;
        const double z = cam.Depth(j.head<3>());
        if (z > 0) zmin = std::min(zmin, z), zmax = std::max(zmax, z);
      }
      if (zmax <= 0 || cv::countNonZero(obj.region) == 0) continue;
      obj.depth_near = std::max(0.05, zmin - options.depth_margin_m);
      obj.depth_far = zmax + options.depth_margin_m;
      in.objects.push_back(obj);
    }
    // Objects without a pose: their masks are their regions; depth ranges as given.
    if (v < static_cast<int>(data.object_depth_ranges.size()))
      for (const auto& [id, range] : data.object_depth_ranges[v]) {
        JointObject obj;
        obj.id = id;
        obj.region = in.initial_labels == id;
        // Not in this view's labels, it may still be in another object's or
        // missed (AddHullSupport).
        if ((cv::countNonZero(obj.region) == 0 && !options.hull.enabled) || person_ids.count(id))
          continue;
        obj.depth_near = range.first;
        obj.depth_far = range.second;
        in.objects.push_back(obj);
      }
  });
  DropSwappedColourSamples(num_labels, &inputs);
  if (options.hull.enabled) AddHullSupport(cams_t, options.hull, &inputs);
  BorrowColourSamples(options.colour_from_other_views, &inputs);
  return inputs;
}

cv::Mat ViewBackgroundFlow(const JointFrameData& data, int v, double scale,
                           const BackgroundFlowOptions& options) {
  const Camera cam_t = ScaledCamera(data.cameras_t[v], scale);
  if (data.cameras_t1.empty() || !options.enabled)
    return cv::Mat::zeros(cam_t.height, cam_t.width, CV_32FC2);
  const Camera cam_t1 = ScaledCamera(data.cameras_t1[v], scale);
  if (!CameraMoved(cam_t, cam_t1)) return cv::Mat::zeros(cam_t.height, cam_t.width, CV_32FC2);
  auto grey = [&](const cv::Mat& bgr) {
    cv::Mat g;
    cv::cvtColor(Resize(bgr, cam_t, cv::INTER_AREA), g, cv::COLOR_BGR2GRAY);
    return g;
  };
  return BackgroundFlow(cam_t, cam_t1, grey(data.images_t[v]), grey(data.images_t1[v]), options);
}

}  // namespace u4d
