// One segment of the 4D scene as an animated binary glTF 2.0 (.glb) that
// three.js, Blender and any glTF viewer play: segments/<kk>/<id>.glb
// (io/layout.h SceneSegmentDir).
//
// Content: one mesh, one node, one scene. The mesh's primitive holds the
// segment's first frame: POSITION (float VEC3, with min/max as the spec
// requires), optional NORMAL, COLOR_0 (float VEC3 RGB in [0,1], when the
// mesh has colours) and indices (uint32, triangles). Frame k >= 1 is morph
// target k-1 (POSITION deltas, with min/max). One animation "play" drives the
// node's morph weights with STEP interpolation: at time k / fps the weights
// are one-hot on target k-1 (all zero at k = 0), so frame k is shown exactly.
// The root's "extras" hold object_id, first_frame, fps and, when the segment
// has one, the object's "class".
// Units: metres, world frame of the capture (glTF's +y up is not imposed).
#pragma once

#include "u4d/fusion/scene_flow.h"
#include "u4d/util/file.h"

namespace u4d {

struct GltfOptions {
  double fps = 25.0;    // frames per second of the animation
  bool normals = true;  // write the first frame's vertex normals
  void Check() const;   // throws u4d::Error naming the bad field
};

// Writes atomically. Throws u4d::Error when the segment has no frame, no
// triangle, frames of different vertex counts or a bad index.
void WriteSegmentGlb(const fs::path& path, const AnimatedMesh& segment, const GltfOptions& options);

// Reads back a segment written by WriteSegmentGlb: triangles, colours (when
// present), object id, first frame and class (from "extras"), and the positions of
// every frame (the base POSITION plus morph target k-1 for frame k, float
// precision). tracked_fraction is not stored and comes back empty. Throws
// u4d::Error naming the file when it is missing, truncated, not a binary
// glTF 2.0, or when an accessor is not the float VEC3 / uint32 SCALAR layout
// the writer uses or points outside the binary chunk.
AnimatedMesh ReadSegmentGlb(const fs::path& path);

}  // namespace u4d
