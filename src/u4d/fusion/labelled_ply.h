// Labelled, coloured triangle meshes as PLY (the 4D scene's meshes/<id>/<frame>.ply,
// io/layout.h SceneMesh).
//
// Format written: binary_little_endian 1.0; element vertex with float x y z,
// float nx ny nz (when the mesh has normals), uchar red green blue (when it
// has colours) and int label; element face with list uchar int
// vertex_indices. Open3D, MeshLab and Blender read it (they ignore `label`).
// The object's class, when given, is a header line `comment class <name>`
// (PLY has no other place for a per-file string that readers keep).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "u4d/util/file.h"

namespace open3d::geometry {
class TriangleMesh;
}

namespace u4d {

// Writes atomically (util/file.h WriteAtomically); every vertex gets `label`;
// a non-empty `class_name` is written as `comment class <class_name>`.
// Throws u4d::Error when the mesh has no vertex, a face index is out of range
// or the class name holds a line break.
void WriteLabelledMesh(const fs::path& path, const open3d::geometry::TriangleMesh& mesh, int label,
                       const std::string& class_name = "");
// As above with one label per vertex (labels.size() == vertices).
void WriteLabelledMesh(const fs::path& path, const open3d::geometry::TriangleMesh& mesh,
                       const std::vector<int>& labels, const std::string& class_name = "");

struct LabelledMesh {
  std::shared_ptr<open3d::geometry::TriangleMesh> mesh;  // colours/normals when in the file
  std::vector<int> labels;                               // per vertex; 0 when the file has none
  std::string class_name;  // from `comment class <name>`; empty when the file has none
};

// Reads a PLY with vertex x, y, z, optional nx ny nz, red green blue and
// label of any PLY scalar type, faces as a list (triangles; polygons are
// fanned), in ascii or binary_little_endian. Other properties are skipped.
// Throws u4d::Error naming the file on anything else or a truncated file.
LabelledMesh ReadLabelledMesh(const fs::path& path);

}  // namespace u4d
