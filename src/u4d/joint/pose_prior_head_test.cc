// E_p's head capsule against the synthetic ground truth: poses triangulated
// from the capture's 2D keypoints, as `u4d run` builds them, put the head
// joint at the head centre (docs/annotations.md), and the capsules drawn from
// them (pose_prior.h, default options) must claim the top of each person's
// head for that person, also where another person stands behind it. With the
// crown setting on these joints the capsule stops at the ears and the top of
// the head is left to nobody or to the person behind.
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "u4d/io/capture.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/poses.h"
#include "u4d/joint/pose_prior.h"
#include "u4d/pose/multiview_pose.h"
#include "u4d/synth/generate.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

// Pixels of the top of the heads, and how many of them the capsules give to
// their own person and to another person.
struct HeadTops {
  int pixels = 0, own = 0, other = 0;
};

// The GT person whose pelvis is nearest to `pose`'s (the ids of the
// triangulated poses are their order of discovery).
int NearestGtPerson(const Pose3d& pose, const std::vector<Pose3d>& gt) {
  int best = 0;
  double best_d = 1e9;
  for (const Pose3d& g : gt) {
    const double d =
        (g.joints[h36m17::kPelvis].head<3>() - pose.joints[h36m17::kPelvis].head<3>()).norm();
    if (d < best_d) best_d = d, best = g.person_id;
  }
  return best;
}

// The poses triangulated from frame f's 2D keypoints, as `u4d run` builds
// them, each named by its nearest GT person; `cameras` receives the views'.
std::vector<PersonPose> TriangulatedPeople(const Capture& capture, int f,
                                           std::vector<Camera>* cameras) {
  std::vector<std::vector<Pose2d>> per_view;
  cameras->clear();
  for (int v = 0; v < capture.NumViews(); ++v) {
    per_view.push_back(ReadPoses2d(capture.root / layout::Poses2d(capture.views[v].name, f)));
    cameras->push_back(capture.views[v].CameraAt(f));
  }
  const std::vector<Pose3d> gt = ReadPoses3d(capture.root / layout::GtJoints3d(f));
  std::vector<PersonPose> people;
  for (const Pose3d& pose : TriangulatePoses(per_view, *cameras)) {
    PersonPose person;
    person.object_id = NearestGtPerson(pose, gt);
    person.at_t = pose;
    people.push_back(person);
  }
  EXPECT_EQ(people.size(), gt.size()) << "frame " << f;
  return people;
}

// Adds the top `fraction` of each GT person's silhouette rows in `ids` (its
// head, for people standing upright), scored against the capsules' map.
void AddHeadTops(const cv::Mat& ids, const PosePriorMap& map, double fraction, HeadTops* score) {
  std::map<int, std::pair<int, int>> rows;  // person -> first and last row
  for (int y = 0; y < ids.rows; ++y)
    for (int x = 0; x < ids.cols; ++x)
      if (const int id = ids.at<uint16_t>(y, x); id > 0)
        rows.try_emplace(id, y, y).first->second.second = y;
  for (int y = 0; y < ids.rows; ++y)
    for (int x = 0; x < ids.cols; ++x) {
      const int id = ids.at<uint16_t>(y, x);
      if (id == 0) continue;
      const auto [top, bottom] = rows[id];
      if (y > top + fraction * (bottom - top)) continue;
      const int claimed = map.object.at<uint16_t>(y, x);
      ++score->pixels;
      score->own += claimed == id;
      score->other += claimed != 0 && claimed != id;
    }
}

// The head tops of every view and frame against the capsules drawn with `options`.
HeadTops ScoreHeadTops(const Capture& capture, const PosePriorOptions& options, double fraction) {
  HeadTops score;
  for (int f = 0; f < capture.num_frames; ++f) {
    std::vector<Camera> cameras;
    const std::vector<PersonPose> people = TriangulatedPeople(capture, f, &cameras);
    for (int v = 0; v < capture.NumViews(); ++v) {
      const std::string& name = capture.views[v].name;
      const cv::Mat ids = ReadInstanceMask(capture.root / layout::GtInstances(name, f),
                                           capture.root / layout::GtInstancesInfo(name, f))
                              .ids;
      AddHeadTops(ids,
                  RenderPosePrior(cameras[v], cameras[v], cv::Mat::zeros(ids.size(), CV_8UC3),
                                  people, options),
                  fraction, &score);
    }
  }
  return score;
}

TEST(PosePriorHeadTest, TheTopOfEachHeadBelongsToItsPerson) {
  // The handshake: two people, one in front of the other in some views.
  const fs::path dir = test_util::RemovedAtExit(synth::WriteCaptureToTempDir(
      "pose_prior_head", synth::SmallHandshakeOptions(6, 320, 180, 4)));
  const Capture capture = ReadCapture(dir);
  const double fraction = 0.06;  // ~10 cm of a 1.75 m person: above the ears
  const HeadTops centre = ScoreHeadTops(capture, PosePriorOptions{}, fraction);
  PosePriorOptions crown_options;
  crown_options.head_joint_on_crown = true;
  const HeadTops crown = ScoreHeadTops(capture, crown_options, fraction);
  ASSERT_GT(centre.pixels, 500);
  const double own = static_cast<double>(centre.own) / centre.pixels;
  const double other = static_cast<double>(centre.other) / centre.pixels;
  const double crown_own = static_cast<double>(crown.own) / crown.pixels;
  std::printf("top of the heads (%d px): own %.3f other %.3f; crown setting own %.3f other %.3f\n",
              centre.pixels, own, other, crown_own,
              static_cast<double>(crown.other) / crown.pixels);
  // The cap is a sphere of head_radius_m around a joint triangulated from
  // keypoints with detector noise (2 px at 320 px, a few centimetres), and
  // the GT head is an ellipsoid 11 cm tall above its centre: the topmost rows
  // are not all covered, and a few go to the capsules of the person behind.
  EXPECT_GE(own, 0.8);
  EXPECT_LE(other, 0.02);
  EXPECT_LT(crown_own, 0.1);
}

}  // namespace
}  // namespace u4d
