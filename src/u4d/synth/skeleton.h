// The internal 17-joint skeleton (Human3.6M order, synth/scene.h `Joint`), a
// body pose that fixes every segment's orientation (so a mesh can be attached
// without twist ambiguity), retargeting of CMU BVH motion capture onto it, and
// the COCO-17 keypoints a 2D detector would report.
//
// Rest pose: standing on the floor y = 0, facing +z, y up, the person's left at
// +x (right-handed, metres), arms hanging with a slight abduction. Every joint
// owns the rigid segment that starts at it (the thigh belongs to the hip, the
// hand to the wrist, the head to the neck and the head joint). A pose stores,
// per joint, `rotation[j]` = world_from_rest rotation of that segment and the
// joint's world position; a rest-pose point x bound to joint j is at
// position[j] + rotation[j] * (x - rest[j]) in the world. Positions obey
// forward kinematics: position[c] = position[p] + rotation[p] * (rest[c] -
// rest[p]) for every child c of p, so bone lengths never change.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "u4d/geometry/rigid3.h"
#include "u4d/synth/bvh.h"
#include "u4d/synth/scene.h"

namespace u4d::synth {

using JointRotations = std::array<Eigen::Matrix3d, kNumJoints>;
using CocoKeypoints3d = std::array<Eigen::Vector3d, 17>;

// Parent of each joint (-1 for the pelvis), H36M tree.
int JointParent(int joint);
// "pelvis", "right_hip", ... (snake case of the enum names).
const char* JointName(int joint);
// The 16 bones as (parent, child) pairs.
std::vector<std::pair<int, int>> SkeletonBones();

// A person's proportions and rest pose.
struct BodyShape {
  double height = 1.75;  // stature, metres: floor to the top of the head (head joint)
  double width = 1.0;    // lateral scale of shoulders, hips and limb girth
  Joints3d rest{};       // rest-pose joint positions (see the file comment)
  // End points of the segments without a child joint, rest pose.
  std::array<Eigen::Vector3d, 2> rest_toe;   // [0] right, [1] left: tip of the foot, on the floor
  std::array<Eigen::Vector3d, 2> rest_heel;  // back of the foot, on the floor
  std::array<Eigen::Vector3d, 2> rest_hand_tip;  // fingertips
  Eigen::Vector3d rest_head_centre;              // centre of the head ellipsoid
  Eigen::Vector3d head_radii;                    // its half axes (x, y, z)
};

// Proportions of an average adult scaled to `height`; `width` scales lateral
// sizes. Throws u4d::Error unless 1.0 <= height <= 2.3 and 0.6 <= width <= 1.6.
BodyShape MakeBodyShape(double height, double width = 1.0);

struct BodyPose {
  JointRotations rotation;  // world_from_rest rotation of each joint's segment
  Joints3d position;        // world positions, metres
};

// The rest pose (identity rotations, rest positions).
BodyPose RestPose(const BodyShape& shape);
// world_from_rest of joint j's segment: x -> position[j] + rotation[j] (x - rest[j]).
Rigid3d SegmentTransform(const BodyShape& shape, const BodyPose& pose, int joint);
// Fills pose->position from `pelvis` and pose->rotation by forward kinematics.
void ForwardKinematics(const BodyShape& shape, const Eigen::Vector3d& pelvis, BodyPose* pose);
// World rotations from rotations relative to the parent segment
// (local[j] = rotation[parent]^T rotation[j]; local[pelvis] is the world one),
// then forward kinematics from `pelvis`.
BodyPose PoseFromLocal(const BodyShape& shape, const Eigen::Vector3d& pelvis,
                       const JointRotations& local);
// Applies a rigid world motion to a whole pose.
BodyPose TransformPose(const BodyPose& pose, const Rigid3d& new_from_old);
// Height of the lowest of the heel and toe contact points of both feet.
double LowestFootHeight(const BodyShape& shape, const BodyPose& pose);
// Shifts the pose vertically so LowestFootHeight is 0.
void PutOnFloor(const BodyShape& shape, BodyPose* pose);

// COCO-17 keypoints (nose, left/right eye, left/right ear, then shoulders,
// elbows, wrists, hips, knees, ankles, left before right): face points are
// fixed on the head segment, the rest are the skeleton joints.
CocoKeypoints3d CocoKeypointsFromPose(const BodyShape& shape, const BodyPose& pose);

// Motion capture retargeted onto a BodyShape, sampled at a fixed rate.
struct MocapClip {
  std::string name;  // source file
  BodyShape shape;
  double fps = 30;
  std::vector<BodyPose> poses;  // poses[i] at time i / fps; clip coordinates
  double Duration() const { return poses.empty() ? 0 : (poses.size() - 1) / fps; }
};

struct RetargetOptions {
  double fps = 30;                // output rate (the source is resampled, rotations slerped)
  bool ground_each_frame = true;  // shift each frame so the lowest foot point is on y = 0
  void Check() const;
};

// Retargets a CMU-style BVH (joints Hips, LeftHip/RightHip, LeftKnee,
// LeftAnkle, LeftToe, Chest, Chest2, Head, LeftShoulder, LeftElbow,
// LeftWrist, LFingers and the Right* ones; y up, metres, facing +z) onto
// `shape`: segment orientations follow the BVH segments (a constant
// correction aligns the rest bone directions), bone lengths are the shape's,
// and the root trajectory is scaled by the ratio of leg lengths. Throws
// u4d::Error naming the file if a required joint is missing.
MocapClip RetargetBvh(const BvhMotion& motion, const BodyShape& shape,
                      const RetargetOptions& options = {});

// Pose at `time` seconds (clamped to the clip), interpolating neighbouring
// samples (slerp of rotations, forward kinematics from the lerped pelvis).
BodyPose SampleClip(const MocapClip& clip, double time);

// Smallest rotation taking direction `from` to direction `to`.
Eigen::Matrix3d RotationBetween(const Eigen::Vector3d& from, const Eigen::Vector3d& to);

}  // namespace u4d::synth
