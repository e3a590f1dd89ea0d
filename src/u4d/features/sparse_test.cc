// Sparse reconstruction and initial object regions against the ground truth
// of synthetic handshake captures (5 views at 480x270, and the preset's 8
// views at 960x540 for the accuracy test; 2 frames each).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include <opencv2/imgproc.hpp>

#include "u4d/features/object_regions.h"
#include "u4d/features/sparse_points.h"
#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/poses.h"
#include "u4d/synth/generate.h"
#include "u4d/util/check.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

struct FrameData {
  std::vector<Camera> cameras;
  std::vector<cv::Mat> images, masks, gt_ids, gt_depth;
  std::vector<Pose3d> gt_poses;
};

class SparseSynthTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test_util::RemovedAtExit(synth::WriteCaptureToTempDir(
        "features_sparse_test", synth::SmallHandshakeOptions(5, 480, 270, 2)));
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static FrameData Load(int frame) {
    const Capture capture = ReadCapture(dir_);
    FrameReader reader(capture);
    FrameData d;
    for (int v = 0; v < capture.NumViews(); ++v) {
      const std::string& name = capture.views[v].name;
      d.cameras.push_back(capture.views[v].CameraAt(frame));
      d.images.push_back(reader.Read(v, frame));
      d.masks.push_back(
          ReadInstanceMask(dir_ / layout::Mask(name, frame), dir_ / layout::MaskInfo(name, frame))
              .ids);
      d.gt_ids.push_back(ReadInstanceMask(dir_ / layout::GtInstances(name, frame),
                                          dir_ / layout::GtInstancesInfo(name, frame))
                             .ids);
      d.gt_depth.push_back(ReadPfm(dir_ / layout::GtDepth(name, frame)));
    }
    d.gt_poses = ReadPoses3d(dir_ / layout::GtJoints3d(frame));
    return d;
  }
  static inline fs::path dir_;
};

float DepthAt(const cv::Mat& depth, const Eigen::Vector2d& px) {
  const int c = static_cast<int>(std::lround(px.x())), r = static_cast<int>(std::lround(px.y()));
  if (c < 0 || r < 0 || c >= depth.cols || r >= depth.rows) return NAN;
  return depth.at<float>(r, c);
}

// GT instance of a point: majority of the GT ids at its observed pixels.
int GtInstanceOf(const SparsePoint& p, const FrameData& d) {
  std::map<int, int> votes;
  for (size_t i = 0; i < p.observations.size(); ++i) {
    ++votes[MaskIdAt(d.gt_ids[p.observations[i].first], p.pixels[i])];
  }
  return std::max_element(votes.begin(), votes.end(),
                          [](const auto& a, const auto& b) { return a.second < b.second; })
      ->first;
}

// Object id -> GT id by majority over the object's points.
std::map<int, int> ObjectToGt(const std::vector<SparsePoint>& points, const FrameData& d) {
  std::map<int, std::map<int, int>> votes;
  for (const SparsePoint& p : points) ++votes[p.instance][GtInstanceOf(p, d)];
  std::map<int, int> out;
  for (const auto& [obj, v] : votes) {
    out[obj] =
        obj == 0 ? 0 : std::max_element(v.begin(), v.end(), [](const auto& a, const auto& b) {
                         return a.second < b.second;
                       })->first;
  }
  return out;
}

// The accuracy test runs on the preset's own rig: 8 views on a ring (45
// degrees apart) at 960x540. On the 5-view 480x270 capture above the people
// are ~60 px wide and neighbouring views are 72 degrees apart, beyond what
// SIFT matches reliably (measured: 10-13 points per frame, 30 % within 2 cm).
class SparseAccuracyTest : public SparseSynthTest {
 protected:
  static void SetUpTestSuite() {
    dir_ = test_util::RemovedAtExit(synth::WriteCaptureToTempDir(
        "features_sparse_accuracy_test", synth::SmallHandshakeOptions(8, 960, 540, 2)));
  }
};

TEST_F(SparseAccuracyTest, PointsAreAccurateAndOnTheRightInstance) {
  SparseFrameOptions options;
  // The synthetic calibration is exact: the epipolar gate only has to admit
  // the keypoint localisation noise (~0.3 px), 1 px is 3 sigma. (The default
  // 2 px leaves room for real calibration error.) Measured with 2 px: 79-95
  // points, 82-86 % within 2 cm, 90-96 % on the right instance.
  options.matching.max_epipolar_px = 1.0;
  for (int frame = 0; frame < 2; ++frame) {
    const FrameData d = Load(frame);
    const SparseFrame sf = ReconstructSparseFrame(d.cameras, d.images, d.masks, options);
    const auto& pts = sf.points;
    double sq = 0;
    int n_obs = 0, within_2cm = 0, with_depth = 0, right = 0;
    for (const SparsePoint& p : pts) {
      sq += p.reprojection_rmse * p.reprojection_rmse * p.observations.size();
      n_obs += static_cast<int>(p.observations.size());
      std::vector<double> errors;
      for (size_t i = 0; i < p.observations.size(); ++i) {
        const int v = p.observations[i].first;
        const float gt = DepthAt(d.gt_depth[v], p.pixels[i]);
        if (std::isfinite(gt) && gt > 0)
          errors.push_back(std::abs(d.cameras[v].Depth(p.position) - gt));
      }
      if (errors.empty()) continue;
      std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
      ++with_depth;
      if (errors[errors.size() / 2] < 0.02) ++within_2cm;
    }
    ASSERT_GT(pts.size(), 0u);
    const std::map<int, int> to_gt = ObjectToGt(pts, d);
    for (const SparsePoint& p : pts) right += to_gt.at(p.instance) == GtInstanceOf(p, d);
    const double rmse = std::sqrt(sq / n_obs);
    const double share_2cm = static_cast<double>(within_2cm) / with_depth;
    const double share_right = static_cast<double>(right) / pts.size();
    std::printf(
        "frame %d: %zu points, %zu tracks, rmse %.3f px, within 2 cm %.3f, right instance "
        "%.3f, objects %d\n",
        frame, pts.size(), sf.tracks.size(), rmse, share_2cm, share_right,
        sf.association.num_objects);
    // Enough points for a sparse depth range per person and view
    // (ObjectRegionOptions::min_points = 10 for each of the 2 people, seen in
    // several views). Measured: 77-85.
    EXPECT_GE(pts.size(), 40u);
    // SIFT localises to ~0.3 px on sharp renders; observations beyond 2 px are
    // cut, so an RMSE near 1 px would mean a systematic (calibration) error.
    EXPECT_LT(rmse, 0.8);
    // At ~5 m, 960 px wide views (f ~ 900 px), 45 degree baselines and 0.3 px
    // noise, the depth error of a point is a few mm; mismatches and points on
    // depth edges (the nearest GT pixel belongs to the other surface) make up
    // the rest. Measured: 0.90-0.91.
    EXPECT_GT(share_2cm, 0.8);
    // The target: >= 90 % of points on the right instance despite the
    // degraded masks (noisy boundaries, merges, dropped views). Measured:
    // 0.965-0.974.
    EXPECT_GE(share_right, 0.9);
    // The two people and no more than two spurious (false-positive) objects.
    EXPECT_GE(sf.association.num_objects, 2);
    EXPECT_LE(sf.association.num_objects, 4);
  }
}

// GT instance maps as masks with the identity association (object = GT id),
// so that the region logic is tested apart from the instance association.
InstanceAssociation IdentityAssociation(const FrameData& d) {
  InstanceAssociation a;
  a.object_of.resize(d.cameras.size());
  for (const Pose3d& p : d.gt_poses) {
    a.num_objects = std::max(a.num_objects, p.person_id);
    for (auto& m : a.object_of) m[p.person_id] = p.person_id;
  }
  return a;
}

TEST_F(SparseSynthTest, RegionsContainTheGroundTruthDepth) {
  const FrameData d = Load(0);
  SparseFrame sf = ReconstructSparseFrame(d.cameras, d.images, d.gt_ids);
  const InstanceAssociation association = IdentityAssociation(d);
  AssignInstances(d.gt_ids, association, sf.points);
  const auto regions =
      InitialObjectRegions(d.cameras, d.gt_ids, association, sf.points, d.gt_poses);
  std::map<int, int> to_gt;
  for (int o = 1; o <= association.num_objects; ++o) to_gt[o] = o;
  int checked = 0;
  for (const auto& per_view : regions) {
    const int gt_id = to_gt.count(per_view[0].instance) ? to_gt.at(per_view[0].instance) : 0;
    if (gt_id == 0) continue;  // a false-positive object
    for (const ObjectRegion& r : per_view) {
      const cv::Mat gt_mask = d.gt_ids[r.view] == gt_id;
      int total = 0, in_range = 0, covered = 0;
      for (int y = 0; y < gt_mask.rows; ++y) {
        for (int x = 0; x < gt_mask.cols; ++x) {
          if (!gt_mask.at<uint8_t>(y, x)) continue;
          const float z = d.gt_depth[r.view].at<float>(y, x);
          ++total;
          in_range += z >= r.depth_near && z <= r.depth_far;
          covered += r.mask.at<uint8_t>(y, x) != 0;
        }
      }
      if (total < 200 || !r.detected) continue;  // barely visible or undetected here
      ++checked;
      std::printf(
          "object %d (gt %d) view %d: %s [%.2f, %.2f] m, depth in range %.3f, "
          "coverage %.3f, pose-added %d px\n",
          r.instance, gt_id, r.view, ToString(r.depth_source).c_str(), r.depth_near, r.depth_far,
          double(in_range) / total, double(covered) / total, r.pose_added_pixels);
      // The range spans the visible surface from the sparse points plus a
      // 0.25 m margin; >= 95 % of the person's GT depths must fall inside.
      EXPECT_GE(static_cast<double>(in_range) / total, 0.95) << "view " << r.view;
      // The degraded mask (boundary noise ~ 1-2 px, possibly a missing limb)
      // repaired by the pose constraint covers most of the silhouette.
      EXPECT_GE(static_cast<double>(covered) / total, 0.85) << "view " << r.view;
    }
  }
  EXPECT_GE(checked, 5);
}

// A forearm cut from an otherwise perfect mask is restored by the pose
// constraint when the 3D joints are given, and not without them.
TEST_F(SparseSynthTest, PoseConstraintRestoresADroppedForearm) {
  const FrameData d = Load(1);
  // Perfect masks (GT), then cut person 1's left forearm in view 0.
  std::vector<cv::Mat> masks = d.gt_ids;
  const Pose3d* pose = nullptr;
  for (const Pose3d& p : d.gt_poses) pose = pose ? pose : &p;
  ASSERT_NE(pose, nullptr);
  const int gt_id = pose->person_id;
  const int view = 0;
  const Camera& cam = d.cameras[view];
  const Eigen::Vector2d elbow = cam.Project(pose->joints[h36m17::kLeftElbow].head<3>());
  const Eigen::Vector2d wrist = cam.Project(pose->joints[h36m17::kLeftWrist].head<3>());
  const Eigen::Vector2d tip = wrist + 0.35 * (wrist - elbow);  // the hand beyond the wrist
  cv::Mat cut = cv::Mat::zeros(masks[view].size(), CV_8U);
  const cv::Point a(std::lround(0.5 * (elbow.x() + wrist.x())),
                    std::lround(0.5 * (elbow.y() + wrist.y())));
  cv::line(cut, a, cv::Point(std::lround(tip.x()), std::lround(tip.y())), 255, 15);
  cut &= (masks[view] == gt_id);
  const int cut_pixels = cv::countNonZero(cut);
  ASSERT_GT(cut_pixels, 20) << "the forearm is not visible in view 0";
  masks[view] = masks[view].clone();
  masks[view].setTo(0, cut);

  const InstanceAssociation association = IdentityAssociation(d);
  const int object = gt_id;
  const auto with = InitialObjectRegions(d.cameras, masks, association, {}, d.gt_poses);
  const auto without = InitialObjectRegions(d.cameras, masks, association, {}, {});
  const cv::Mat gt_mask = d.gt_ids[view] == gt_id;
  const int restored = cv::countNonZero(with[object - 1][view].mask & cut);
  const int restored_without = cv::countNonZero(without[object - 1][view].mask & cut);
  const int spurious = cv::countNonZero(with[object - 1][view].mask & ~gt_mask);
  std::printf("cut %d px, restored %d with joints, %d without; region pixels outside GT %d\n",
              cut_pixels, restored, restored_without, spurious);
  // The bone drawn with a 7 cm radius is wider than a forearm: all but the
  // pixels at the cut's rounded ends must come back.
  EXPECT_GE(restored, 0.8 * cut_pixels);
  EXPECT_EQ(restored_without, 0);
}

// Two views, each with instances 1 and 2; five points link view 0's
// instance 1 to view 1's instance 2 (and nothing else). Without classes they
// are one object; with different classes they stay apart.
TEST(SparsePoints, InstancesOfDifferentClassesAreNeverOneObject) {
  Camera cam;
  cam.width = 20;
  cam.height = 10;
  const std::vector<Camera> cams = {cam, cam};
  cv::Mat mask(10, 20, CV_16U, cv::Scalar(0));
  mask(cv::Rect(0, 0, 10, 10)).setTo(1);
  mask(cv::Rect(10, 0, 10, 10)).setTo(2);
  const std::vector<cv::Mat> masks = {mask, mask};
  std::vector<SparsePoint> points(5);
  for (int i = 0; i < 5; ++i) {
    points[i].observations = {{0, i}, {1, i}};
    points[i].pixels = {Eigen::Vector2d(2 + i, 5), Eigen::Vector2d(12 + i, 5)};
  }
  const InstanceAssociation blind = AssociateInstances(cams, masks, points);
  EXPECT_EQ(blind.num_objects, 1);
  EXPECT_EQ(blind.ObjectOf(0, 1), blind.ObjectOf(1, 2));
  InstanceClasses classes = {{{1, "box"}, {2, "person"}}, {{1, "person"}, {2, "ball"}}};
  const InstanceAssociation apart = AssociateInstances(cams, masks, points, {}, &classes);
  EXPECT_EQ(apart.num_objects, 0);  // no cluster spans two views
  classes[1][2] = "box";
  const InstanceAssociation alike = AssociateInstances(cams, masks, points, {}, &classes);
  EXPECT_EQ(alike.num_objects, 1);
  EXPECT_EQ(alike.ObjectOf(0, 1), alike.ObjectOf(1, 2));
  classes.pop_back();
  EXPECT_THROW(AssociateInstances(cams, masks, points, {}, &classes), Error);
}

// A point on an object seen in view 0 and on the background of views 1 and
// 2, where a person's detection covers it (the object merged with, or hidden
// by, the person there): background by majority, unless those views abstain.
TEST(SparsePoints, ViewsThatCannotTellAbstainFromTheVote) {
  cv::Mat object(10, 20, CV_16U, cv::Scalar(0)), none(10, 20, CV_16U, cv::Scalar(0));
  object(cv::Rect(0, 0, 10, 10)).setTo(1);
  cv::Mat person(10, 20, CV_16U, cv::Scalar(0));
  person(cv::Rect(0, 0, 10, 10)).setTo(1);
  const std::vector<cv::Mat> masks = {object, none, none};
  InstanceAssociation association;
  association.num_objects = 1;
  association.object_of = {{{1, 1}}, {}, {}};
  std::vector<SparsePoint> points(1);
  points[0].observations = {{0, 0}, {1, 0}, {2, 0}};
  points[0].pixels.assign(3, Eigen::Vector2d(5, 5));
  AssignInstances(masks, association, points);
  EXPECT_EQ(points[0].instance, 0);
  const std::vector<cv::Mat> unknown = {cv::Mat(), person, person};
  AssignInstances(masks, association, points, &unknown);
  EXPECT_EQ(points[0].instance, 1);
  const std::vector<cv::Mat> short_list = {person};
  EXPECT_THROW(AssignInstances(masks, association, points, &short_list), Error);
}

TEST(SparsePoints, BadInputThrows) {
  Camera cam;
  cam.width = 10;
  cam.height = 10;
  std::vector<Camera> cams = {cam, cam};
  std::vector<ViewKeypoints> kps(1);
  EXPECT_THROW(TriangulateTracks(cams, kps, {}), Error);
  EXPECT_THROW(AssociateInstances(cams, {cv::Mat()}, {}), Error);
  SparseOptions bad;
  bad.min_views = 1;
  EXPECT_THROW(bad.Check(), Error);
  MatchingOptions bad_match;
  bad_match.ratio = 1.5;
  EXPECT_THROW(bad_match.Check(), Error);
  bad_match = {};
  bad_match.neighbour_views = -1;
  EXPECT_THROW(bad_match.Check(), Error);
  bad_match = {};
  bad_match.max_pair_angle_deg = 0;
  EXPECT_THROW(bad_match.Check(), Error);
  EXPECT_THROW(DetectKeypoints(cv::Mat(), cv::Mat()), Error);
  EXPECT_THROW(DetectKeypoints(cv::Mat::zeros(10, 10, CV_8U), cv::Mat::zeros(5, 5, CV_8U)), Error);
}

}  // namespace
}  // namespace u4d
