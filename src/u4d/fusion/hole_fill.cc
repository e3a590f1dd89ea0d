#include "u4d/fusion/hole_fill.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include <open3d/geometry/TriangleMesh.h>

#include "u4d/util/check.h"

namespace u4d {

namespace {

// Umbrella smoothing steps of a patch's new vertices.
constexpr int kSmoothingSteps = 60;
// Rings of a patch are this many border edge lengths apart. A patch holds no
// measured detail, and each of its vertices is one the scene flow can only
// interpolate (no view has depth there), so rings one edge apart raised the
// vertex drift of the coherent meshes several times more than these.
constexpr double kRingSpacingInEdges = 3;

// For each vertex, the vertices its boundary half-edges lead to, walking
// each hole so that the hole lies on the side opposite the triangle: an edge
// a -> b of one triangle only is the hole's b -> a.
std::vector<std::vector<int>> BorderSuccessors(const open3d::geometry::TriangleMesh& mesh) {
  // Undirected edge (the smaller vertex first, in 64 bits) -> its triangles.
  std::unordered_map<uint64_t, int> uses;
  const auto key = [](int a, int b) {
    return (static_cast<uint64_t>(std::min(a, b)) << 32) | static_cast<uint32_t>(std::max(a, b));
  };
  for (const Eigen::Vector3i& t : mesh.triangles_)
    for (int k = 0; k < 3; ++k) ++uses[key(t[k], t[(k + 1) % 3])];
  std::vector<std::vector<int>> next(mesh.vertices_.size());
  for (const Eigen::Vector3i& t : mesh.triangles_)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (uses[key(a, b)] == 1) next[b].push_back(a);
    }
  return next;
}

// The border's simple loops: each boundary half-edge is walked once; where
// the walk comes back to a vertex already on its path (two holes touching at
// a vertex, as a ragged trim leaves them), the loop closed there is split
// off and the walk goes on from that vertex.
std::vector<std::vector<int>> BorderLoops(const std::vector<std::vector<int>>& next) {
  std::vector<std::vector<int>> loops;
  std::vector<size_t> taken(next.size(), 0);  // successors walked, per vertex
  std::vector<int> on_path(next.size(), -1);  // position on the current path
  for (size_t start = 0; start < next.size(); ++start) {
    if (taken[start] == next[start].size()) continue;  // no border edge left here
    std::vector<int> path = {static_cast<int>(start)};
    on_path[start] = 0;
    int at = static_cast<int>(start);
    while (taken[at] < next[at].size()) {
      const int to = next[at][taken[at]++];
      if (on_path[to] < 0) {
        on_path[to] = static_cast<int>(path.size());
        path.push_back(to);
      } else {
        std::vector<int> loop(path.begin() + on_path[to], path.end());
        for (size_t i = 1; i < loop.size(); ++i) on_path[loop[i]] = -1;
        path.resize(on_path[to] + 1);
        if (loop.size() >= 3) loops.push_back(std::move(loop));
      }
      at = to;
    }
    for (const int v : path) on_path[v] = -1;
  }
  return loops;
}

// The patch's rings: ring 0 is the border, ring `rings` the centroid alone.
struct Patch {
  std::vector<std::vector<int>> rings;
  std::vector<Eigen::Vector3i> triangles;
};

// New vertices interpolated from the border towards its centroid (and their
// colours towards the border's mean colour), in `rings` - 1 rings and a
// centre.
Patch MakePatch(const std::vector<int>& border, const Eigen::Vector3d& centre, int rings,
                open3d::geometry::TriangleMesh* mesh) {
  Eigen::Vector3d colour = Eigen::Vector3d::Zero();
  const bool coloured = mesh->HasVertexColors();
  if (coloured)
    for (const int v : border) colour += mesh->vertex_colors_[v];
  colour /= border.size();
  auto add = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& c) {
    mesh->vertices_.push_back(p);
    if (coloured) mesh->vertex_colors_.push_back(c);
    if (mesh->HasVertexNormals()) mesh->vertex_normals_.push_back(Eigen::Vector3d::Zero());
    return static_cast<int>(mesh->vertices_.size()) - 1;
  };
  Patch patch;
  patch.rings.push_back(border);
  for (int k = 1; k < rings; ++k) {
    const double s = static_cast<double>(k) / rings;
    std::vector<int> ring;
    for (const int v : border) {
      const Eigen::Vector3d c = coloured ? mesh->vertex_colors_[v] : colour;
      ring.push_back(add((1 - s) * mesh->vertices_[v] + s * centre, (1 - s) * c + s * colour));
    }
    patch.rings.push_back(std::move(ring));
  }
  patch.rings.push_back({add(centre, colour)});
  return patch;
}

// Triangles between consecutive rings, oriented as the border's neighbours
// (the border runs b -> a where its triangle has a -> b).
void Triangulate(Patch* patch) {
  const size_t n = patch->rings[0].size();
  for (size_t k = 0; k + 1 < patch->rings.size(); ++k) {
    const std::vector<int>& outer = patch->rings[k];
    const std::vector<int>& inner = patch->rings[k + 1];
    for (size_t i = 0; i < n; ++i) {
      const size_t j = (i + 1) % n;
      if (inner.size() == 1) {
        patch->triangles.emplace_back(outer[i], outer[j], inner[0]);
        continue;
      }
      patch->triangles.emplace_back(outer[i], outer[j], inner[j]);
      patch->triangles.emplace_back(outer[i], inner[j], inner[i]);
    }
  }
}

// Umbrella smoothing of the patch's new vertices (all but ring 0), which
// are numbered from `first_new` on.
void Relax(const Patch& patch, int first_new, open3d::geometry::TriangleMesh* mesh) {
  const int n = static_cast<int>(mesh->vertices_.size()) - first_new;
  std::vector<std::vector<int>> neighbours(n);
  for (const Eigen::Vector3i& t : patch.triangles)
    for (int k = 0; k < 3; ++k) {
      if (t[k] < first_new) continue;
      neighbours[t[k] - first_new].push_back(t[(k + 1) % 3]);
      neighbours[t[k] - first_new].push_back(t[(k + 2) % 3]);
    }
  std::vector<Eigen::Vector3d> moved(n);
  for (int step = 0; step < kSmoothingSteps; ++step) {
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (const int u : neighbours[i]) sum += mesh->vertices_[u];
      moved[i] = sum / static_cast<double>(neighbours[i].size());
    }
    std::copy(moved.begin(), moved.end(), mesh->vertices_.begin() + first_new);
  }
}

// A border loop's centroid, the largest distance of its vertices from it and
// their mean edge length.
struct BorderShape {
  Eigen::Vector3d centre;
  double radius = 0, edge = 0;
};

BorderShape ShapeOf(const std::vector<int>& border, const open3d::geometry::TriangleMesh& mesh) {
  BorderShape shape{Eigen::Vector3d::Zero()};
  for (const int v : border) shape.centre += mesh.vertices_[v];
  shape.centre /= border.size();
  for (size_t i = 0; i < border.size(); ++i) {
    const Eigen::Vector3d& p = mesh.vertices_[border[i]];
    shape.radius = std::max(shape.radius, (p - shape.centre).norm());
    shape.edge += (mesh.vertices_[border[(i + 1) % border.size()]] - p).norm();
  }
  shape.edge /= border.size();
  return shape;
}

}  // namespace

int FillHoles(double max_radius, open3d::geometry::TriangleMesh* mesh) {
  U4D_CHECK(std::isfinite(max_radius) && max_radius >= 0,
            "FillHoles: max_radius must be finite and >= 0, found {}", max_radius);
  U4D_CHECK(mesh != nullptr, "FillHoles: no mesh given");
  if (max_radius == 0 || mesh->triangles_.empty()) return 0;
  int closed = 0;
  for (const std::vector<int>& border : BorderLoops(BorderSuccessors(*mesh))) {
    const BorderShape shape = ShapeOf(border, *mesh);
    if (shape.radius > max_radius) continue;
    const double spacing = std::max(kRingSpacingInEdges * shape.edge, 1e-12);
    const int rings = std::clamp(static_cast<int>(std::lround(shape.radius / spacing)), 1,
                                 static_cast<int>(border.size()));
    const int first_new = static_cast<int>(mesh->vertices_.size());
    Patch patch = MakePatch(border, shape.centre, rings, mesh);
    Triangulate(&patch);
    Relax(patch, first_new, mesh);
    mesh->triangles_.insert(mesh->triangles_.end(), patch.triangles.begin(), patch.triangles.end());
    ++closed;
  }
  if (mesh->HasTriangleNormals()) mesh->triangle_normals_.clear();
  return closed;
}

}  // namespace u4d
