#include "u4d/io/poses.h"

#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "u4d/io/import_fourda.h"
#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

const fs::path kData = DataDir();

fs::path FreshDir(const std::string& name) { return test_util::FreshTestDir("poses_test", name); }

using test_util::ExpectErrorMentions;

TEST(Poses, CocoKeypointsAgreeWithTheFileAndTheMasks) {
  const fs::path path = kData / "coco_people" / "test_coco.json";
  U4D_SKIP_WITHOUT_SHARED_DATA(path);
  const CocoFile coco = ReadCocoFile(path);
  // 000000000785.jpg: one skier, all 17 keypoints labelled; nose (367, 81),
  // right ankle (396, 341) in the file.
  const std::vector<Pose2d> skier = ReadCocoKeypoints(path, "000000000785.jpg");
  ASSERT_EQ(skier.size(), 1u);
  EXPECT_EQ(skier[0].person_id, 1);
  EXPECT_EQ(skier[0].keypoints[coco17::kNose], Eigen::Vector3d(367, 81, 1));
  EXPECT_EQ(skier[0].keypoints[coco17::kRightAnkle], Eigen::Vector3d(396, 341, 1));

  // Labelled keypoints should lie on or near their own person's mask (the
  // polygon and the keypoints were drawn on the same person): within 6 px, as
  // hands and feet are often clicked just outside a coarse polygon. Occluded
  // keypoints (v = 1) may lie on whoever hides them, so not all do; on these
  // images 167 of 181 do, and a wrong person numbering or swapped x / y
  // would drop far below 90 %. Person ids must match the instance ids.
  int labelled = 0, near = 0;
  for (const CocoImage& image : coco.images) {
    const InstanceMask mask = CocoInstanceMask(coco, image);
    for (const Pose2d& pose : CocoKeypointPoses(coco, image)) {
      ASSERT_NE(mask.Find(pose.person_id), nullptr);
      cv::Mat own = mask.ids == pose.person_id;
      cv::dilate(own, own, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(13, 13)));
      for (const Eigen::Vector3d& k : pose.keypoints) {
        if (k.z() == 0) continue;
        ++labelled;
        const int x = static_cast<int>(std::lround(k.x())),
                  y = static_cast<int>(std::lround(k.y()));
        if (x >= 0 && y >= 0 && x < own.cols && y < own.rows && own.at<uint8_t>(y, x)) ++near;
      }
    }
  }
  EXPECT_GT(labelled, 100);
  EXPECT_GE(near, 0.9 * labelled) << near << " of " << labelled;
}

TEST(Poses, OpenPoseLayoutsMapToCoco17) {
  const fs::path dir = FreshDir("openpose");
  // Keypoint i of the source layout at (10 i, 10 i + 1), confidence 0.5,
  // except source keypoint 0 (nose), which is missing.
  const auto make = [](int n) {
    nlohmann::json kp = nlohmann::json::array();
    for (int i = 0; i < n; ++i) {
      kp.push_back(10.0 * i);
      kp.push_back(10.0 * i + 1);
      kp.push_back(i == 0 ? 0.0 : 0.5);
    }
    return kp;
  };
  WriteJsonFileAtomic(dir / "body25.json",
                      {{"version", 1.3},
                       {"people",
                        {{{"person_id", {-1}}, {"pose_keypoints_2d", make(25)}},
                         {{"person_id", {4}}, {"pose_keypoints_2d", make(25)}}}}});
  const std::vector<Pose2d> b = ReadOpenPoseJson(dir / "body25.json");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].person_id, -1);
  EXPECT_EQ(b[1].person_id, 4);
  // BODY_25: 16 = left eye, 18 = left ear, 12 = left hip, 11 = right ankle.
  EXPECT_EQ(b[0].keypoints[coco17::kLeftEye], Eigen::Vector3d(160, 161, 0.5));
  EXPECT_EQ(b[0].keypoints[coco17::kLeftEar], Eigen::Vector3d(180, 181, 0.5));
  EXPECT_EQ(b[0].keypoints[coco17::kLeftHip], Eigen::Vector3d(120, 121, 0.5));
  EXPECT_EQ(b[0].keypoints[coco17::kRightAnkle], Eigen::Vector3d(110, 111, 0.5));
  EXPECT_EQ(b[0].keypoints[coco17::kNose].z(), 0);
  EXPECT_DOUBLE_EQ(b[0].score, 0.5);

  WriteJsonFileAtomic(dir / "coco18.json", {{"people", {{{"pose_keypoints_2d", make(18)}}}}});
  const std::vector<Pose2d> c = ReadOpenPoseJson(dir / "coco18.json");
  ASSERT_EQ(c.size(), 1u);
  // COCO-18: 15 = left eye, 17 = left ear, 11 = left hip, 10 = right ankle.
  EXPECT_EQ(c[0].keypoints[coco17::kLeftEye], Eigen::Vector3d(150, 151, 0.5));
  EXPECT_EQ(c[0].keypoints[coco17::kLeftEar], Eigen::Vector3d(170, 171, 0.5));
  EXPECT_EQ(c[0].keypoints[coco17::kLeftHip], Eigen::Vector3d(110, 111, 0.5));
  EXPECT_EQ(c[0].keypoints[coco17::kRightAnkle], Eigen::Vector3d(100, 101, 0.5));

  WriteJsonFileAtomic(dir / "odd.json", {{"people", {{{"pose_keypoints_2d", make(20)}}}}});
  ExpectErrorMentions([&] { ReadOpenPoseJson(dir / "odd.json"); }, {"odd.json", "60"});
}

TEST(Poses, OwnFilesRoundTripAndRejectBadInput) {
  const fs::path dir = FreshDir("own");
  Pose2d p;
  p.person_id = 3;
  p.score = 0.75;
  for (int k = 0; k < 17; ++k) p.keypoints[k] = Eigen::Vector3d(k + 0.25, 2 * k - 0.5, k % 2);
  WritePoses2d(dir / "p2.json", {p});
  const std::vector<Pose2d> back = ReadPoses2d(dir / "p2.json");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].person_id, 3);
  EXPECT_EQ(back[0].score, 0.75);
  for (int k = 0; k < 17; ++k) EXPECT_EQ(back[0].keypoints[k], p.keypoints[k]);

  Pose3d q;
  q.person_id = 1;
  for (int k = 0; k < 17; ++k) q.joints[k] = Eigen::Vector4d(0.1 * k, -0.2 * k, 3.0 + k, 1.0);
  WritePoses3d(dir / "p3.json", {q, q});
  const std::vector<Pose3d> back3 = ReadPoses3d(dir / "p3.json");
  ASSERT_EQ(back3.size(), 2u);
  for (int k = 0; k < 17; ++k) EXPECT_EQ(back3[1].joints[k], q.joints[k]);

  // Writers refuse what the readers would refuse.
  Pose2d nan = p;
  nan.keypoints[4].x() = std::nan("");
  EXPECT_THROW(WritePoses2d(dir / "nan.json", {nan}), Error);

  nlohmann::json j = ReadJsonFile(dir / "p2.json");
  j["people"][0]["keypoints"].erase(16);
  WriteJsonFileAtomic(dir / "short.json", j);
  ExpectErrorMentions([&] { ReadPoses2d(dir / "short.json"); }, {"short.json", "17"});
  j = ReadJsonFile(dir / "p2.json");
  j["people"][0]["keypoints"][2][2] = 1.5;
  WriteJsonFileAtomic(dir / "conf.json", j);
  ExpectErrorMentions([&] { ReadPoses2d(dir / "conf.json"); }, {"conf.json", "1.5"});
  ExpectErrorMentions([&] { ReadPoses3d(dir / "p2.json"); }, {"p2.json", "u4d-poses3d"});
  j = ReadJsonFile(dir / "p3.json");
  j["units"] = "millimetres";
  WriteJsonFileAtomic(dir / "mm.json", j);
  ExpectErrorMentions([&] { ReadPoses3d(dir / "mm.json"); }, {"mm.json", "millimetres"});
  ExpectErrorMentions([&] { ReadPoses3d(dir / "none.json"); }, {"none.json"});
}

// COCO-17 points of a standing person (x right, y up, z forward; metres).
std::array<Eigen::Vector4d, 17> StandingCoco() {
  std::array<Eigen::Vector4d, 17> c;
  const auto at = [](double x, double y, double z) { return Eigen::Vector4d(x, y, z, 1.0); };
  c[coco17::kNose] = at(0, 1.62, 0.10);
  c[coco17::kLeftEye] = at(0.03, 1.66, 0.08);
  c[coco17::kRightEye] = at(-0.03, 1.66, 0.08);
  c[coco17::kLeftEar] = at(0.08, 1.64, 0.0);
  c[coco17::kRightEar] = at(-0.08, 1.64, 0.0);
  c[coco17::kLeftShoulder] = at(0.18, 1.42, 0);
  c[coco17::kRightShoulder] = at(-0.18, 1.42, 0);
  c[coco17::kLeftElbow] = at(0.22, 1.15, 0);
  c[coco17::kRightElbow] = at(-0.22, 1.15, 0);
  c[coco17::kLeftWrist] = at(0.24, 0.90, 0.05);
  c[coco17::kRightWrist] = at(-0.24, 0.90, 0.05);
  c[coco17::kLeftHip] = at(0.10, 0.92, 0);
  c[coco17::kRightHip] = at(-0.10, 0.92, 0);
  c[coco17::kLeftKnee] = at(0.10, 0.50, 0.02);
  c[coco17::kRightKnee] = at(-0.10, 0.50, 0.02);
  c[coco17::kLeftAnkle] = at(0.10, 0.08, 0);
  c[coco17::kRightAnkle] = at(-0.10, 0.08, 0);
  return c;
}

TEST(Poses, H36mFromCocoFollowsTheDocumentedRules) {
  std::array<Eigen::Vector4d, 17> c = StandingCoco();
  c[coco17::kLeftHip][3] = 0.8;
  std::array<Eigen::Vector4d, 17> h = H36m17FromCoco17(c);
  EXPECT_LT((h[h36m17::kPelvis] - Eigen::Vector4d(0, 0.92, 0, 0.8)).norm(), 1e-12);
  EXPECT_LT((h[h36m17::kThorax] - Eigen::Vector4d(0, 1.42, 0, 1)).norm(), 1e-12);
  EXPECT_LT((h[h36m17::kSpine] - Eigen::Vector4d(0, 1.17, 0, 0.8)).norm(), 1e-12);
  EXPECT_LT((h[h36m17::kHead] - Eigen::Vector4d(0, 1.64, 0, 1)).norm(), 1e-12);  // mid-ears
  EXPECT_LT((h[h36m17::kNeck] - Eigen::Vector4d(0, 1.53, 0, 1)).norm(), 1e-12);
  EXPECT_EQ(h[h36m17::kLeftKnee], c[coco17::kLeftKnee]);
  EXPECT_EQ(h[h36m17::kRightWrist], c[coco17::kRightWrist]);
  // Anatomical order along the body axis.
  EXPECT_LT(h[h36m17::kPelvis].y(), h[h36m17::kSpine].y());
  EXPECT_LT(h[h36m17::kSpine].y(), h[h36m17::kThorax].y());
  EXPECT_LT(h[h36m17::kThorax].y(), h[h36m17::kNeck].y());
  EXPECT_LT(h[h36m17::kNeck].y(), h[h36m17::kHead].y());

  // One ear missing: the head falls back to the eyes, then to the nose.
  c[coco17::kLeftEar][3] = 0;
  h = H36m17FromCoco17(c);
  EXPECT_LT((h[h36m17::kHead] - Eigen::Vector4d(0, 1.66, 0.08, 1)).norm(), 1e-12);
  c[coco17::kRightEye][3] = 0;
  h = H36m17FromCoco17(c);
  EXPECT_EQ(h[h36m17::kHead], c[coco17::kNose]);
  // A missing hip makes pelvis and spine missing.
  c[coco17::kRightHip][3] = 0;
  h = H36m17FromCoco17(c);
  EXPECT_EQ(h[h36m17::kPelvis][3], 0);
  EXPECT_EQ(h[h36m17::kSpine][3], 0);

  // 2D variant and the way back: shared joints survive, the face is missing.
  std::array<Eigen::Vector3d, 17> c2;
  for (int k = 0; k < 17; ++k) c2[k] = Eigen::Vector3d(k, 2 * k, 1);
  const std::array<Eigen::Vector3d, 17> back = Coco17FromH36m17(H36m17FromCoco17(c2));
  for (int k = 0; k < 17; ++k) {
    if (k <= coco17::kRightEar)
      EXPECT_EQ(back[k].z(), 0) << Coco17Names()[k];
    else
      EXPECT_EQ(back[k], c2[k]) << Coco17Names()[k];
  }
}

double Dist(const Pose3d& p, int a, int b) {
  return (p.joints[a].head<3>() - p.joints[b].head<3>()).norm();
}

TEST(Poses, ShelfGroundTruthIsAPlausibleMetricSkeleton) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "shelf_pose" / "gt.txt");
  const FourdaGroundTruth gt = ReadFourdaGroundTruth(kData / "shelf_pose" / "gt.txt");
  EXPECT_EQ(gt.num_joints, 15);
  ASSERT_EQ(gt.frames.size(), 301u);
  int people = 0;
  namespace H = h36m17;
  const std::vector<std::pair<int, int>> limbs = {
      {H::kRightHip, H::kRightKnee},       {H::kRightKnee, H::kRightAnkle},
      {H::kLeftHip, H::kLeftKnee},         {H::kLeftKnee, H::kLeftAnkle},
      {H::kLeftShoulder, H::kLeftElbow},   {H::kLeftElbow, H::kLeftWrist},
      {H::kRightShoulder, H::kRightElbow}, {H::kRightElbow, H::kRightWrist}};
  const fs::path dir = FreshDir("shelf");
  for (size_t f = 0; f < gt.frames.size(); ++f) {
    std::vector<Pose3d> poses;
    for (const FourdaPerson3d& person : gt.frames[f]) {
      const Pose3d p = H36m17FromShelf15(person.joints, person.id);
      ++people;
      // Shelf's world is z up, the floor at z = 0: heights in [-0.15, 2.2] m.
      for (const Eigen::Vector4d& j : p.joints) {
        EXPECT_GT(j.z(), -0.15);
        EXPECT_LT(j.z(), 2.2);
      }
      // Adult limbs (upper/lower arm, thigh, shin): 0.12 .. 0.6 m.
      for (const auto& [a, b] : limbs) {
        EXPECT_GT(Dist(p, a, b), 0.12) << "frame " << f << " limb " << a << "-" << b;
        EXPECT_LT(Dist(p, a, b), 0.6) << "frame " << f << " limb " << a << "-" << b;
      }
      // The built joints keep the body axis in order, head on top.
      EXPECT_LT(p.joints[H::kPelvis].z(), p.joints[H::kSpine].z());
      EXPECT_LT(p.joints[H::kSpine].z(), p.joints[H::kThorax].z());
      EXPECT_LT(p.joints[H::kNeck].z(), p.joints[H::kHead].z());
      EXPECT_LT(p.joints[H::kLeftAnkle].z(), p.joints[H::kLeftKnee].z());
      poses.push_back(p);
    }
    if (f == 150) {  // the 3D file format carries it unchanged
      WritePoses3d(dir / "000150.json", poses);
      const std::vector<Pose3d> back = ReadPoses3d(dir / "000150.json");
      ASSERT_EQ(back.size(), poses.size());
      for (size_t i = 0; i < poses.size(); ++i)
        for (int k = 0; k < 17; ++k) EXPECT_EQ(back[i].joints[k], poses[i].joints[k]);
    }
  }
  EXPECT_GT(people, 301);  // at least one person per frame on average
}

TEST(Poses, ShelfDetectionsParseCompletely) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "shelf_pose" / "detection");
  for (int cam = 0; cam < 5; ++cam) {
    const fs::path path = kData / "shelf_pose" / "detection" / (std::to_string(cam) + ".txt");
    const FourdaDetections det = ReadFourdaDetections(path);  // throws on leftovers
    ASSERT_EQ(det.frames.size(), 301u) << path;
    int candidates = 0;
    for (const FourdaDetectionFrame& frame : det.frames) {
      ASSERT_EQ(frame.joints.size(), 25u);
      ASSERT_EQ(frame.pafs.size(), 26u);
      for (const Eigen::Matrix3Xd& j : frame.joints) {
        candidates += static_cast<int>(j.cols());
        // Normalised image coordinates and scores.
        if (j.cols() > 0) {
          EXPECT_GE(j.minCoeff(), 0.0);
          EXPECT_LE(j.topRows<2>().maxCoeff(), 1.0);
        }
      }
      // The limbs through the neck (BODY_25 joint 1): the neck-mid-hip PAF
      // has one row per neck candidate.
      EXPECT_EQ(frame.pafs[0].rows(), frame.joints[1].cols());
      EXPECT_EQ(frame.pafs[0].cols(), frame.joints[8].cols());
    }
    EXPECT_GT(candidates, 301 * 25) << path;  // a few people seen in most frames
  }
}

}  // namespace
}  // namespace u4d
