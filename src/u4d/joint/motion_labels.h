// The discrete motion label set M of the joint optimisation (paper Sec. 2.1,
// "Motion constraints - E_f(m) and E_r(l,m)").
//
// The paper searches the flow m_p of every pixel p of the reference view
// between frames t and t+1 "within a window from a sparse constraint": the
// candidate motions are integer pixel offsets in a window around the
// displacements of the sparse temporal correspondences (features/
// temporal_tracks.h, feature and joint tracks) of that view. The displacements
// of all sparse correspondences are clustered (greedy, cluster_radius); the
// max_centres most-supported cluster centres, plus the zero motion, each
// contribute the (2 window + 1)^2 integer offsets around their rounded centre.
// The union, deduplicated, is the global label set M. Units: pixels at the
// working resolution of the images the costs are computed on.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "u4d/features/temporal_tracks.h"

namespace u4d {

// A sparse temporal correspondence of one view between frame t and t+1 (from
// features/temporal_tracks.h tracks, or projected joints): the pixel at t and
// the displacement to its position at t+1.
struct SparseMotion {
  Eigen::Vector2d pixel;         // (x, y) at frame t, pixel-centre origin
  Eigen::Vector2d displacement;  // position at t+1 minus pixel (pixels)
  int instance = 0;              // instance id of the track (0 = unknown); carried, not used by E_f
};

struct MotionLabelOptions {
  int window = 3;               // half-size (pixels, working resolution) of the window of motions
                                // around each sparse displacement (the paper's window)
  double cluster_radius = 1.0;  // sparse displacements closer than this (pixels) share one centre
  int max_centres = 12;         // most-supported displacement clusters kept as window centres
                                // (+ the zero motion always)
  double support_radius = 25;   // e_F^S: a pixel is "near" a sparse correspondence when within
                                // this distance (pixels)
  void Check() const;           // throws u4d::Error naming the bad field
};

// The global discrete motion label set M: integer-offset windows around the
// clustered sparse displacements (and around 0), deduplicated, as (dx, dy) in
// pixels at the working resolution. Deterministic: sorted by (dy, dx). The
// zero motion is always present. Throws u4d::Error on bad options or a
// non-finite sparse displacement.
std::vector<Eigen::Vector2f> BuildMotionLabels(const std::vector<SparseMotion>& sparse,
                                               const MotionLabelOptions& options);

// Sparse correspondences of view `view` from frame t to t+1 out of temporal
// tracks (features/temporal_tracks.h TemporalTrack, given by their points):
// every track with a point at both frames gives one SparseMotion. `scale`
// multiplies pixels and displacements (pixel-centre convention, as
// ScaledCamera) to reach the working resolution.
std::vector<SparseMotion> SparseMotionsFromTracks(const std::vector<TemporalTrack>& tracks,
                                                  int view, int frame_t, double scale = 1.0);

// Integer motion (dx, dy) -> its index in a label set M, over the bounding
// box of M's integer motions (non-integer motions are not indexed).
struct MotionLabelGrid {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  std::vector<int> index;  // w * h, -1 = no label
  explicit MotionLabelGrid(const std::vector<Eigen::Vector2f>& motions);
  // The label of the integer motion (fx, fy), or -1 (also for non-integers).
  int Find(float fx, float fy) const;
  // The label of the integer motion nearest to m, or -1.
  int Nearest(const Eigen::Vector2f& m) const;
};

}  // namespace u4d
