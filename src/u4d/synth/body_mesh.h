// The body mesh: fixed topology bound to the 17-joint skeleton, and per-person
// appearance (materials, proportions) drawn from a seed.
//
// The surface is a union of closed tubes (each a watertight, consistently
// oriented genus-0 mesh): head, neck, torso, upper arms, forearms, hands,
// thighs, shins and feet. Tubes overlap at the joints, so the union has no
// gaps in any pose. Each vertex is rigidly bound to its tube's joint, or
// linearly blended with one neighbour joint near an end (weights up to 1/2 at
// the joint, equal on both sides, so knees and elbows bend without tearing).
// Topology, texcoords (= rest-pose positions), vertex parts and face
// materials never change; only vertex positions follow the pose.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "u4d/synth/scene.h"
#include "u4d/synth/skeleton.h"

namespace u4d::synth {

// Indices into a person's materials.
enum BodyMaterial : uint8_t { kSkin = 0, kHair, kShirt, kTrousers, kShoes, kNumBodyMaterials };

// How a person looks: proportions, clothing and materials.
struct Appearance {
  double height = 1.75;      // metres
  double width = 1.0;        // lateral scale (see MakeBodyShape)
  bool long_sleeves = true;  // forearms covered by the shirt, else bare skin
  std::array<Material, kNumBodyMaterials> materials;  // indexed by BodyMaterial
};

// A random person: height 1.60-1.90 m, width 0.9-1.12, skin tone from a
// palette of five, hair colour, a patterned shirt (stripes, checker, spots or
// noise; never plain) and trousers, dark shoes. Deterministic in `seed`.
Appearance MakeAppearance(uint64_t seed);

struct BodyMeshOptions {
  int ring_segments = 16;  // vertices around a limb (torso and head get 1.5x), >= 6
  int limb_rings = 7;      // rings along the straight part of a limb tube, >= 2
  int cap_rings = 3;       // rings in each rounded end of a tube, >= 1
  void Check() const;
};

// One tube of the body, in the rest pose, for tests and debugging.
struct BodyTube {
  int joint = 0;  // the joint its vertices are bound to (mostly)
  BodyPart part = BodyPart::kNone;
  Eigen::Vector3d a, b;   // axis end points, rest pose
  double max_radius = 0;  // largest distance of a vertex from the axis segment
  int first_vertex = 0, num_vertices = 0, first_face = 0, num_faces = 0;
};

struct BodyMeshTemplate {
  SurfaceMesh rest;  // rest-pose vertices (= texcoords), faces, materials, parts
  std::vector<BodyTube> tubes;
  // Skinning: vertex i = (1 - w) T[j0](x) + w T[j1](x), T = SegmentTransform.
  std::vector<std::array<uint8_t, 2>> vertex_joints;
  std::vector<float> vertex_weight;  // w, in [0, 0.5]
};

BodyMeshTemplate MakeBodyMesh(const BodyShape& shape, const Appearance& appearance,
                              const BodyMeshOptions& options = {});

// Fills `mesh` with the body in `pose`: the template's topology, texcoords,
// parts and materials, and the posed vertices.
void PoseBodyMesh(const BodyMeshTemplate& body, const BodyShape& shape, const BodyPose& pose,
                  SurfaceMesh* mesh);

}  // namespace u4d::synth
