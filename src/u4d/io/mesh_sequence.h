// Captured animated mesh sequences with a fixed topology: vertex i is the same
// surface point in every frame and the triangle list never changes. These are
// the formats animation tools export (docs/formats.md, "Mesh sequences"):
//
//  1. A folder of per-frame meshes, one file per frame: Wavefront OBJ
//     (`.obj`, or gzipped `.obj.gz`) or PLY (`.ply`, `.ply.gz`; ASCII or
//     binary). Frames are ordered by the numbers in the file names (natural
//     order: 2 before 10). Every mesh file name must contain a number, two
//     files must not carry the same number, and one folder holds one format;
//     other files (README, MANIFEST.tsv, ...) and sub-folders are ignored.
//  2. A template OBJ (faces and first positions, may be `.obj.gz`) plus a PC2
//     point cache holding every frame's positions (Blender / Maya / 3ds Max):
//     little-endian char[12] "POINTCACHE2\0", int32 version = 1, int32 number
//     of points, float32 start frame, float32 sample rate, int32 number of
//     samples, then float32 [samples][points][3] in the template's vertex
//     order. The frames come from the cache alone; the template gives faces
//     and colours.
//
// OBJ: `v x y z`, `v x y z w` (divided by w) or `v x y z r g b` (colour in
// [0, 1]); `f` with 1-based or negative (relative) indices, `a`, `a/t`,
// `a//n` or `a/t/n` corners; polygons with more than three corners are
// fan-triangulated (0 1 2, 0 2 3, ...). Other statements are ignored.
// PLY: element `vertex` with float/int properties x y z and optional
// red green blue (uchar 0..255 or float 0..1); element `face` with a list
// property `vertex_indices` (or `vertex_index`), fan-triangulated as OBJ.
//
// Positions are in the source's units (captured sequences rarely say which;
// see the data's SOURCE.txt) and axes, unchanged.
//
// Every reader throws u4d::Error naming the file and the problem: a missing
// or empty folder, a file that does not parse (with its line for OBJ), a
// truncated or corrupt gzip stream, a face index out of range, a non-finite
// coordinate, a frame whose vertex count or faces differ from the first
// frame's, a PC2 header that disagrees with the file size (checked before
// anything is allocated) or whose point count differs from the template's,
// and a frame selection that starts past the end of the sequence.
//
// Only the selected frames are read: a folder reader parses only the chosen
// files and the PC2 reader seeks to the chosen samples.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "u4d/util/file.h"

namespace u4d {

struct MeshSequence {
  // Triangles, 0-based vertex indices; the same in every frame.
  std::vector<Eigen::Vector3i> faces;
  // frames[k][i]: position of vertex i in the k-th selected frame, source units.
  std::vector<std::vector<Eigen::Vector3f>> frames;
  // Per-vertex RGB in [0, 1] when the source has colours (taken from the first
  // selected frame, or the template for PC2), else empty.
  std::vector<Eigen::Vector3f> colors;
  // source_frames[k]: the 0-based index in the whole source sequence of
  // frames[k] (first_frame + k * stride).
  std::vector<int> source_frames;
  // How many frames the source holds in all, selected or not.
  int source_frame_count = 0;

  int NumVertices() const { return frames.empty() ? 0 : static_cast<int>(frames[0].size()); }
};

// Which frames to read: source frames first_frame, first_frame + stride, ...
// up to max_frames of them.
struct MeshSequenceOptions {
  // 0-based index of the first frame to read; must be < the source's count.
  int first_frame = 0;
  // How many frames to read at most; -1 reads to the end.
  int max_frames = -1;
  // Read every stride-th frame; >= 1.
  int stride = 1;

  // Throws u4d::Error naming the field on first_frame < 0, max_frames == 0 or
  // < -1, stride < 1.
  void Check() const;
};

// `source` is a folder of per-frame OBJ / OBJ.gz / PLY files, a `.pc2` file
// (the template is the single *.obj or *.obj.gz beside it), or a folder that
// holds no per-frame meshes but exactly one `.pc2` (read the same way).
MeshSequence ReadMeshSequence(const fs::path& source, const MeshSequenceOptions& options = {});

// A folder of per-frame meshes (case 1 above).
MeshSequence ReadMeshFolder(const fs::path& folder, const MeshSequenceOptions& options = {});

// A template mesh (usually .obj or .obj.gz; any mesh file above is accepted)
// and a PC2 cache (case 2 above).
MeshSequence ReadPointCache(const fs::path& template_obj, const fs::path& pc2,
                            const MeshSequenceOptions& options = {});

// One mesh file (.obj, .obj.gz, .ply, .ply.gz) as a one-frame sequence;
// source_frames = {0}, source_frame_count = 1.
MeshSequence ReadMeshFile(const fs::path& path);

// The per-frame mesh files of `folder` in frame order, with the rules of
// case 1 above (throws on an empty folder, a name without a number, two files
// with the same number or mixed formats).
std::vector<fs::path> ListMeshFrameFiles(const fs::path& folder);

// The header of a PC2 file, checked against the file's size.
struct PointCacheHeader {
  int num_points = 0;
  int num_samples = 0;
  float start_frame = 0;
  float sample_rate = 1;
};
PointCacheHeader ReadPointCacheHeader(const fs::path& pc2);

// Writes a PC2 file (little-endian; start frame 0, sample rate 1); every frame
// must have the same number of points. For tests and exporters.
void WritePointCache(const fs::path& pc2, const std::vector<std::vector<Eigen::Vector3f>>& frames);

}  // namespace u4d
