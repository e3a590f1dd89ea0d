#include "u4d/synth/people.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "u4d/synth/bvh.h"
#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

constexpr double kReach = 0.8;    // s, hand moves to the partner's
constexpr double kShake = 1.3;    // s, hands pump
constexpr double kRelease = 0.7;  // s, hand returns
constexpr double kTurn = 1.0;     // s, turning in place
constexpr double kForever = 1e6;  // end of the last phase

using Kind = MotionPhase::Kind;

Eigen::Vector2d Dir(double angle) { return {std::cos(angle), std::sin(angle)}; }

// Appends a phase that starts where the previous one ended.
MotionPhase& Append(PersonMotion* m, Kind kind, double duration) {
  MotionPhase p;
  p.kind = kind;
  if (!m->phases.empty()) {
    const MotionPhase& last = m->phases.back();
    p.start = last.end;
    p.from_xz = last.kind == Kind::kWalk ? last.to_xz : last.from_xz;
    p.from_heading = last.to_heading;
  }
  p.end = p.start + duration;
  p.to_xz = p.from_xz;
  p.to_heading = p.from_heading;
  m->phases.push_back(p);
  return m->phases.back();
}

void StartAt(PersonMotion* m, const Eigen::Vector2d& xz, double heading) {
  MotionPhase& p = Append(m, Kind::kStand, 1e-3);
  p.from_xz = p.to_xz = xz;
  p.from_heading = p.to_heading = heading;
}

void WalkTo(PersonMotion* m, const Eigen::Vector2d& xz) {
  const Eigen::Vector2d from =
      m->phases.back().kind == Kind::kWalk ? m->phases.back().to_xz : m->phases.back().from_xz;
  const double length = (xz - from).norm();
  MotionPhase& p = Append(m, Kind::kWalk, WalkDuration(m->gait, length));
  p.to_xz = xz;
  p.from_heading = p.to_heading = HeadingTowards(from, xz);
}

void StandTurning(PersonMotion* m, double duration, double heading) {
  MotionPhase& p = Append(m, Kind::kStand, duration);
  p.to_heading = heading;
}

void StandUntil(PersonMotion* m, double time, double heading) {
  StandTurning(m, std::max(1e-3, time - m->phases.back().end), heading);
}

double CurrentHeading(const PersonMotion& m) { return m.phases.back().to_heading; }
Eigen::Vector2d CurrentXz(const PersonMotion& m) {
  return m.phases.back().kind == Kind::kWalk ? m.phases.back().to_xz : m.phases.back().from_xz;
}

// Geometry of a handshake between persons a and b standing on a line.
struct HandshakePlan {
  double standoff[2];      // horizontal distance pelvis -> meeting point
  double height;           // meeting height
  double along = 0.04;     // each wrist stops this far on its own side of the midpoint
  double lateral = 0.018;  // and this far to its own right
};

HandshakePlan PlanHandshake(const BodyShape& a, const BodyShape& b) {
  HandshakePlan plan;
  const BodyShape* s[2] = {&a, &b};
  double arm[2], shoulder_y[2], lateral[2];
  for (int i = 0; i < 2; ++i) {
    const Joints3d& r = s[i]->rest;
    arm[i] = (r[kRightElbow] - r[kRightShoulder]).norm() + (r[kRightWrist] - r[kRightElbow]).norm();
    shoulder_y[i] = r[kRightShoulder].y() - 0.01;
    lateral[i] = std::abs(r[kRightShoulder].x() - r[kPelvis].x());
  }
  plan.height = 0.5 * (shoulder_y[0] + shoulder_y[1]) - 0.6 * std::min(arm[0], arm[1]);
  for (int i = 0; i < 2; ++i) {
    const double reach = 0.9 * arm[i];
    const double dy = shoulder_y[i] - plan.height;
    const double dl = lateral[i] - plan.lateral;
    const double h2 = reach * reach - dy * dy - dl * dl;
    plan.standoff[i] = plan.along + std::sqrt(std::max(h2, 0.2 * 0.2));
  }
  return plan;
}

// Adds the handshake phases to persons a (at meet - standoff_a * e) and b (at
// meet + standoff_b * e), both already standing there facing each other.
void AddHandshake(const HandshakePlan& plan, const Eigen::Vector2d& meet, const Eigen::Vector2d& e,
                  double start, PersonMotion* a, PersonMotion* b, HandshakeEvent* event) {
  const Eigen::Vector3d e3(e.x(), 0, e.y());
  const Eigen::Vector3d right_a = e3.cross(Eigen::Vector3d::UnitY());  // facing e: right = fwd x up
  const Eigen::Vector3d m3(meet.x(), plan.height, meet.y());
  PersonMotion* who[2] = {a, b};
  for (int i = 0; i < 2; ++i) {
    PersonMotion* m = who[i];
    const double sign = i == 0 ? 1 : -1;  // facing direction is sign * e
    StandUntil(m, start, CurrentHeading(*m));
    MotionPhase& p = Append(m, Kind::kHandshake, kReach + kShake + kRelease);
    p.shake_start = p.start + kReach;
    p.shake_end = p.shake_start + kShake;
    p.hand_target = m3 - sign * plan.along * e3 + sign * plan.lateral * right_a;
  }
  event->shake_start = start + kReach;
  event->shake_end = start + kReach + kShake;
}

void CheckTiming(int num_frames, double fps, double min_seconds, const char* what) {
  U4D_CHECK(std::isfinite(fps) && fps > 0 && fps <= 1000, "{}: fps {} outside (0, 1000]", what,
            fps);
  U4D_CHECK(num_frames > 0, "{}: num_frames must be positive, got {}", what, num_frames);
  U4D_CHECK(num_frames / fps >= min_seconds, "{}: {} frames at {} fps last {:.2f} s, need >= {} s",
            what, num_frames, fps, num_frames / fps, min_seconds);
}

}  // namespace

PersonScript MakePerson(uint64_t seed, const BodyMeshOptions& mesh_options) {
  PersonScript p;
  p.appearance = MakeAppearance(seed);
  p.shape = MakeBodyShape(p.appearance.height, p.appearance.width);
  p.mesh = MakeBodyMesh(p.shape, p.appearance, mesh_options);
  p.motion.gait = MakeGaitParams(p.shape.height, seed + 17);
  return p;
}

PeopleScript MakeHandshakeScript(int num_frames, double fps, uint64_t seed) {
  CheckTiming(num_frames, fps, 4.0, "MakeHandshakeScript");
  const double duration = num_frames / fps;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  PeopleScript script;
  script.fps = fps;
  script.num_frames = num_frames;
  script.people.push_back(MakePerson(seed * 2 + 1));
  script.people.push_back(MakePerson(seed * 2 + 2));
  PersonMotion* a = &script.people[0].motion;
  PersonMotion* b = &script.people[1].motion;
  const HandshakePlan plan = PlanHandshake(script.people[0].shape, script.people[1].shape);

  const double axis_angle = 2 * M_PI * u01(rng);
  const Eigen::Vector2d e = Dir(axis_angle);
  const Eigen::Vector2d meet = 0.2 * Eigen::Vector2d(2 * u01(rng) - 1, 2 * u01(rng) - 1);
  const Eigen::Vector2d stop_a = meet - plan.standoff[0] * e;
  const Eigen::Vector2d stop_b = meet + plan.standoff[1] * e;
  // Approach: as long as the duration allows, at most 1.6 m.
  const double budget = std::clamp(0.3 * (duration - kReach - kShake - kRelease), 0.7, 2.4);
  const double delay_b = 0.3 * u01(rng);
  const double len_a = std::clamp(a->gait.speed * (budget - 0.6), 0.25, 1.6);
  const double len_b = std::clamp(b->gait.speed * (budget - 0.6 - delay_b), 0.25, 1.6);
  StartAt(a, stop_a - len_a * e, HeadingTowards(stop_a - len_a * e, stop_a));
  StartAt(b, stop_b + len_b * e, HeadingTowards(stop_b + len_b * e, stop_b));
  StandTurning(b, delay_b, CurrentHeading(*b));
  WalkTo(a, stop_a);
  WalkTo(b, stop_b);
  const double start = std::max(a->phases.back().end, b->phases.back().end) + 0.25;
  HandshakeEvent event;
  AddHandshake(plan, meet, e, start, a, b, &event);
  script.handshakes.push_back(event);
  // Turn away (about 145 degrees, opposite senses) and walk apart.
  const double remaining = duration - a->phases.back().end - kTurn;
  PersonMotion* who[2] = {a, b};
  for (int i = 0; i < 2; ++i) {
    PersonMotion* m = who[i];
    const double away = CurrentHeading(*m) + (i == 0 ? 1 : -1) * 0.8 * M_PI;
    StandTurning(m, kTurn, away);
    if (remaining > 1.2) {
      const double len = std::clamp(m->gait.speed * (remaining - 0.6), 0.2, 1.3);
      const Eigen::Vector2d from = CurrentXz(*m);
      WalkTo(m, from + len * Eigen::Vector2d(std::sin(away), std::cos(away)));
    }
    StandTurning(m, kForever, CurrentHeading(*m));
  }
  CheckPeopleScript(script);
  return script;
}

PeopleScript MakeMeetupScript(int num_people, int num_frames, double fps, uint64_t seed,
                              const fs::path& mocap_bvh) {
  U4D_CHECK(num_people >= 3 && num_people <= 8, "MakeMeetupScript: num_people {} outside 3..8",
            num_people);
  CheckTiming(num_frames, fps, 5.0, "MakeMeetupScript");
  const double duration = num_frames / fps;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  PeopleScript script;
  script.fps = fps;
  script.num_frames = num_frames;
  for (int i = 0; i < num_people; ++i) script.people.push_back(MakePerson(seed * 16 + i + 1));
  const HandshakePlan plan = PlanHandshake(script.people[0].shape, script.people[1].shape);

  // Slots on a circle: the pair 0-1 at the handshake distance, the rest evenly.
  const double ring = 0.85;
  const double chord = plan.standoff[0] + plan.standoff[1];
  const double beta = 2 * std::asin(std::min(1.0, chord / (2 * ring)));
  const double theta0 = 2 * M_PI * u01(rng);
  std::vector<double> slot_angle(num_people);
  slot_angle[0] = theta0 - beta / 2;
  slot_angle[1] = theta0 + beta / 2;
  for (int k = 2; k < num_people; ++k) {
    slot_angle[k] = theta0 + beta / 2 + (2 * M_PI - beta) * (k - 1) / (num_people - 1);
  }
  const double budget =
      std::clamp(0.35 * (duration - kReach - kShake - kRelease - kTurn), 0.7, 2.5);
  double arrival_pair = 0;
  const int mocap_person = num_people - 1;
  for (int i = 0; i < mocap_person; ++i) {
    PersonMotion* m = &script.people[i].motion;
    const Eigen::Vector2d slot = ring * Dir(slot_angle[i]);
    const double delay = 0.5 * u01(rng);
    const double len = std::clamp(m->gait.speed * (budget - 0.6 - delay), 0.25, 1.55);
    const Eigen::Vector2d start = (ring + len) * Dir(slot_angle[i]);
    StartAt(m, start, HeadingTowards(start, slot));
    StandTurning(m, delay, CurrentHeading(*m));
    WalkTo(m, slot);
    if (i < 2) arrival_pair = std::max(arrival_pair, m->phases.back().end);
  }
  // The pair turns to face each other and shakes hands, then faces the group.
  const Eigen::Vector2d slot0 = ring * Dir(slot_angle[0]);
  const Eigen::Vector2d slot1 = ring * Dir(slot_angle[1]);
  const Eigen::Vector2d e = (slot1 - slot0).normalized();
  const Eigen::Vector2d meet = slot0 + plan.standoff[0] * e;
  PersonMotion* a = &script.people[0].motion;
  PersonMotion* b = &script.people[1].motion;
  StandTurning(a, kTurn, HeadingTowards(slot0, slot1));
  StandTurning(b, kTurn, HeadingTowards(slot1, slot0));
  HandshakeEvent event;
  AddHandshake(plan, meet, e, arrival_pair + kTurn + 0.2, a, b, &event);
  script.handshakes.push_back(event);
  for (int i = 0; i < mocap_person; ++i) {
    PersonMotion* m = &script.people[i].motion;
    StandTurning(m, kForever, HeadingTowards(CurrentXz(*m), Eigen::Vector2d::Zero()));
  }

  // The mocap person: the clip's walk ends at its slot, heading inwards.
  {
    PersonScript& person = script.people[mocap_person];
    const BvhMotion bvh = ReadBvh(mocap_bvh);
    RetargetOptions ropt;
    ropt.fps = fps;
    script.clips.push_back(RetargetBvh(bvh, person.shape, ropt));
    const MocapClip& clip = script.clips.back();
    const Eigen::Vector3d p0 = clip.poses.front().position[kPelvis];
    const Eigen::Vector3d p1 = clip.poses.back().position[kPelvis];
    const Eigen::Vector2d travel(p1.x() - p0.x(), p1.z() - p0.z());
    U4D_CHECK(travel.norm() > 0.3, "{}: the clip travels only {:.2f} m; a walk is needed",
              mocap_bvh.string(), travel.norm());
    const Eigen::Vector2d slot = ring * Dir(slot_angle[mocap_person]);
    const double yaw = HeadingTowards(slot, Eigen::Vector2d::Zero()) -
                       HeadingTowards(Eigen::Vector2d::Zero(), travel);
    Rigid3d world_from_clip;
    world_from_clip.rotation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Vector3d end = world_from_clip.rotation * p1;
    world_from_clip.translation = Eigen::Vector3d(slot.x() - end.x(), 0, slot.y() - end.z());
    MotionPhase p;
    p.kind = Kind::kMocap;
    p.start = 0;
    p.end = kForever;
    p.clip = 0;
    // The clip stops walking at t_stop (the last time the pelvis moves faster
    // than 0.15 m/s); play it so that it stops at 75% of the scene.
    double t_stop = 0;
    const int half = std::max(1, static_cast<int>(std::lround(0.25 * clip.fps)));
    for (int i = half; i + half < static_cast<int>(clip.poses.size()); ++i) {
      const Eigen::Vector3d d =
          clip.poses[i + half].position[kPelvis] - clip.poses[i - half].position[kPelvis];
      if (Eigen::Vector2d(d.x(), d.z()).norm() / (2 * half / clip.fps) > 0.15)
        t_stop = i / clip.fps;
    }
    p.clip_time = std::max(0.0, t_stop - 0.75 * duration);
    p.world_from_clip = world_from_clip;
    p.from_xz = p.to_xz = slot;
    person.motion.phases = {p};
  }
  CheckPeopleScript(script);
  return script;
}

void CheckPeopleScript(const PeopleScript& script) {
  U4D_CHECK(std::isfinite(script.fps) && script.fps > 0, "PeopleScript: fps {}", script.fps);
  U4D_CHECK(script.num_frames > 0, "PeopleScript: num_frames {}", script.num_frames);
  for (size_t i = 0; i < script.people.size(); ++i) {
    const PersonScript& p = script.people[i];
    CheckMotion(p.motion, static_cast<int>(script.clips.size()));
    U4D_CHECK(p.mesh.rest.vertices.size() == p.mesh.vertex_joints.size() &&
                  p.mesh.rest.faces.size() == p.mesh.rest.face_material.size(),
              "PeopleScript: person {} has an inconsistent mesh template", i);
  }
}

BodyPose PosePerson(const PeopleScript& script, int person, int frame) {
  U4D_CHECK(person >= 0 && person < static_cast<int>(script.people.size()),
            "PosePerson: person {} of {}", person, script.people.size());
  const PersonScript& p = script.people[person];
  return EvaluateMotion(p.motion, p.shape, script.clips, FrameTime(script, frame));
}

void PosePeople(const PeopleScript& script, int frame, SceneFrame* out) {
  U4D_CHECK(frame >= 0 && frame < script.num_frames, "PosePeople: frame {} outside 0..{}", frame,
            script.num_frames - 1);
  const size_t n = script.people.size();
  out->time = FrameTime(script, frame);
  out->people.resize(n);
  out->joints.resize(n);
  out->coco_keypoints.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const PersonScript& p = script.people[i];
    const BodyPose pose = PosePerson(script, static_cast<int>(i), frame);
    SceneObject& obj = out->people[i];
    obj.instance_id = static_cast<int>(i) + 1;
    obj.label = "person";
    obj.materials.assign(p.appearance.materials.begin(), p.appearance.materials.end());
    PoseBodyMesh(p.mesh, p.shape, pose, &obj.mesh);
    out->joints[i] = pose.position;
    out->coco_keypoints[i] = CocoKeypointsFromPose(p.shape, pose);
  }
}

}  // namespace u4d::synth
