#include "u4d/synth/props.h"

#include <cmath>

#include <Eigen/Geometry>

#include "u4d/synth/environment.h"
#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

constexpr double kGripM = 0.07;  // from the wrist down to the top of what the hand holds

// A box from (-x/2, -y, -z/2) to (x/2, 0, z/2): its top centre at the origin.
SurfaceMesh BoxMesh(const Eigen::Vector3f& size) {
  const Eigen::Vector3f lo(-size.x() / 2, -size.y(), -size.z() / 2);
  const Eigen::Vector3f hi(size.x() / 2, 0, size.z() / 2);
  auto corner = [&](int i) {
    return Eigen::Vector3f(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                           i & 4 ? hi.z() : lo.z());
  };
  SurfaceMesh mesh;
  // Corners of each face, counter-clockwise seen from outside.
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : faces)
    AddQuad(mesh, corner(q[0]), corner(q[1]), corner(q[2]), corner(q[3]), 0);
  return mesh;
}

// A UV sphere of `radius` about the origin, shared vertices (smooth shading).
SurfaceMesh BallMesh(float radius) {
  constexpr int kRings = 12, kSegments = 24;
  SurfaceMesh mesh;
  for (int i = 0; i <= kRings; ++i) {
    const double theta = M_PI * i / kRings;
    for (int j = 0; j < kSegments; ++j) {
      const double phi = 2 * M_PI * j / kSegments;
      const Eigen::Vector3f p(static_cast<float>(radius * std::sin(theta) * std::cos(phi)),
                              static_cast<float>(radius * std::cos(theta)),
                              static_cast<float>(radius * std::sin(theta) * std::sin(phi)));
      mesh.vertices.push_back(p);
      mesh.texcoords.push_back(p);
    }
  }
  auto at = [](int i, int j) { return i * kSegments + (j % kSegments); };
  for (int i = 0; i < kRings; ++i) {
    for (int j = 0; j < kSegments; ++j) {
      mesh.faces.emplace_back(at(i, j), at(i, j + 1), at(i + 1, j + 1));
      mesh.faces.emplace_back(at(i, j), at(i + 1, j + 1), at(i + 1, j));
    }
  }
  mesh.face_material.assign(mesh.faces.size(), 0);
  return mesh;
}

// The holder's horizontal frame: columns forward, up, side (towards the
// holding hand), from the hips.
Eigen::Matrix3d HolderFrame(const Joints3d& joints, bool left_hand) {
  Eigen::Vector3d side = joints[kLeftHip] - joints[kRightHip];
  if (!left_hand) side = -side;
  side.y() = 0;
  side = side.norm() > 1e-6 ? Eigen::Vector3d(side.normalized()) : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  Eigen::Matrix3d frame;
  frame << up.cross(side), up, side;
  return frame;
}

Material PropMaterial(const PropOptions& o) {
  Material m;
  m.seed = o.seed;
  if (o.kind == PropOptions::Kind::kCarriedBox) {
    m.pattern = Material::Pattern::kStripes;
    m.color_a = {0.25f, 0.45f, 0.62f};  // cardboard (BGR)
    m.color_b = {0.15f, 0.30f, 0.45f};
    m.scale = 0.08f;
  } else {
    m.pattern = Material::Pattern::kSpots;
    m.color_a = {0.10f, 0.35f, 0.85f};  // orange (BGR)
    m.color_b = {0.05f, 0.05f, 0.08f};
    m.scale = 0.07f;
  }
  return m;
}

// Moves the rest mesh by `rotation` then `translation`.
void Place(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation, SurfaceMesh* mesh) {
  const Eigen::Matrix3f r = rotation.cast<float>();
  const Eigen::Vector3f t = translation.cast<float>();
  for (Eigen::Vector3f& v : mesh->vertices) v = r * v + t;
}

SceneObject PoseBox(const PropOptions& o, const Joints3d& joints) {
  SceneObject obj;
  obj.mesh = BoxMesh(o.size.cast<float>());
  const Eigen::Matrix3d frame = HolderFrame(joints, o.left_hand);
  const Eigen::Vector3d wrist = joints[o.left_hand ? kLeftWrist : kRightWrist];
  // The hand holds the top's centre; the box hangs a little outwards so that
  // its inner face clears the thigh.
  const Eigen::Vector3d top =
      wrist - Eigen::Vector3d(0, kGripM, 0) + 0.3 * o.size.z() * frame.col(2);
  Place(frame, top, &obj.mesh);
  return obj;
}

SceneObject PoseBall(const PropOptions& o, const Joints3d& joints, double time) {
  SceneObject obj;
  const double radius = 0.5 * o.size.x();
  obj.mesh = BallMesh(static_cast<float>(radius));
  const Eigen::Matrix3d frame = HolderFrame(joints, o.left_hand);
  const Eigen::Vector3d wrist = joints[o.left_hand ? kLeftWrist : kRightWrist];
  const double phase = time / o.period_s - std::floor(time / o.period_s);
  const double q = std::abs(2 * phase - 1);  // 1 at the hand, 0 at the floor
  const double top = std::max(radius, wrist.y() - kGripM - radius);
  const double y = radius + (top - radius) * (2 * q - q * q);
  const Eigen::Vector3d centre(wrist.x(), y, wrist.z());
  const Eigen::Matrix3d spin =
      Eigen::AngleAxisd(2 * M_PI * phase, frame.col(2)).toRotationMatrix() * frame;
  Place(spin, centre + 0.5 * radius * frame.col(2), &obj.mesh);
  return obj;
}

}  // namespace

std::string PropOptions::Label() const {
  if (!label.empty()) return label;
  return kind == Kind::kCarriedBox ? "box" : "ball";
}

void PropOptions::Check() const {
  U4D_CHECK(size.allFinite() && size.minCoeff() > 0.01 && size.maxCoeff() < 2.0,
            "synth: a prop's size must be in (0.01, 2) m, got {} {} {}", size.x(), size.y(),
            size.z());
  U4D_CHECK(std::isfinite(period_s) && period_s > 0.05,
            "synth: a ball's bounce period must be above 0.05 s, got {}", period_s);
  U4D_CHECK(holder >= 0, "synth: a prop's holder must be a person index >= 0, got {}", holder);
  U4D_CHECK(Label() != "person" && Label() != "background", "synth: a prop's class cannot be '{}'",
            Label());
}

std::vector<PropOptions> PropsFromNames(const std::vector<std::string>& names) {
  std::vector<PropOptions> out;
  for (const std::string& name : names) {
    U4D_CHECK(name == "box" || name == "ball", "synth: unknown prop '{}' (known: box, ball)", name);
    PropOptions o;
    o.holder = static_cast<int>(out.size());
    o.seed = 11 + static_cast<uint32_t>(out.size());
    if (name == "ball") {
      o.kind = PropOptions::Kind::kDribbledBall;
      o.size = {0.24, 0.24, 0.24};
    }
    out.push_back(o);
  }
  return out;
}

std::vector<SceneObject> PoseProps(const std::vector<PropOptions>& props, const SceneFrame& frame,
                                   int first_id) {
  std::vector<SceneObject> out;
  for (const PropOptions& o : props) {
    o.Check();
    U4D_CHECK(o.holder < static_cast<int>(frame.joints.size()),
              "synth: prop '{}' is held by person {}, but only {} people have a skeleton",
              o.Label(), o.holder, frame.joints.size());
    const Joints3d& joints = frame.joints[o.holder];
    SceneObject obj = o.kind == PropOptions::Kind::kCarriedBox ? PoseBox(o, joints)
                                                               : PoseBall(o, joints, frame.time);
    obj.instance_id = first_id + static_cast<int>(out.size());
    obj.label = o.Label();
    obj.materials = {PropMaterial(o)};
    out.push_back(std::move(obj));
  }
  return out;
}

}  // namespace u4d::synth
