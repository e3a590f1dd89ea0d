// Vertex drift of the temporally coherent meshes (paper Sec. 3, 4D temporal
// coherence) against the ground truth's vertex identities.
//
// A segment (segments/<kk>/<id>.glb, fusion/gltf.h) is one mesh whose
// vertices move through the frames first_frame, first_frame + 1, ... The
// synthetic ground truth's meshes (gt/meshes/<id>/<frame>.ply) keep their
// vertex order in every frame, so a vertex of the segment can be followed on
// the true surface: at the segment's first frame each segment vertex i is
// matched to its nearest GT vertex m(i) of the GT person the segment is
// matched to (the one with the smallest median vertex distance); at frame k
// its drift is
//     | p_k(i) - (g_k(m(i)) + p_0(i) - g_0(m(i))) |,
// the distance from where the true surface point carried the vertex (its
// offset from the surface at the first frame kept). Vertices farther than
// `max_match_distance` from the GT surface at the first frame are
// reconstruction errors, not drift, and are left out (counted).
// For scale, the same median for a mesh that does not move at all, i.e. the
// true motion | g_k(m(i)) - g_0(m(i)) |, is reported beside it.
#pragma once

#include <vector>

#include <nlohmann/json.hpp>

#include "u4d/eval/silhouette.h"
#include "u4d/io/scene_index.h"
#include "u4d/util/file.h"

namespace u4d::eval {

struct DriftOptions {
  // Metres: a segment vertex farther than this from every vertex of its GT
  // person at the first frame is not followed (a fusion error, not drift).
  double max_match_distance = 0.05;
  void Check() const;
};

struct SegmentDrift {
  int segment = 0;    // index of segments/<kk>
  int object_id = 0;  // the scene's object
  int gt_id = 0;      // the GT person it was matched to (0: none)
  int first_frame = 0;
  int vertices = 0;  // in the segment mesh
  int followed = 0;  // within max_match_distance of the GT surface
  // Per frame of the segment (index 0 = first frame, where both are 0):
  // median drift and median true motion over the followed vertices, metres.
  std::vector<double> median_drift;
  std::vector<double> median_motion;
};

struct DriftReport {
  std::vector<SegmentDrift> segments;
  // Over segments with at least two frames: the median drift and the median
  // true motion at each segment's last frame (metres), averaged.
  RatioMean last_frame_drift, last_frame_motion;
  // The same per frame offset k (k = 1, 2, ...), averaged over segments long
  // enough to have it.
  std::vector<RatioMean> drift_at, motion_at;
  nlohmann::json ToJson() const;
};

// Reads the scene's segments (scene.json's "segments" and their .glb files)
// and the GT meshes under <capture_root>/gt/meshes. Throws u4d::Error naming
// the file when a listed .glb or a needed GT mesh is missing or corrupt.
// Segments whose object matches no GT mesh get gt_id 0 and no drift.
DriftReport EvaluateSegmentDrift(const fs::path& capture_root, const fs::path& scene_dir,
                                 const DriftOptions& options = {});

}  // namespace u4d::eval
