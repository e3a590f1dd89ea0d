// Human poses as annotation inputs: 2D keypoints per view and frame (COCO-17
// order) and 3D joints per frame (the internal Human3.6M-17 skeleton), their
// files, readers for COCO keypoint JSON and OpenPose JSON, and the mappings
// between skeletons. docs/annotations.md has the conventions in prose.
//
// Own files (layout.h: poses2d/<view>/<frame>.json, poses3d/<frame>.json and
// gt/joints3d/<frame>.json):
//   {"format": "u4d-poses2d", "skeleton": "coco17",
//    "people": [{"id": 3, "score": 0.9, "keypoints": [[x, y, c], ... 17]}]}
//   {"format": "u4d-poses3d", "skeleton": "h36m17", "units": "metres",
//    "people": [{"id": 1, "joints": [[x, y, z, c], ... 17]}]}
// Pixels follow docs/conventions.md (origin at the centre of the top-left
// pixel). A confidence of 0 means "missing"; the coordinates of a missing
// point carry no meaning. Confidences are in [0, 1].
//
// Every reader throws u4d::Error naming the file and the problem on a missing
// file, malformed JSON, a wrong "format" / "skeleton", a wrong number of
// keypoints or values, a non-finite number or a confidence outside [0, 1].
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "u4d/io/coco.h"
#include "u4d/util/file.h"

namespace u4d {

// COCO-17 keypoint order (as in COCO's person category).
namespace coco17 {
enum Keypoint : int {
  kNose = 0,
  kLeftEye,
  kRightEye,
  kLeftEar,
  kRightEar,
  kLeftShoulder,
  kRightShoulder,
  kLeftElbow,
  kRightElbow,
  kLeftWrist,
  kRightWrist,
  kLeftHip,
  kRightHip,
  kLeftKnee,
  kRightKnee,
  kLeftAnkle,
  kRightAnkle,
  kNumKeypoints
};
}  // namespace coco17

// The internal skeleton: the paper's 17 joints in Human3.6M order. This is
// the one definition; synth (scene.h) and later modules use it.
namespace h36m17 {
enum Joint : int {
  kPelvis = 0,
  kRightHip,
  kRightKnee,
  kRightAnkle,
  kLeftHip,
  kLeftKnee,
  kLeftAnkle,
  kSpine,
  kThorax,
  kNeck,
  kHead,
  kLeftShoulder,
  kLeftElbow,
  kLeftWrist,
  kRightShoulder,
  kRightElbow,
  kRightWrist,
  kNumJoints
};
}  // namespace h36m17

// Names, for messages and documentation ("nose", "left_eye", ... / "pelvis",
// "right_hip", ...).
const std::array<std::string, 17>& Coco17Names();

// The COCO-17 index of the mirror keypoint (left <-> right; the nose maps to
// itself). Throws when `keypoint` is not in [0, 17).
int Coco17Mirror(int keypoint);
const std::array<std::string, 17>& H36m17Names();
// The 16 bones of the H36M-17 skeleton as (parent, child) joint indices.
const std::vector<std::pair<int, int>>& H36m17Bones();

using Keypoints2d = std::array<Eigen::Vector3d, 17>;   // x, y (pixels), confidence
using Joints3dConf = std::array<Eigen::Vector4d, 17>;  // x, y, z (metres), confidence

struct Pose2d {
  int person_id = -1;     // -1 if unknown
  Keypoints2d keypoints;  // COCO-17 order; all zero (missing) by default
  double score = 0;       // detection score in [0, 1]

  Pose2d() { keypoints.fill(Eigen::Vector3d::Zero()); }
};

struct Pose3d {
  int person_id = -1;   // -1 if unknown
  Joints3dConf joints;  // Human3.6M-17 order, metres; all zero (missing) by default

  Pose3d() { joints.fill(Eigen::Vector4d::Zero()); }
};

// ---- Readers of other tools' files ----

// COCO keypoint annotations (dataset or results) of one image, in the order
// and with the numbering of SelectCocoAnnotations (coco.h): person_id is the
// instance id the same annotation gets in CocoInstanceMask. Annotations
// without 51 keypoint values or with no labelled keypoint are left out.
// Coordinates are taken as they are (COCO stores integer pixel indices for
// keypoints, i.e. pixel centres; unlike polygon vertices they are not
// shifted). Confidence: v = 0 -> 0 (missing); otherwise the annotation's
// "score" if it has one (results files), else 1 for v in {1, 2} (labelled,
// occluded or visible) and v itself for 0 < v < 1 (results files that store a
// per-keypoint confidence). Pose score: the annotation's "score", else 1.
std::vector<Pose2d> CocoKeypointPoses(const CocoFile& coco, const CocoImage& image,
                                      const CocoMaskOptions& options = {});
// Convenience: reads `path` and picks the image by file name.
std::vector<Pose2d> ReadCocoKeypoints(const fs::path& path, const std::string& image_file_name);

// OpenPose JSON ({"people": [{"pose_keypoints_2d": [x, y, c, ...]}]}), one
// image. The layout follows from the length: 75 values = BODY_25, 54 =
// COCO-18; mapped to COCO-17 by Coco17FromBody25 / Coco17FromOpenPoseCoco18.
// person_id: the "person_id" field (a number or a one-element array) when it
// is >= 0, else -1. Score: mean confidence of the keypoints present (0 if
// none). A person with an empty keypoint array is skipped.
std::vector<Pose2d> ReadOpenPoseJson(const fs::path& path);

// Index maps: entry k is the source index of COCO-17 keypoint k.
//  BODY_25 (0 nose, 1 neck, 2-4 right shoulder/elbow/wrist, 5-7 left, 8 mid
//  hip, 9-11 right hip/knee/ankle, 12-14 left, 15/16 right/left eye, 17/18
//  right/left ear, 19-24 feet): {0, 16, 15, 18, 17, 5, 2, 6, 3, 7, 4, 12, 9,
//  13, 10, 14, 11}.
//  COCO-18 (as BODY_25 up to 7, then 8-10 right hip/knee/ankle, 11-13 left,
//  14/15 right/left eye, 16/17 right/left ear): {0, 15, 14, 17, 16, 5, 2, 6,
//  3, 7, 4, 11, 8, 12, 9, 13, 10}.
// Neck, mid hip and the feet have no COCO-17 counterpart and are dropped.
const std::array<int, 17>& Coco17FromBody25();
const std::array<int, 17>& Coco17FromOpenPoseCoco18();

// ---- Own files ----

std::vector<Pose2d> ReadPoses2d(const fs::path& path);
void WritePoses2d(const fs::path& path, const std::vector<Pose2d>& people);
std::vector<Pose3d> ReadPoses3d(const fs::path& path);
void WritePoses3d(const fs::path& path, const std::vector<Pose3d>& people);

// ---- Skeleton mappings (2D: Vector3d = x, y, c; 3D: Vector4d = x, y, z, c) ----
//
// H36m17FromCoco17. Joints present in both (shoulders, elbows, wrists, hips,
// knees, ankles) are copied. The others are built from COCO points:
//   pelvis = mid-point of the hips
//   thorax = mid-point of the shoulders
//   spine  = mid-point of pelvis and thorax
//   head   = the head CENTRE: mid-point of the ears if both are present, else
//            of the eyes if both are present, else the nose
//   neck   = mid-point of thorax and head
// A built joint's confidence is the minimum of the confidences it was built
// from, so it is 0 (missing) as soon as one input is missing.
// Coco17FromH36m17 copies the shared joints; nose, eyes and ears do not exist
// in H36M-17 and come out missing (confidence 0, placed at the head joint).
std::array<Eigen::Vector3d, 17> H36m17FromCoco17(const std::array<Eigen::Vector3d, 17>& coco);
std::array<Eigen::Vector4d, 17> H36m17FromCoco17(const std::array<Eigen::Vector4d, 17>& coco);
std::array<Eigen::Vector3d, 17> Coco17FromH36m17(const std::array<Eigen::Vector3d, 17>& h36m);
std::array<Eigen::Vector4d, 17> Coco17FromH36m17(const std::array<Eigen::Vector4d, 17>& h36m);

// The Shelf / Campus 15-joint ground truth (4D Association's gt.txt, see
// import_fourda.h: 0 right ankle, 1 right knee, 2 right hip, 3 left hip,
// 4 left knee, 5 left ankle, 6 right wrist, 7 right elbow, 8 right shoulder,
// 9 left shoulder, 10 left elbow, 11 left wrist, 12 neck (bottom of the
// head), 13 head top, 14 pelvis) -> H36M-17: limbs and pelvis copied,
// thorax = mid-shoulders, spine = mid(pelvis, thorax), neck = Shelf neck,
// head = mid(neck, head top) (the head centre, as above). `joints` is 4 x 15
// (x, y, z, confidence), as ReadFourdaGroundTruth returns it; throws on
// another size.
Pose3d H36m17FromShelf15(const Eigen::Matrix4Xd& joints, int person_id);

}  // namespace u4d
