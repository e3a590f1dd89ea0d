// The synthetic world at one instant: what the body/motion code produces and
// the renderer consumes. Plain data, no behaviour.
//
// Identity through time: an object's mesh has the same faces and the same
// number of vertices at every frame, and vertex i is the same surface point at
// every frame. Ground-truth flow, vertex tracks and the per-frame GT meshes
// rely on this.
//
// Texture: every vertex carries `texcoord`, a 3D point fixed to the surface
// (its rest-pose position); materials are solid textures evaluated at the
// barycentric interpolation of texcoords, so the pattern moves with the
// surface and has detail at any resolution.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "u4d/io/poses.h"

namespace u4d::synth {

// The paper's 17-joint set, in Human3.6M order (the internal skeleton), is
// defined once in io/poses.h (h36m17::Joint); synth uses it unqualified.
using namespace ::u4d::h36m17;  // NOLINT(build/namespaces): the joint vocabulary
using Joints3d = std::array<Eigen::Vector3d, kNumJoints>;  // world, metres

// Body parts for per-pixel part maps (used to drop thin limbs from the
// degraded masks). Background and static geometry are kNone.
enum class BodyPart : uint8_t {
  kNone = 0,
  kHead,
  kTorso,
  kUpperArm,
  kForearm,
  kHand,
  kThigh,
  kShin,
  kFoot
};

// How a surface looks. Colours are linear BGR in [0, 1].
struct Material {
  enum class Pattern : uint8_t { kPlain, kNoise, kStripes, kChecker, kSpots };
  Pattern pattern = Pattern::kNoise;
  Eigen::Vector3f color_a{0.5f, 0.5f, 0.5f};
  Eigen::Vector3f color_b{0.3f, 0.3f, 0.3f};
  float scale = 0.05f;  // metres per pattern period
  uint32_t seed = 0;
};

struct SurfaceMesh {
  std::vector<Eigen::Vector3f> vertices;   // world, metres, at this instant
  std::vector<Eigen::Vector3f> texcoords;  // fixed per vertex (rest pose), metres
  std::vector<Eigen::Vector3i> faces;      // counter-clockwise seen from outside
  std::vector<uint8_t> face_material;      // index into the object's materials
  std::vector<BodyPart> vertex_part;       // per vertex; empty for static geometry
};

struct SceneObject {
  int instance_id = 0;           // >= 1 for people (the GT instance id); 0 for static
  std::string label = "person";  // class name; "background" for static geometry
  SurfaceMesh mesh;
  std::vector<Material> materials;
};

struct SceneFrame {
  double time = 0;                  // seconds from the start
  std::vector<SceneObject> people;  // instance ids 1..N, same order every frame
  // One per person with a skeleton, in `people` order: the procedural bodies
  // come first and have one; captured performers (captured.h) follow and
  // have none, so joints.size() <= people.size(). Likewise coco_keypoints.
  std::vector<Joints3d> joints;
  // COCO-17 keypoints in 3D (nose, eyes, ears, shoulders, elbows, wrists,
  // hips, knees, ankles, in COCO order), one per person: what a 2D keypoint
  // detector would report, used to synthesise 2D detections. Parallel to
  // `joints`.
  std::vector<std::array<Eigen::Vector3d, 17>> coco_keypoints;
  std::vector<SceneObject> statics;  // floor, walls, props: do not move
};

}  // namespace u4d::synth
