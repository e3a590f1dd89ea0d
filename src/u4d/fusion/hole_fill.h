// Closing the holes that trimming leaves in a fused surface (docs/fusion.md,
// "Trimming", step 6).
//
// Screened Poisson returns a closed surface; the trims (silhouette_trim.h,
// the distance trim of depth_fusion.h) cut away what the views say is not
// the object, and leave a hole with a ragged border where they cut: a person
// without the top of the head, soles or the parts of the back no view saw in
// depth. A studio wants a closed surface. Each hole is closed by a membrane spanned over its
// border: rings of new vertices between the border and its centroid, relaxed by umbrella
// (Laplacian) smoothing with the border fixed, so that the patch is the smooth surface the border
// bounds (flat for a flat border) and meets the mesh without a seam. The patch is made of the
// border's own vertices and new ones only; nothing of the mesh moves.
//
// A hole is a loop of boundary edges (edges of exactly one triangle); where
// two holes touch at a vertex (a ragged trim leaves many such), the border is
// split there into simple loops, each closed on its own. Holes whose border
// lies farther than `max_radius` from its centroid stay open: a border that
// wide runs between parts of a body (the inner sides of two legs whose
// Poisson bridge was trimmed), and a membrane across it would put the bridge
// back. The patch's triangles are oriented as their neighbours across the
// border; its vertices take the border's colours, blended towards their
// mean. Normals are not updated (the caller computes them).
#pragma once

namespace open3d::geometry {
class TriangleMesh;
}

namespace u4d {

// Closes the holes of `mesh` whose border lies within `max_radius` (mesh
// units, metres for the fused meshes) of the border's centroid; returns how
// many were closed. `max_radius` 0 closes none. Throws u4d::Error when
// `max_radius` is negative or not finite or `mesh` is null.
int FillHoles(double max_radius, open3d::geometry::TriangleMesh* mesh);

}  // namespace u4d
