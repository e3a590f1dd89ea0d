#include "u4d/synth/motion.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

constexpr double kRamp = 0.6;      // seconds to accelerate / stop when walking
constexpr double kTurnTime = 1.0;  // seconds to turn in place
constexpr double kHeadingTurnWalk = 0.5;

Eigen::Matrix3d Rx(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
Eigen::Matrix3d Ry(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
Eigen::Matrix3d Rz(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}
// Swings a hanging segment forward (+z) by `a` radians.
Eigen::Matrix3d Flex(double a) { return Rx(-a); }

double SmoothStep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

double WrapAngle(double a) { return std::remainder(a, 2 * M_PI); }

double TurnHeading(const MotionPhase& p, double tau, double turn_time) {
  const double dh = WrapAngle(p.to_heading - p.from_heading);
  return p.from_heading + dh * SmoothStep(0, std::max(1e-6, turn_time), tau);
}

// Trapezoidal speed profile over a walk of length `length` and duration `d`.
struct WalkState {
  double distance = 0;
  double speed = 0;
};
WalkState WalkProgress(double length, double d, double tau) {
  tau = std::clamp(tau, 0.0, d);
  const double r = std::min(kRamp, d / 3);
  const double v = length / std::max(1e-9, d - r);
  WalkState s;
  if (tau < r) {
    s.distance = 0.5 * v * tau * tau / r;
    s.speed = v * tau / r;
  } else if (tau <= d - r) {
    s.distance = 0.5 * v * r + v * (tau - r);
    s.speed = v;
  } else {
    const double rem = d - tau;
    s.distance = length - 0.5 * v * rem * rem / r;
    s.speed = v * rem / r;
  }
  return s;
}

const MotionPhase& PhaseAt(const PersonMotion& motion, double time) {
  for (const MotionPhase& p : motion.phases) {
    if (time < p.end) return p;
  }
  return motion.phases.back();
}

// Procedural pose: standing (amplitude 0) to full walking (amplitude 1) at gait
// phase `phi`, with idle sway weighted by `sway`.
BodyPose GaitPose(const BodyShape& shape, const GaitParams& g, const Eigen::Vector2d& xz,
                  double heading, double phi, double amp, double sway_weight, double time) {
  JointRotations local;
  local.fill(Eigen::Matrix3d::Identity());
  const double s = std::sin(phi);
  const double sway_t = 2 * M_PI * g.sway_hz * time + g.phase;
  const double sway_roll = sway_weight * 0.025 * std::sin(sway_t);
  const double sway_yaw = sway_weight * 0.04 * std::sin(0.7 * sway_t + 1.0);
  local[kPelvis] =
      Ry(heading + amp * 0.07 * s + sway_yaw) * Rz(sway_roll + amp * 0.03 * std::cos(phi));
  local[kSpine] = Ry(-amp * 0.10 * s - 0.5 * sway_yaw) * Rx(g.lean * (0.5 + amp));
  local[kThorax] = Ry(-amp * 0.06 * s) * Rz(-0.6 * sway_roll) * Rx(0.01 * std::sin(2.1 * sway_t));
  local[kNeck] = Ry(amp * 0.12 * s + 0.15 * sway_weight * std::sin(0.4 * sway_t + 2.0)) *
                 Rx(-g.lean * (0.5 + amp));
  local[kHead] = Eigen::Matrix3d::Identity();
  for (int side = 0; side < 2; ++side) {
    const double ph = side == 0 ? phi : phi + M_PI;  // right, left
    const double hip = amp * g.hip_swing * std::sin(ph);
    const double c = std::max(0.0, std::cos(ph - 0.3));
    const double knee = 0.06 + amp * (0.08 + g.knee_lift * c * c);
    const double sign = side == 0 ? -1 : 1;  // lateral direction of this side
    local[side == 0 ? kRightHip : kLeftHip] = Flex(hip) * Rz(sign * 0.02 * (1 - amp));
    local[side == 0 ? kRightKnee : kLeftKnee] = Flex(-knee);
    local[side == 0 ? kRightAnkle : kLeftAnkle] = Flex(-(hip - knee) * 0.9);
    const double arm =
        -amp * g.arm_swing * std::sin(ph) + sway_weight * 0.03 * std::sin(sway_t + side);
    local[side == 0 ? kRightShoulder : kLeftShoulder] = Flex(arm + 0.05) * Rz(sign * 0.04);
    local[side == 0 ? kRightElbow : kLeftElbow] =
        Flex(g.elbow_bend + amp * 0.25 * std::max(0.0, -std::sin(ph)));
    local[side == 0 ? kRightWrist : kLeftWrist] = Flex(0.05);
  }
  BodyPose pose =
      PoseFromLocal(shape, Eigen::Vector3d(xz.x(), shape.rest[kPelvis].y(), xz.y()), local);
  PutOnFloor(shape, &pose);
  // Idle weight shift: the pelvis drifts sideways a little.
  const Eigen::Vector3d side_dir(std::cos(heading), 0, -std::sin(heading));
  const Eigen::Vector3d drift = side_dir * (sway_weight * g.sway * std::sin(sway_t));
  for (auto& p : pose.position) p += drift;
  return pose;
}

Eigen::Matrix3d FrameFrom(const Eigen::Vector3d& a, const Eigen::Vector3d& ref) {
  const Eigen::Vector3d x = a.normalized();
  Eigen::Vector3d y = ref - ref.dot(x) * x;
  if (y.norm() < 1e-9) y = x.unitOrthogonal();
  y.normalize();
  Eigen::Matrix3d m;
  m << x, y, x.cross(y);
  return m;
}

}  // namespace

void GaitParams::Check() const {
  U4D_CHECK(std::isfinite(speed) && speed > 0.1 && speed < 3, "GaitParams: speed {} m/s", speed);
  U4D_CHECK(std::isfinite(stride) && stride > 0.3 && stride < 3, "GaitParams: stride {} m", stride);
  U4D_CHECK(
      std::isfinite(hip_swing + knee_lift + arm_swing + elbow_bend + lean + sway + phase + sway_hz),
      "GaitParams: non-finite parameter");
}

GaitParams MakeGaitParams(double height, uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  std::uniform_real_distribution<double> u(-1, 1);
  GaitParams g;
  g.speed = 1.15 + 0.15 * u(rng);
  g.stride = height * (0.78 + 0.04 * u(rng));
  g.hip_swing = 0.42 + 0.04 * u(rng);
  g.knee_lift = 0.95 + 0.1 * u(rng);
  g.arm_swing = 0.28 + 0.08 * u(rng);
  g.elbow_bend = 0.22 + 0.1 * u(rng);
  g.lean = 0.04 + 0.02 * u(rng);
  g.sway = 0.012 + 0.005 * u(rng);
  g.phase = M_PI * (1 + u(rng));
  g.sway_hz = 0.23 + 0.05 * u(rng);
  return g;
}

double WalkDuration(const GaitParams& gait, double distance) {
  const double cruise = distance / gait.speed;
  return cruise + std::min(kRamp, cruise);
}

double HeadingTowards(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  const Eigen::Vector2d d = to - from;
  return std::atan2(d.x(), d.y());
}

void CheckMotion(const PersonMotion& motion, int num_clips) {
  motion.gait.Check();
  U4D_CHECK(!motion.phases.empty(), "PersonMotion: no phases");
  for (size_t i = 0; i < motion.phases.size(); ++i) {
    const MotionPhase& p = motion.phases[i];
    U4D_CHECK(std::isfinite(p.start) && std::isfinite(p.end) && p.end > p.start,
              "PersonMotion: phase {} has times [{}, {}]", i, p.start, p.end);
    if (i > 0) {
      U4D_CHECK(std::abs(p.start - motion.phases[i - 1].end) < 1e-9,
                "PersonMotion: phase {} starts at {} but phase {} ends at {}", i, p.start, i - 1,
                motion.phases[i - 1].end);
    }
    U4D_CHECK(p.from_xz.allFinite() && p.to_xz.allFinite() && std::isfinite(p.from_heading) &&
                  std::isfinite(p.to_heading) && p.hand_target.allFinite(),
              "PersonMotion: phase {} has non-finite positions", i);
    if (p.kind == MotionPhase::Kind::kMocap) {
      U4D_CHECK(p.clip >= 0 && p.clip < num_clips, "PersonMotion: phase {} uses clip {} of {}", i,
                p.clip, num_clips);
    }
    if (p.kind == MotionPhase::Kind::kHandshake) {
      U4D_CHECK(p.start <= p.shake_start && p.shake_start <= p.shake_end && p.shake_end <= p.end,
                "PersonMotion: handshake phase {} needs start <= shake_start <= shake_end <= end",
                i);
    }
  }
}

void SolveArmIk(const BodyShape& shape, bool right, const Eigen::Vector3d& target,
                const Eigen::Vector3d& pole, BodyPose* pose) {
  const int sh = right ? kRightShoulder : kLeftShoulder;
  const int el = right ? kRightElbow : kLeftElbow;
  const int wr = right ? kRightWrist : kLeftWrist;
  const Eigen::Vector3d rest_upper = shape.rest[el] - shape.rest[sh];
  const Eigen::Vector3d rest_fore = shape.rest[wr] - shape.rest[el];
  const double l1 = rest_upper.norm(), l2 = rest_fore.norm();
  const Eigen::Vector3d s = pose->position[sh];
  Eigen::Vector3d to_target = target - s;
  const double d = std::clamp(to_target.norm(), std::abs(l1 - l2) + 1e-4, l1 + l2 - 1e-4);
  const Eigen::Vector3d n =
      to_target.norm() > 1e-9 ? to_target.normalized() : Eigen::Vector3d(0, -1, 0);
  Eigen::Vector3d m = pole - pole.dot(n) * n;
  if (m.norm() < 1e-9) m = n.unitOrthogonal();
  m.normalize();
  const double cos_a = std::clamp((l1 * l1 + d * d - l2 * l2) / (2 * l1 * d), -1.0, 1.0);
  const Eigen::Vector3d elbow = s + l1 * (cos_a * n + std::sqrt(1 - cos_a * cos_a) * m);
  const Eigen::Vector3d wrist = s + d * n;
  const Eigen::Vector3d upper = elbow - s, fore = wrist - elbow;
  // Bend-plane normal: in the rest pose the elbow flexes forward about -x.
  Eigen::Vector3d axis = upper.cross(fore);
  if (axis.norm() < 1e-6 * l1 * l2) axis = upper.cross(m);
  const Eigen::Vector3d rest_axis(-1, 0, 0);
  pose->rotation[sh] = FrameFrom(upper, axis) * FrameFrom(rest_upper, rest_axis).transpose();
  pose->rotation[el] = FrameFrom(fore, axis) * FrameFrom(rest_fore, rest_axis).transpose();
  pose->rotation[wr] = pose->rotation[el];
  pose->position[el] = s + pose->rotation[sh] * rest_upper;
  pose->position[wr] = pose->position[el] + pose->rotation[el] * rest_fore;
}

Eigen::Vector2d FloorPosition(const PersonMotion& motion, const std::vector<MocapClip>& clips,
                              const BodyShape& shape, double time) {
  const BodyPose pose = EvaluateMotion(motion, shape, clips, time);
  return {pose.position[kPelvis].x(), pose.position[kPelvis].z()};
}

BodyPose EvaluateMotion(const PersonMotion& motion, const BodyShape& shape,
                        const std::vector<MocapClip>& clips, double time) {
  U4D_CHECK(!motion.phases.empty(), "EvaluateMotion: no phases");
  U4D_CHECK(std::isfinite(time), "EvaluateMotion: time is not finite");
  const MotionPhase& p = PhaseAt(motion, time);
  const double tau = std::clamp(time - p.start, 0.0, p.end - p.start);
  const GaitParams& g = motion.gait;
  const double sway_in = SmoothStep(0, 1.0, tau);
  switch (p.kind) {
    case MotionPhase::Kind::kStand:
      return GaitPose(shape, g, p.from_xz, TurnHeading(p, tau, kTurnTime), 0, 0, sway_in, time);
    case MotionPhase::Kind::kWalk: {
      const Eigen::Vector2d delta = p.to_xz - p.from_xz;
      const double length = delta.norm();
      const WalkState w = WalkProgress(length, p.end - p.start, tau);
      const Eigen::Vector2d xz =
          length > 1e-9 ? Eigen::Vector2d(p.from_xz + delta * (w.distance / length)) : p.from_xz;
      const double amp = std::min(1.0, w.speed / g.speed);
      const double phi = g.phase + 2 * M_PI * w.distance / g.stride;
      return GaitPose(shape, g, xz, TurnHeading(p, tau, kHeadingTurnWalk), phi, amp,
                      1 - SmoothStep(0, kRamp, tau), time);
    }
    case MotionPhase::Kind::kHandshake: {
      const double heading = TurnHeading(p, tau, kTurnTime);
      BodyPose pose = GaitPose(shape, g, p.from_xz, heading, 0, 0, 0.3 * sway_in, time);
      const double reach =
          SmoothStep(p.start, p.shake_start, time) * (1 - SmoothStep(p.shake_end, p.end, time));
      if (reach <= 0) return pose;
      const double shake_env = SmoothStep(p.shake_start, p.shake_start + 0.15, time) *
                               (1 - SmoothStep(p.shake_end - 0.15, p.shake_end, time));
      const Eigen::Vector3d target =
          p.hand_target +
          Eigen::Vector3d(0,
                          p.shake_amplitude * shake_env *
                              std::sin(2 * M_PI * p.shake_hz * (time - p.shake_start)),
                          0);
      const Eigen::Vector3d rest_wrist = pose.position[kRightWrist];
      const Eigen::Vector3d goal = rest_wrist + reach * (target - rest_wrist);
      const Eigen::Vector3d right(-std::cos(heading), 0, std::sin(heading));
      const Eigen::Vector3d back(-std::sin(heading), 0, -std::cos(heading));
      SolveArmIk(shape, true, goal, Eigen::Vector3d(0, -1, 0) + 0.6 * right + 0.3 * back, &pose);
      return pose;
    }
    case MotionPhase::Kind::kMocap: {
      U4D_CHECK(p.clip >= 0 && p.clip < static_cast<int>(clips.size()),
                "EvaluateMotion: mocap phase uses clip {} of {}", p.clip, clips.size());
      return TransformPose(SampleClip(clips[p.clip], p.clip_time + tau), p.world_from_clip);
    }
  }
  U4D_ASSERT(false);
  return {};
}

}  // namespace u4d::synth
