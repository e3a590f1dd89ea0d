// Captured performers: real animated mesh sequences (one mesh per frame, fixed
// topology; io/mesh_sequence.h) as people of the synthetic world, beside the
// procedural bodies of people.h.
//
// A captured sequence is scaled to a stature, stood on the floor y = 0 and
// turned and placed on it; vertex i stays the same surface point in every
// frame, so the renderer's ground truth (instances, depth, occlusion-aware
// flow, meshes with stable vertex ids) is exactly as for the procedural
// bodies. What a capture does not have is a skeleton: a captured performer has
// no 3D joints and no COCO keypoints, so the capture holds no GT joints and no
// 2D keypoints for it (docs/synthetic.md).
//
// Appearance: the solid textures of a random Appearance (body_mesh.h),
// assigned by height on the first frame (head / shirt / trousers / shoes
// bands of the stature), evaluated at the first frame's positions, so that
// the pattern moves with the surface. Vertex parts come from the same bands
// (head, torso, thigh, shin, foot): arms are not told apart from the torso.
//
// Time: capture frame f shows source frame first_frame + f * frame_step,
// played forwards then backwards (ping-pong) when the capture is longer than
// the source.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "u4d/io/mesh_sequence.h"
#include "u4d/synth/scene.h"
#include "u4d/util/file.h"

namespace u4d::synth {

struct CapturedPerformerOptions {
  fs::path source;              // per-frame mesh folder or .pc2 cache (ReadMeshSequence)
  bool source_has_head = true;  // false: the top of the mesh is the neck
  // Stature in metres of a person with a head; the first frame's vertical
  // extent is scaled to it (to 0.87 of it when the source has no head).
  double stature = 1.75;
  int first_frame = 0;  // source frame shown at capture frame 0
  int frame_step = 1;   // source frames per capture frame, >= 1
  // Where the centre of the first frame's footprint stands on the floor
  // (world x, z in metres) and the turn about +y (radians) applied first.
  Eigen::Vector2d position{0, 0};
  double yaw = 0;
  uint64_t appearance_seed = 1;  // MakeAppearance seed
  void Check() const;            // throws u4d::Error naming the field
};

// A loaded, placed performer: the rest surface (first frame, world metres)
// with its texcoords, faces, materials and parts, and the world vertices of
// every source frame the capture uses.
struct CapturedPerformer {
  SurfaceMesh rest;
  std::vector<Material> materials;
  std::vector<int> source_frames;                      // loaded source frame indices
  std::vector<std::vector<Eigen::Vector3f>> vertices;  // parallel to source_frames, world
  int first_frame = 0, frame_step = 1;
  int source_length = 1;  // frames in the source (for the ping-pong)
};

// Reads options.source (the frames that capture frames 0..num_frames-1 need)
// and places it. A first_frame past the source's end is an error. Throws u4d::Error naming the file
// on unreadable input.
CapturedPerformer LoadCapturedPerformer(const CapturedPerformerOptions& options, int num_frames);

// Source frame shown at capture frame `frame` (ping-pong over `length`).
int CapturedSourceFrame(int first_frame, int frame_step, int length, int frame);

// The performer at capture frame `frame` as a person with `instance_id`.
SceneObject PoseCapturedPerformer(const CapturedPerformer& performer, int frame, int instance_id);

// Moves `b` along the horizontal unit direction `direction` (x, z) so that the
// closest approach of the two performers' surfaces over capture frames
// 0..num_frames-1 is `gap` metres (they touch once, without passing through
// each other). Uses every `vertex_stride`-th vertex. Returns the offset added
// to b (metres along `direction`; 0 when no sampled pair ever lines up).
double PlaceAtClosestApproach(const CapturedPerformer& a, CapturedPerformer* b,
                              const Eigen::Vector2d& direction, double gap, int num_frames,
                              int vertex_stride = 8);

}  // namespace u4d::synth
