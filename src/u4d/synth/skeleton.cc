#include "u4d/synth/skeleton.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

constexpr int kParents[kNumJoints] = {-1, 0, 1, 2, 0, 4, 5, 0, 7, 8, 9, 8, 11, 12, 8, 14, 15};
constexpr const char* kNames[kNumJoints] = {
    "pelvis",     "right_hip",  "right_knee",     "right_ankle", "left_hip",   "left_knee",
    "left_ankle", "spine",      "thorax",         "neck",        "head",       "left_shoulder",
    "left_elbow", "left_wrist", "right_shoulder", "right_elbow", "right_wrist"};

}  // namespace

int JointParent(int joint) {
  U4D_ASSERT(joint >= 0 && joint < kNumJoints);
  return kParents[joint];
}

const char* JointName(int joint) {
  U4D_ASSERT(joint >= 0 && joint < kNumJoints);
  return kNames[joint];
}

std::vector<std::pair<int, int>> SkeletonBones() {
  std::vector<std::pair<int, int>> bones;
  for (int j = 1; j < kNumJoints; ++j) bones.emplace_back(kParents[j], j);
  return bones;
}

BodyShape MakeBodyShape(double height, double width) {
  U4D_CHECK(std::isfinite(height) && height >= 1.0 && height <= 2.3,
            "MakeBodyShape: height {} m outside 1.0..2.3", height);
  U4D_CHECK(std::isfinite(width) && width >= 0.6 && width <= 1.6,
            "MakeBodyShape: width {} outside 0.6..1.6", width);
  BodyShape shape;
  shape.height = height;
  shape.width = width;
  const double s = height / 1.75;
  const double w = s * width;
  auto p = [&](double x, double y, double z) { return Eigen::Vector3d(x * w, y * s, z * s); };
  Joints3d& r = shape.rest;
  r[kPelvis] = p(0, 0.95, 0);
  r[kRightHip] = p(-0.09, 0.88, 0);
  r[kRightKnee] = p(-0.09, 0.50, 0.005);
  r[kRightAnkle] = p(-0.09, 0.08, -0.005);
  r[kSpine] = p(0, 1.17, -0.005);
  r[kThorax] = p(0, 1.42, 0);
  r[kNeck] = p(0, 1.545, 0.005);
  r[kHead] = p(0, 1.75, 0);
  r[kRightShoulder] = p(-0.175, 1.42, 0);
  r[kRightElbow] = p(-0.205, 1.13, -0.01);
  r[kRightWrist] = p(-0.23, 0.875, 0.0);
  for (int j : {kRightHip, kRightKnee, kRightAnkle, kRightShoulder, kRightElbow, kRightWrist}) {
    const int left = j == kRightHip        ? kLeftHip
                     : j == kRightKnee     ? kLeftKnee
                     : j == kRightAnkle    ? kLeftAnkle
                     : j == kRightShoulder ? kLeftShoulder
                     : j == kRightElbow    ? kLeftElbow
                                           : kLeftWrist;
    r[left] = r[j];
    r[left].x() = -r[j].x();
  }
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? -1 : 1;
    shape.rest_toe[side] = p(sign * 0.095, 0, 0.17);
    shape.rest_heel[side] = p(sign * 0.09, 0, -0.06);
    shape.rest_hand_tip[side] = p(sign * 0.24, 0.69, 0.01);
  }
  shape.rest_head_centre = p(0, 1.645, 0.012);
  shape.head_radii = Eigen::Vector3d(0.078 * w, 0.112 * s, 0.098 * s);
  return shape;
}

BodyPose RestPose(const BodyShape& shape) {
  BodyPose pose;
  pose.rotation.fill(Eigen::Matrix3d::Identity());
  pose.position = shape.rest;
  return pose;
}

Rigid3d SegmentTransform(const BodyShape& shape, const BodyPose& pose, int joint) {
  Rigid3d t;
  t.rotation = pose.rotation[joint];
  t.translation = pose.position[joint] - pose.rotation[joint] * shape.rest[joint];
  return t;
}

void ForwardKinematics(const BodyShape& shape, const Eigen::Vector3d& pelvis, BodyPose* pose) {
  pose->position[kPelvis] = pelvis;
  for (int j = 1; j < kNumJoints; ++j) {
    const int p = kParents[j];
    pose->position[j] = pose->position[p] + pose->rotation[p] * (shape.rest[j] - shape.rest[p]);
  }
}

BodyPose PoseFromLocal(const BodyShape& shape, const Eigen::Vector3d& pelvis,
                       const JointRotations& local) {
  BodyPose pose;
  pose.rotation[kPelvis] = local[kPelvis];
  for (int j = 1; j < kNumJoints; ++j) pose.rotation[j] = pose.rotation[kParents[j]] * local[j];
  ForwardKinematics(shape, pelvis, &pose);
  return pose;
}

BodyPose TransformPose(const BodyPose& pose, const Rigid3d& new_from_old) {
  BodyPose out;
  for (int j = 0; j < kNumJoints; ++j) {
    out.rotation[j] = new_from_old.rotation * pose.rotation[j];
    out.position[j] = new_from_old * pose.position[j];
  }
  return out;
}

double LowestFootHeight(const BodyShape& shape, const BodyPose& pose) {
  double lowest = std::numeric_limits<double>::infinity();
  for (int side = 0; side < 2; ++side) {
    const Rigid3d t = SegmentTransform(shape, pose, side == 0 ? kRightAnkle : kLeftAnkle);
    lowest = std::min({lowest, (t * shape.rest_toe[side]).y(), (t * shape.rest_heel[side]).y()});
  }
  return lowest;
}

void PutOnFloor(const BodyShape& shape, BodyPose* pose) {
  const double dy = LowestFootHeight(shape, *pose);
  for (auto& p : pose->position) p.y() -= dy;
}

CocoKeypoints3d CocoKeypointsFromPose(const BodyShape& shape, const BodyPose& pose) {
  const Rigid3d head = SegmentTransform(shape, pose, kNeck);
  const Eigen::Vector3d& c = shape.rest_head_centre;
  const Eigen::Vector3d& r = shape.head_radii;
  CocoKeypoints3d k;
  k[0] = head * (c + Eigen::Vector3d(0, -0.12 * r.y(), 1.08 * r.z()));            // nose
  k[1] = head * (c + Eigen::Vector3d(0.42 * r.x(), 0.2 * r.y(), 0.85 * r.z()));   // left eye
  k[2] = head * (c + Eigen::Vector3d(-0.42 * r.x(), 0.2 * r.y(), 0.85 * r.z()));  // right eye
  k[3] = head * (c + Eigen::Vector3d(1.0 * r.x(), 0.0, -0.05 * r.z()));           // left ear
  k[4] = head * (c + Eigen::Vector3d(-1.0 * r.x(), 0.0, -0.05 * r.z()));          // right ear
  const int body[12] = {kLeftShoulder, kRightShoulder, kLeftElbow, kRightElbow,
                        kLeftWrist,    kRightWrist,    kLeftHip,   kRightHip,
                        kLeftKnee,     kRightKnee,     kLeftAnkle, kRightAnkle};
  for (int i = 0; i < 12; ++i) k[5 + i] = pose.position[body[i]];
  return k;
}

Eigen::Matrix3d RotationBetween(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  return Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
}

void RetargetOptions::Check() const {
  U4D_CHECK(std::isfinite(fps) && fps > 0 && fps <= 1000,
            "RetargetOptions: fps {} outside (0, 1000]", fps);
}

namespace {

struct JointMap {
  int joint;              // ours
  const char* bvh;        // the BVH joint whose world rotation drives the segment
  const char* bvh_child;  // its child giving the bone direction; nullptr: no correction
};

constexpr JointMap kCmuMap[kNumJoints] = {
    {kPelvis, "Hips", nullptr},
    {kRightHip, "RightHip", "RightKnee"},
    {kRightKnee, "RightKnee", "RightAnkle"},
    {kRightAnkle, "RightAnkle", "RightToe"},
    {kLeftHip, "LeftHip", "LeftKnee"},
    {kLeftKnee, "LeftKnee", "LeftAnkle"},
    {kLeftAnkle, "LeftAnkle", "LeftToe"},
    {kSpine, "Chest", "Chest2"},
    {kThorax, "Chest2", nullptr},
    {kNeck, "Head", "Head_End"},
    {kHead, "Head", "Head_End"},
    {kLeftShoulder, "LeftShoulder", "LeftElbow"},
    {kLeftElbow, "LeftElbow", "LeftWrist"},
    {kLeftWrist, "LeftWrist", "LFingers"},
    {kRightShoulder, "RightShoulder", "RightElbow"},
    {kRightElbow, "RightElbow", "RightWrist"},
    {kRightWrist, "RightWrist", "RFingers"},
};

// Our rest direction of joint j's segment (to its child or end point).
Eigen::Vector3d RestSegmentDirection(const BodyShape& s, int j) {
  switch (j) {
    case kRightAnkle:
      return s.rest_toe[0] - s.rest[j];
    case kLeftAnkle:
      return s.rest_toe[1] - s.rest[j];
    case kRightWrist:
      return s.rest_hand_tip[0] - s.rest[j];
    case kLeftWrist:
      return s.rest_hand_tip[1] - s.rest[j];
    case kNeck:
    case kHead:
      return s.rest[kHead] - s.rest[kNeck];
    default:
      for (int c = 1; c < kNumJoints; ++c) {
        if (kParents[c] == j) return s.rest[c] - s.rest[j];
      }
  }
  U4D_ASSERT(false);
  return {};
}

}  // namespace

MocapClip RetargetBvh(const BvhMotion& motion, const BodyShape& shape,
                      const RetargetOptions& options) {
  options.Check();
  int bvh_index[kNumJoints];
  Eigen::Matrix3d correction[kNumJoints];
  const std::vector<Rigid3d> rest = BvhRestPose(motion);
  auto find = [&](const char* name) {
    const int i = FindBvhJoint(motion, name);
    U4D_CHECK(i >= 0, "{}: retargeting needs a BVH joint named '{}' (CMU naming)", motion.source,
              name);
    return i;
  };
  for (const JointMap& m : kCmuMap) {
    bvh_index[m.joint] = find(m.bvh);
    // Our segment at the BVH rest pose: the BVH rest bone direction; then it
    // follows the BVH joint: R(t) = W(t) W_rest^T R_align.
    Eigen::Matrix3d align = Eigen::Matrix3d::Identity();
    if (m.bvh_child != nullptr) {
      const int child = find(m.bvh_child);
      const Eigen::Vector3d bvh_dir =
          rest[child].translation - rest[bvh_index[m.joint]].translation;
      U4D_CHECK(bvh_dir.norm() > 1e-6, "{}: joint '{}' has a zero-length bone to '{}'",
                motion.source, m.bvh, m.bvh_child);
      align = RotationBetween(RestSegmentDirection(shape, m.joint), bvh_dir);
    }
    correction[m.joint] = rest[bvh_index[m.joint]].rotation.transpose() * align;
  }
  // Leg length ratio scales the root trajectory.
  const int bvh_hips = bvh_index[kPelvis];
  const int bvh_ankle = bvh_index[kLeftAnkle];
  const double bvh_leg = rest[bvh_hips].translation.y() - rest[bvh_ankle].translation.y();
  const double our_leg = shape.rest[kPelvis].y() - shape.rest[kLeftAnkle].y();
  U4D_CHECK(bvh_leg > 1e-3, "{}: the rest pose has the ankles above the hips", motion.source);
  const double scale = our_leg / bvh_leg;

  // Retarget every source frame, then resample.
  std::vector<std::array<Eigen::Quaterniond, kNumJoints>> src_rot(motion.num_frames);
  std::vector<Eigen::Vector3d> src_pelvis(motion.num_frames);
  for (int f = 0; f < motion.num_frames; ++f) {
    const std::vector<Rigid3d> world = BvhForwardKinematics(motion, f);
    for (int j = 0; j < kNumJoints; ++j) {
      src_rot[f][j] = Eigen::Quaterniond(world[bvh_index[j]].rotation * correction[j]).normalized();
      if (f > 0 && src_rot[f][j].dot(src_rot[f - 1][j]) < 0) src_rot[f][j].coeffs() *= -1;
    }
    src_pelvis[f] = scale * world[bvh_hips].translation;
  }
  MocapClip clip;
  clip.name = motion.source;
  clip.shape = shape;
  clip.fps = options.fps;
  const double duration = (motion.num_frames - 1) * motion.frame_time;
  const int n = static_cast<int>(std::floor(duration * options.fps + 1e-9)) + 1;
  clip.poses.resize(n);
  for (int i = 0; i < n; ++i) {
    const double x = std::min(i / options.fps / motion.frame_time, motion.num_frames - 1.0);
    const int f0 = static_cast<int>(std::floor(x));
    const int f1 = std::min(f0 + 1, motion.num_frames - 1);
    const double a = x - f0;
    BodyPose& pose = clip.poses[i];
    for (int j = 0; j < kNumJoints; ++j) {
      pose.rotation[j] = src_rot[f0][j].slerp(a, src_rot[f1][j]).toRotationMatrix();
    }
    ForwardKinematics(shape, (1 - a) * src_pelvis[f0] + a * src_pelvis[f1], &pose);
    if (options.ground_each_frame) PutOnFloor(shape, &pose);
  }
  return clip;
}

BodyPose SampleClip(const MocapClip& clip, double time) {
  U4D_CHECK(!clip.poses.empty(), "SampleClip: clip '{}' has no poses", clip.name);
  const double x = std::clamp(time * clip.fps, 0.0, clip.poses.size() - 1.0);
  const int f0 = static_cast<int>(std::floor(x));
  const int f1 = std::min<int>(f0 + 1, clip.poses.size() - 1);
  const double a = x - f0;
  if (a < 1e-9) return clip.poses[f0];
  BodyPose pose;
  for (int j = 0; j < kNumJoints; ++j) {
    const Eigen::Quaterniond q0(clip.poses[f0].rotation[j]);
    Eigen::Quaterniond q1(clip.poses[f1].rotation[j]);
    pose.rotation[j] = q0.slerp(a, q1).toRotationMatrix();
  }
  ForwardKinematics(
      clip.shape, (1 - a) * clip.poses[f0].position[kPelvis] + a * clip.poses[f1].position[kPelvis],
      &pose);
  return pose;
}

}  // namespace u4d::synth
