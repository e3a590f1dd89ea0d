// People of the synthetic world: body mesh invariants, the handshake and
// meetup presets against the facts they promise, COCO keypoint geometry.
#include "u4d/synth/people.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/timer.h"

namespace u4d::synth {
namespace {

// The meetup preset's CMU walk, shipped in data/mocap.
fs::path WalkBvh() { return ShippedDataFile(fs::path("mocap") / "scaled_131_02.bvh"); }

double MinY(const SurfaceMesh& m) {
  double y = 1e9;
  for (const auto& v : m.vertices) y = std::min<double>(y, v.y());
  return y;
}

double PointSegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t =
      ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0;
  return (p - (a + t * ab)).norm();
}

TEST(BodyMesh, TubesAreClosedOrientedAndNonDegenerate) {
  const PersonScript person = MakePerson(7);
  const BodyMeshTemplate& body = person.mesh;
  const SurfaceMesh& m = body.rest;
  ASSERT_EQ(m.vertices.size(), m.texcoords.size());
  ASSERT_EQ(m.vertices.size(), m.vertex_part.size());
  ASSERT_EQ(m.faces.size(), m.face_material.size());
  std::printf("body mesh: %zu vertices, %zu faces, %zu tubes\n", m.vertices.size(), m.faces.size(),
              body.tubes.size());
  EXPECT_GT(m.faces.size(), 2000u);
  EXPECT_LT(m.faces.size(), 12000u);
  double min_area = 1e9;
  for (const BodyTube& tube : body.tubes) {
    // Every directed edge appears once and its reverse once: closed, manifold,
    // consistently oriented.
    std::map<std::pair<int, int>, int> edges;
    double volume = 0;
    for (int f = tube.first_face; f < tube.first_face + tube.num_faces; ++f) {
      const Eigen::Vector3i& t = m.faces[f];
      for (int k = 0; k < 3; ++k) {
        ASSERT_GE(t[k], tube.first_vertex);
        ASSERT_LT(t[k], tube.first_vertex + tube.num_vertices);
        ++edges[{t[k], t[(k + 1) % 3]}];
      }
      const Eigen::Vector3d a = m.vertices[t[0]].cast<double>(),
                            b = m.vertices[t[1]].cast<double>(),
                            c = m.vertices[t[2]].cast<double>();
      min_area = std::min(min_area, 0.5 * (b - a).cross(c - a).norm());
      volume += a.dot(b.cross(c)) / 6;
      ASSERT_LT(m.face_material[f], kNumBodyMaterials);
    }
    for (const auto& [e, count] : edges) {
      ASSERT_EQ(count, 1) << "tube of joint " << tube.joint;
      ASSERT_EQ(edges.count({e.second, e.first}), 1u)
          << "open edge in tube of joint " << tube.joint;
    }
    // Counter-clockwise seen from outside <=> positive enclosed volume.
    EXPECT_GT(volume, 0) << "tube of joint " << tube.joint;
  }
  EXPECT_GT(min_area, 1e-7);
  // Every material is used, and the face has skin.
  std::vector<int> used(kNumBodyMaterials, 0);
  for (uint8_t mat : m.face_material) ++used[mat];
  for (int i = 0; i < kNumBodyMaterials; ++i) EXPECT_GT(used[i], 0) << "material " << i;
}

TEST(BodyMesh, VerticesStayNearTheirBonesInEveryPose) {
  const PeopleScript script = MakeHandshakeScript(250, 25, 3);
  const PersonScript& person = script.people[0];
  double worst_excess = 0;
  for (int frame = 0; frame < script.num_frames; frame += 5) {
    const BodyPose pose = PosePerson(script, 0, frame);
    SurfaceMesh mesh;
    PoseBodyMesh(person.mesh, person.shape, pose, &mesh);
    for (const BodyTube& tube : person.mesh.tubes) {
      const Rigid3d t = SegmentTransform(person.shape, pose, tube.joint);
      const Eigen::Vector3d a = t * tube.a, b = t * tube.b;
      for (int i = tube.first_vertex; i < tube.first_vertex + tube.num_vertices; ++i) {
        const double d = PointSegmentDistance(mesh.vertices[i].cast<double>(), a, b);
        worst_excess = std::max(worst_excess, d - tube.max_radius);
      }
    }
  }
  std::printf("worst vertex distance beyond its tube radius: %.4f m\n", worst_excess);
  EXPECT_LT(worst_excess, 0.04);
}

TEST(BodyMesh, AppearanceIsDeterministicAndVaried) {
  const Appearance a = MakeAppearance(11), b = MakeAppearance(11);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.materials[kShirt].color_a, b.materials[kShirt].color_a);
  int patterned = 0;
  double min_h = 10, max_h = 0;
  for (uint64_t seed = 0; seed < 40; ++seed) {
    const Appearance p = MakeAppearance(seed);
    patterned += p.materials[kShirt].pattern != Material::Pattern::kPlain;
    min_h = std::min(min_h, p.height);
    max_h = std::max(max_h, p.height);
    EXPECT_GT((p.materials[kShirt].color_a - p.materials[kShirt].color_b).norm(), 0.02);
  }
  EXPECT_EQ(patterned, 40);
  EXPECT_GE(min_h, 1.6);
  EXPECT_LE(max_h, 1.9);
  EXPECT_GT(max_h - min_h, 0.15);
}

// Facts every posed frame must satisfy, for every person.
void CheckFrames(const PeopleScript& script, bool check_feet_for_mocap) {
  SceneFrame frame0;
  PosePeople(script, 0, &frame0);
  double min_pelvis_distance = 1e9, worst_floor = 0, max_radius = 0, worst_bone = 0;
  for (int f = 0; f < script.num_frames; ++f) {
    SceneFrame frame;
    PosePeople(script, f, &frame);
    ASSERT_EQ(frame.people.size(), script.people.size());
    ASSERT_EQ(frame.joints.size(), script.people.size());
    ASSERT_EQ(frame.coco_keypoints.size(), script.people.size());
    for (size_t i = 0; i < frame.people.size(); ++i) {
      const SceneObject& obj = frame.people[i];
      const PersonScript& person = script.people[i];
      EXPECT_EQ(obj.instance_id, static_cast<int>(i) + 1);
      EXPECT_EQ(obj.label, "person");
      ASSERT_EQ(obj.mesh.vertices.size(), frame0.people[i].mesh.vertices.size());
      ASSERT_EQ(obj.mesh.faces, frame0.people[i].mesh.faces);
      ASSERT_EQ(obj.mesh.texcoords, frame0.people[i].mesh.texcoords);
      ASSERT_EQ(obj.materials.size(), static_cast<size_t>(kNumBodyMaterials));
      const Joints3d& j = frame.joints[i];
      for (const auto& [p, c] : SkeletonBones()) {
        worst_bone = std::max(
            worst_bone,
            std::abs((j[c] - j[p]).norm() - (person.shape.rest[c] - person.shape.rest[p]).norm()));
      }
      const bool mocap = person.motion.phases[0].kind == MotionPhase::Kind::kMocap;
      if (!mocap || check_feet_for_mocap) {
        worst_floor = std::max(worst_floor, std::abs(MinY(obj.mesh)));
      }
      max_radius = std::max(max_radius, Eigen::Vector2d(j[kPelvis].x(), j[kPelvis].z()).norm());
      for (size_t k = i + 1; k < frame.people.size(); ++k) {
        const Eigen::Vector3d d = j[kPelvis] - frame.joints[k][kPelvis];
        min_pelvis_distance = std::min(min_pelvis_distance, Eigen::Vector2d(d.x(), d.z()).norm());
      }
      // COCO: nose in front of the head, left keypoints on the left.
      const auto& kp = frame.coco_keypoints[i];
      const Eigen::Vector3d left = (j[kLeftShoulder] - j[kRightShoulder]).normalized();
      const Eigen::Vector3d up = (j[kNeck] - j[kThorax]).normalized();
      const Eigen::Vector3d forward = left.cross(up).normalized();
      const Eigen::Vector3d ear_mid = 0.5 * (kp[3] + kp[4]);
      // Procedural heads face the way the shoulders do; the mocap dancer turns
      // his head up to ~60 degrees, so only "not backwards" is required there.
      EXPECT_GT((kp[0] - ear_mid).dot(forward), mocap ? 0.02 : 0.06)
          << "frame " << f << " person " << i;
      EXPECT_GT((kp[1] - kp[2]).dot(left), 0.02);
      EXPECT_GT((kp[3] - kp[4]).dot(left), 0.08);
      EXPECT_EQ(kp[5], j[kLeftShoulder]);
      EXPECT_EQ(kp[16], j[kRightAnkle]);
    }
  }
  std::printf(
      "frames: min pelvis distance %.3f m, worst |lowest vertex y| %.4f m, max pelvis radius "
      "%.2f m, worst bone length change %.2e m\n",
      min_pelvis_distance, worst_floor, max_radius, worst_bone);
  EXPECT_GT(min_pelvis_distance, 0.35);
  EXPECT_LT(worst_floor, 0.03);
  EXPECT_LT(max_radius, 2.6);
  EXPECT_LT(worst_bone, 1e-6);
}

void CheckHandshake(const PeopleScript& script, const HandshakeEvent& hs) {
  double max_during = 0, min_during = 1e9, min_vertical_span = 1e9;
  double wrist_y_min = 1e9, wrist_y_max = -1e9;
  const int first = static_cast<int>(std::ceil(hs.shake_start * script.fps));
  const int last = static_cast<int>(std::floor(hs.shake_end * script.fps));
  ASSERT_LT(last, script.num_frames) << "the shake must fit into the scene";
  ASSERT_GE(last - first, static_cast<int>(0.9 * script.fps));  // ~1 s or more
  for (int f = first; f <= last; ++f) {
    const BodyPose a = PosePerson(script, hs.person_a, f);
    const BodyPose b = PosePerson(script, hs.person_b, f);
    const double d = (a.position[kRightWrist] - b.position[kRightWrist]).norm();
    max_during = std::max(max_during, d);
    min_during = std::min(min_during, d);
    // Hands move together: their heights agree.
    EXPECT_LT(std::abs(a.position[kRightWrist].y() - b.position[kRightWrist].y()), 0.03);
    wrist_y_min = std::min(wrist_y_min, a.position[kRightWrist].y());
    wrist_y_max = std::max(wrist_y_max, a.position[kRightWrist].y());
  }
  min_vertical_span = wrist_y_max - wrist_y_min;
  const BodyPose a0 = PosePerson(script, hs.person_a, 0);
  const BodyPose b0 = PosePerson(script, hs.person_b, 0);
  const double at_start = (a0.position[kRightWrist] - b0.position[kRightWrist]).norm();
  std::printf(
      "handshake %d-%d: right wrists %.3f-%.3f m apart while shaking (%.2f s), %.2f m at "
      "the start; shaking moves the wrist %.3f m vertically\n",
      hs.person_a, hs.person_b, min_during, max_during, hs.shake_end - hs.shake_start, at_start,
      min_vertical_span);
  EXPECT_LT(max_during, 0.10);
  EXPECT_GT(at_start, 0.5);
  EXPECT_GT(min_vertical_span, 0.03);  // they shake
}

TEST(People, HandshakeScriptKeepsItsPromises) {
  const PeopleScript script = MakeHandshakeScript(250, 25, 42);
  ASSERT_EQ(script.people.size(), 2u);
  ASSERT_EQ(script.handshakes.size(), 1u);
  CheckHandshake(script, script.handshakes[0]);
  CheckFrames(script, true);
  // Released afterwards, and apart at the end.
  const BodyPose a = PosePerson(script, 0, script.num_frames - 1);
  const BodyPose b = PosePerson(script, 1, script.num_frames - 1);
  EXPECT_GT((a.position[kRightWrist] - b.position[kRightWrist]).norm(), 0.5);
}

TEST(People, HandshakeWorksForOtherSeedsAndShortScenes) {
  for (uint64_t seed : {1, 2, 5}) {
    const PeopleScript script = MakeHandshakeScript(125, 25, seed);  // 5 s
    CheckHandshake(script, script.handshakes[0]);
  }
  EXPECT_THROW(MakeHandshakeScript(50, 25, 1), Error);  // 2 s is too short
}

TEST(People, FaceToFacePartnersOccludeEachOtherAlongTheirAxis) {
  const PeopleScript script = MakeHandshakeScript(200, 20, 9);
  // While they stand face to face, one hides part of the other as seen from
  // a camera on their axis 4.5 m away: the nearer body covers the line of
  // sight to the farther person's pelvis.
  const HandshakeEvent& hs = script.handshakes[0];
  const int f = static_cast<int>((hs.shake_start + 0.5) * script.fps);
  const BodyPose a = PosePerson(script, 0, f), b = PosePerson(script, 1, f);
  const Eigen::Vector3d axis = (b.position[kPelvis] - a.position[kPelvis]).normalized();
  const Eigen::Vector3d camera = a.position[kPelvis] - 4.5 * axis;
  const Eigen::Vector3d target = b.position[kThorax];
  double closest = 1e9;  // distance of a's thorax from the ray camera -> b's thorax
  const Eigen::Vector3d ray = (target - camera).normalized();
  const Eigen::Vector3d q = a.position[kThorax] - camera;
  closest = (q - q.dot(ray) * ray).norm();
  EXPECT_LT(closest, 0.1);  // a's torso (half width ~0.15 m) is on the line of sight
}

TEST(People, MeetupHasAHandshakeAMocapPersonAndNoCollisions) {
  const PeopleScript script = MakeMeetupScript(4, 200, 25, 5, WalkBvh());
  ASSERT_EQ(script.people.size(), 4u);
  ASSERT_EQ(script.clips.size(), 1u);
  EXPECT_EQ(script.people[3].motion.phases[0].kind, MotionPhase::Kind::kMocap);
  ASSERT_EQ(script.handshakes.size(), 1u);
  CheckHandshake(script, script.handshakes[0]);
  CheckFrames(script, true);
  // The mocap person really walks: more than 0.5 m over the scene.
  const BodyPose first = PosePerson(script, 3, 0);
  const BodyPose last = PosePerson(script, 3, script.num_frames - 1);
  EXPECT_GT((first.position[kPelvis] - last.position[kPelvis]).norm(), 0.5);
  EXPECT_THROW(MakeMeetupScript(4, 200, 25, 5, "/nonexistent.bvh"), Error);
  EXPECT_THROW(MakeMeetupScript(2, 200, 25, 5, WalkBvh()), Error);
}

TEST(People, MeetupWithMorePeopleAndTiming) {
  const PeopleScript script = MakeMeetupScript(6, 250, 25, 77, WalkBvh());
  CheckFrames(script, true);
  SceneFrame frame;
  PosePeople(script, 100, &frame);  // warm up
  Timer timer;
  const int reps = 50;
  for (int r = 0; r < reps; ++r) PosePeople(script, r * 5 % script.num_frames, &frame);
  const double per_frame = timer.Seconds() / reps;
  size_t faces = 0;
  for (const auto& p : frame.people) faces += p.mesh.faces.size();
  std::printf("PosePeople: %.3f ms per frame for %zu people (%zu triangles)\n", per_frame * 1e3,
              frame.people.size(), faces);
  EXPECT_LT(per_frame, 0.05);
}

TEST(People, ScriptsAreDeterministic) {
  const PeopleScript a = MakeHandshakeScript(100, 25, 123), b = MakeHandshakeScript(100, 25, 123);
  SceneFrame fa, fb;
  PosePeople(a, 60, &fa);
  PosePeople(b, 60, &fb);
  ASSERT_EQ(fa.people[1].mesh.vertices, fb.people[1].mesh.vertices);
  const PeopleScript c = MakeHandshakeScript(100, 25, 124);
  SceneFrame fc;
  PosePeople(c, 60, &fc);
  EXPECT_FALSE(fa.people[1].mesh.vertices == fc.people[1].mesh.vertices);
  EXPECT_THROW(PosePeople(a, 100, &fa), Error);
}

}  // namespace
}  // namespace u4d::synth
