// Procedural and mocap-driven motion of one person: a timeline of phases
// (stand, walk, handshake, mocap) evaluated to a BodyPose at any time.
//
// Floor positions are (x, z) of the pelvis on the floor y = 0; a heading h is
// the yaw about +y, the person facing (sin h, 0, cos h) (h = 0 faces +z).
// Procedural poses are put on the floor (the lowest heel/toe point at y = 0).
// Everything is deterministic: randomness is drawn once, when the gait
// parameters are made from a seed.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "u4d/geometry/rigid3.h"
#include "u4d/synth/skeleton.h"

namespace u4d::synth {

// Per-person style of the procedural motion.
struct GaitParams {
  double speed = 1.2;        // nominal walking speed, m/s (plans use it for durations)
  double stride = 1.35;      // metres per full gait cycle (two steps)
  double hip_swing = 0.42;   // hip flexion amplitude while walking, radians
  double knee_lift = 0.95;   // extra knee flexion in swing, radians
  double arm_swing = 0.28;   // shoulder flexion amplitude while walking, radians
  double elbow_bend = 0.22;  // resting elbow flexion, radians
  double lean = 0.04;        // forward trunk lean, radians
  double sway = 0.012;       // idle sway amplitude, metres
  double phase = 0;          // gait and sway phase offset, radians
  double sway_hz = 0.23;     // idle sway frequency
  void Check() const;
};

// Gait parameters with person-to-person variation drawn from `seed`,
// proportional to the body height.
GaitParams MakeGaitParams(double height, uint64_t seed);

struct MotionPhase {
  enum class Kind : uint8_t {
    kStand,      // stay at `from_xz`, turning from from_heading to to_heading in the first second
    kWalk,       // walk from from_xz to to_xz (smooth start and stop), facing the way (headings)
    kHandshake,  // stand like kStand and bring the right wrist to `hand_target` (see below)
    kMocap       // play clip `clip` from `clip_time`, placed by world_from_clip
  };
  Kind kind = Kind::kStand;
  double start = 0;  // seconds; phases of a person are sorted and contiguous
  double end = 0;
  Eigen::Vector2d from_xz = Eigen::Vector2d::Zero();
  Eigen::Vector2d to_xz = Eigen::Vector2d::Zero();
  double from_heading = 0;
  double to_heading = 0;
  // kHandshake: the wrist reaches from its resting place to hand_target during
  // [start, shake_start], pumps up and down (shake_amplitude, shake_hz, the
  // same function of time for both partners) during [shake_start, shake_end]
  // and returns to rest during [shake_end, end].
  Eigen::Vector3d hand_target = Eigen::Vector3d::Zero();
  double shake_start = 0;
  double shake_end = 0;
  double shake_amplitude = 0.035;  // metres
  double shake_hz = 2.2;
  // kMocap
  int clip = -1;            // index into the clips passed to EvaluateMotion
  double clip_time = 0;     // clip time at `start`; the clip holds its end pose after its end
  Rigid3d world_from_clip;  // rigid placement (a yaw and a floor offset)
};

struct PersonMotion {
  GaitParams gait;
  std::vector<MotionPhase> phases;  // non-empty; before the first / after the last, they clamp
};

// Checks the timeline (sorted, contiguous, finite, valid clip indices).
void CheckMotion(const PersonMotion& motion, int num_clips);

// The pose at `time`. `shape` must be the shape the clips were retargeted to.
BodyPose EvaluateMotion(const PersonMotion& motion, const BodyShape& shape,
                        const std::vector<MocapClip>& clips, double time);

// The pelvis floor position and heading at `time` (no pose), for planning.
Eigen::Vector2d FloorPosition(const PersonMotion& motion, const std::vector<MocapClip>& clips,
                              const BodyShape& shape, double time);

// Duration a walk over `distance` takes at the gait's speed, ramps included.
double WalkDuration(const GaitParams& gait, double distance);

// Heading facing from `from` towards `to` on the floor.
double HeadingTowards(const Eigen::Vector2d& from, const Eigen::Vector2d& to);

// Two-bone IK for the right or left arm: rotates the shoulder and elbow
// segments (the hand follows the forearm) so the wrist reaches `target`, or
// points at it when out of reach; the elbow bends towards `pole`
// (a world direction). Positions are recomputed.
void SolveArmIk(const BodyShape& shape, bool right, const Eigen::Vector3d& target,
                const Eigen::Vector3d& pole, BodyPose* pose);

}  // namespace u4d::synth
