#include "u4d/synth/contact.h"

#include <Eigen/Geometry>

#include "u4d/util/check.h"

namespace u4d::synth {

namespace {

Eigen::AlignedBox3f BoundsOf(const SurfaceMesh& mesh) {
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& v : mesh.vertices) box.extend(v);
  return box;
}

bool InContact(const SurfaceMesh& a, const SurfaceMesh& b, const Eigen::AlignedBox3f& near_b,
               double distance, int stride) {
  const float d2 = static_cast<float>(distance * distance);
  for (size_t i = 0; i < a.vertices.size(); i += stride) {
    if (!near_b.contains(a.vertices[i])) continue;
    for (size_t j = 0; j < b.vertices.size(); j += stride)
      if ((a.vertices[i] - b.vertices[j]).squaredNorm() < d2) return true;
  }
  return false;
}

}  // namespace

std::vector<std::pair<int, int>> PeopleInContact(const SceneFrame& frame, double distance,
                                                 int vertex_stride) {
  U4D_CHECK(distance > 0 && vertex_stride >= 1, "PeopleInContact: distance {} stride {}", distance,
            vertex_stride);
  std::vector<Eigen::AlignedBox3f> boxes;
  for (const SceneObject& p : frame.people) boxes.push_back(BoundsOf(p.mesh));
  std::vector<std::pair<int, int>> pairs;
  const Eigen::Vector3f pad = Eigen::Vector3f::Constant(static_cast<float>(distance));
  for (size_t a = 0; a < frame.people.size(); ++a)
    for (size_t b = a + 1; b < frame.people.size(); ++b) {
      const Eigen::AlignedBox3f near_b(boxes[b].min() - pad, boxes[b].max() + pad);
      if (!near_b.intersects(boxes[a])) continue;
      if (!InContact(frame.people[a].mesh, frame.people[b].mesh, near_b, distance, vertex_stride))
        continue;
      const int ia = frame.people[a].instance_id, ib = frame.people[b].instance_id;
      pairs.emplace_back(std::min(ia, ib), std::max(ia, ib));
    }
  return pairs;
}

}  // namespace u4d::synth
