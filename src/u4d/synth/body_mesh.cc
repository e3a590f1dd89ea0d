#include "u4d/synth/body_mesh.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

// One cross-section of a tube: an ellipse with half axes (ru, rv) centred at
// `axial` along the axis, shifted by (cu, cv) across it. ru = rv = 0 is a pole.
struct Ring {
  double axial, ru, rv, cu = 0, cv = 0;
};

struct Binding {
  int j0, j1;
  double w;
};

struct TubeSpec {
  int joint;
  BodyPart part;
  Eigen::Vector3d a, b;     // axis; rings are placed along a -> b (b may equal a: then `dir`)
  Eigen::Vector3d dir;      // axis direction (unit)
  Eigen::Vector3d u;        // first cross axis (made orthogonal to dir)
  std::vector<Ring> rings;  // first and last are poles
  int segments;
  std::function<Binding(const Eigen::Vector3d&, double)> bind;  // (rest point, axial)
  std::function<uint8_t(const Eigen::Vector3d&)> material;      // (face centroid, rest)
};

double Lerp(double a, double b, double t) { return a + (b - a) * t; }

double SmoothStep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// Piecewise-linear interpolation in a table of (x, y), x increasing.
double Table(const std::vector<std::pair<double, double>>& t, double x) {
  if (x <= t.front().first) return t.front().second;
  for (size_t i = 1; i < t.size(); ++i) {
    if (x <= t[i].first) {
      return Lerp(t[i - 1].second, t[i].second,
                  (x - t[i - 1].first) / (t[i].first - t[i - 1].first));
    }
  }
  return t.back().second;
}

// Capsule rings: a hemi-ellipsoidal cap of length cap_a at a, `mid` rings of
// linearly tapering radius (r(t) from `radius`) and a cap at b.
std::vector<Ring> CapsuleRings(double length, double cap_a, double cap_b, int caps, int mid,
                               const std::function<std::pair<double, double>(double)>& radius) {
  std::vector<Ring> rings;
  rings.push_back({-cap_a, 0, 0});
  const auto [ra_u, ra_v] = radius(0.0);
  for (int k = 1; k <= caps; ++k) {
    const double phi = 0.5 * M_PI * k / (caps + 0.0);
    rings.push_back({-cap_a * std::cos(phi), ra_u * std::sin(phi), ra_v * std::sin(phi)});
  }
  for (int k = 1; k < mid; ++k) {
    const double t = k / static_cast<double>(mid);
    const auto [ru, rv] = radius(t);
    rings.push_back({t * length, ru, rv});
  }
  const auto [rb_u, rb_v] = radius(1.0);
  for (int k = caps; k >= 1; --k) {
    const double phi = 0.5 * M_PI * k / (caps + 0.0);
    rings.push_back({length + cap_b * std::cos(phi), rb_u * std::sin(phi), rb_v * std::sin(phi)});
  }
  rings.push_back({length + cap_b, 0, 0});
  return rings;
}

void AddTube(const TubeSpec& spec, BodyMeshTemplate* body) {
  SurfaceMesh& m = body->rest;
  const Eigen::Vector3d d = spec.dir.normalized();
  const Eigen::Vector3d u = (spec.u - spec.u.dot(d) * d).normalized();
  const Eigen::Vector3d v = d.cross(u);  // (u, v, d) right-handed
  BodyTube tube;
  tube.joint = spec.joint;
  tube.part = spec.part;
  tube.a = spec.a;
  tube.b = spec.b;
  tube.first_vertex = static_cast<int>(m.vertices.size());
  tube.first_face = static_cast<int>(m.faces.size());
  const int n = spec.segments;
  const int num_rings = static_cast<int>(spec.rings.size());
  U4D_ASSERT(num_rings >= 3);
  // Vertex index of (ring r, segment k); poles have one vertex.
  std::vector<int> ring_start(num_rings);
  auto add_vertex = [&](const Eigen::Vector3d& x, double axial) {
    m.vertices.push_back(x.cast<float>());
    m.vertex_part.push_back(spec.part);
    const Binding b = spec.bind(x, axial);
    body->vertex_joints.push_back({static_cast<uint8_t>(b.j0), static_cast<uint8_t>(b.j1)});
    body->vertex_weight.push_back(static_cast<float>(b.w));
    // Distance to the axis segment, for BodyTube::max_radius.
    const Eigen::Vector3d ab = spec.b - spec.a;
    const double t =
        ab.squaredNorm() > 0 ? std::clamp((x - spec.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0;
    tube.max_radius = std::max(tube.max_radius, (x - (spec.a + t * ab)).norm());
  };
  for (int r = 0; r < num_rings; ++r) {
    const Ring& ring = spec.rings[r];
    ring_start[r] = static_cast<int>(m.vertices.size());
    const Eigen::Vector3d c = spec.a + ring.axial * d + ring.cu * u + ring.cv * v;
    if (r == 0 || r == num_rings - 1) {
      add_vertex(c, ring.axial);
      continue;
    }
    for (int k = 0; k < n; ++k) {
      const double al = 2 * M_PI * k / n;
      add_vertex(c + ring.ru * std::cos(al) * u + ring.rv * std::sin(al) * v, ring.axial);
    }
  }
  // Faces: CCW seen from outside. With (u, v, d) right-handed the triangle
  // (r,k), (r,k+1), (r+1,k) has its normal along the outward radial direction.
  auto add_face = [&](int i, int j, int k) { m.faces.emplace_back(i, j, k); };
  const int first = ring_start[1], last = ring_start[num_rings - 2];
  for (int k = 0; k < n; ++k) {
    const int k1 = (k + 1) % n;
    add_face(ring_start[0], first + k1, first + k);            // pole a
    add_face(ring_start[num_rings - 1], last + k, last + k1);  // pole b
  }
  for (int r = 1; r + 2 < num_rings; ++r) {
    const int s0 = ring_start[r], s1 = ring_start[r + 1];
    for (int k = 0; k < n; ++k) {
      const int k1 = (k + 1) % n;
      add_face(s0 + k, s0 + k1, s1 + k);
      add_face(s0 + k1, s1 + k1, s1 + k);
    }
  }
  for (size_t f = tube.first_face; f < m.faces.size(); ++f) {
    const Eigen::Vector3i& t = m.faces[f];
    const Eigen::Vector3d centroid =
        (m.vertices[t[0]] + m.vertices[t[1]] + m.vertices[t[2]]).cast<double>() / 3;
    m.face_material.push_back(spec.material(centroid));
  }
  tube.num_vertices = static_cast<int>(m.vertices.size()) - tube.first_vertex;
  tube.num_faces = static_cast<int>(m.faces.size()) - tube.first_face;
  body->tubes.push_back(tube);
}

// A limb: rigid on `joint`, blended with `parent_joint` near a and with
// `child_joint` near b (either may be -1).
Binding LimbBinding(int joint, int parent_joint, int child_joint, double length, double axial) {
  const double t = axial / length;
  if (child_joint >= 0 && t > 0.7) return {joint, child_joint, 0.5 * SmoothStep(0.7, 1.0, t)};
  if (parent_joint >= 0 && t < 0.3)
    return {joint, parent_joint, 0.5 * (1 - SmoothStep(0.0, 0.3, t))};
  return {joint, joint, 0.0};
}

Eigen::Vector3f Srgb(double r, double g, double b) {
  auto lin = [](double c) { return static_cast<float>(std::pow(c / 255.0, 2.2)); };
  return {lin(b), lin(g), lin(r)};  // BGR
}

}  // namespace

void BodyMeshOptions::Check() const {
  U4D_CHECK(ring_segments >= 6 && ring_segments <= 128,
            "BodyMeshOptions: ring_segments {} outside 6..128", ring_segments);
  U4D_CHECK(limb_rings >= 2 && limb_rings <= 64, "BodyMeshOptions: limb_rings {} outside 2..64",
            limb_rings);
  U4D_CHECK(cap_rings >= 1 && cap_rings <= 32, "BodyMeshOptions: cap_rings {} outside 1..32",
            cap_rings);
}

Appearance MakeAppearance(uint64_t seed) {
  std::mt19937_64 rng(seed * 0x2545F4914F6CDD1DULL + 12345);
  std::uniform_real_distribution<double> u01(0, 1);
  auto pick = [&](int n) { return static_cast<int>(std::min<double>(n - 1, u01(rng) * n)); };
  auto jitter = [&](Eigen::Vector3f c, double amount) {
    for (int i = 0; i < 3; ++i)
      c[i] = std::clamp<float>(c[i] * (1 + amount * (2 * u01(rng) - 1)), 0.f, 1.f);
    return c;
  };
  Appearance a;
  a.height = 1.60 + 0.30 * u01(rng);
  a.width = 0.90 + 0.22 * u01(rng);
  a.long_sleeves = u01(rng) < 0.5;
  const Eigen::Vector3f skins[5] = {Srgb(241, 194, 167), Srgb(224, 172, 130), Srgb(198, 134, 96),
                                    Srgb(141, 85, 54), Srgb(96, 60, 40)};
  const Eigen::Vector3f hairs[5] = {Srgb(25, 20, 18), Srgb(70, 45, 30), Srgb(120, 80, 45),
                                    Srgb(200, 170, 110), Srgb(150, 150, 150)};
  const Eigen::Vector3f shirts[8] = {Srgb(200, 40, 40),  Srgb(40, 90, 190),  Srgb(240, 240, 235),
                                     Srgb(40, 150, 70),  Srgb(240, 190, 40), Srgb(120, 50, 150),
                                     Srgb(240, 120, 30), Srgb(30, 30, 35)};
  const Eigen::Vector3f trousers[5] = {Srgb(40, 60, 110), Srgb(30, 30, 32), Srgb(170, 150, 110),
                                       Srgb(90, 90, 95), Srgb(80, 60, 40)};
  const uint32_t base_seed = static_cast<uint32_t>(rng());
  Material skin;
  skin.pattern = Material::Pattern::kNoise;
  skin.color_a = jitter(skins[pick(5)], 0.06);
  skin.color_b = skin.color_a * 0.82f;
  skin.scale = 0.02f;
  Material hair;
  hair.pattern = Material::Pattern::kNoise;
  hair.color_a = jitter(hairs[pick(5)], 0.1);
  hair.color_b = hair.color_a * 0.6f;
  hair.scale = 0.008f;
  const Material::Pattern shirt_patterns[4] = {
      Material::Pattern::kStripes, Material::Pattern::kChecker, Material::Pattern::kSpots,
      Material::Pattern::kNoise};
  Material shirt;
  shirt.pattern = shirt_patterns[pick(4)];
  const int sa = pick(8);
  int sb = pick(8);
  if (sb == sa) sb = (sa + 3) % 8;
  shirt.color_a = jitter(shirts[sa], 0.1);
  shirt.color_b = shirt.pattern == Material::Pattern::kNoise
                      ? Eigen::Vector3f(shirt.color_a * 0.45f)
                      : jitter(shirts[sb], 0.1);
  shirt.scale = static_cast<float>(0.04 + 0.08 * u01(rng));
  Material trouser;
  const Material::Pattern trouser_patterns[3] = {
      Material::Pattern::kNoise, Material::Pattern::kChecker, Material::Pattern::kStripes};
  trouser.pattern = trouser_patterns[pick(3)];
  trouser.color_a = jitter(trousers[pick(5)], 0.1);
  trouser.color_b = trouser.color_a * (trouser.pattern == Material::Pattern::kNoise ? 0.55f : 0.7f);
  trouser.scale = static_cast<float>(0.03 + 0.05 * u01(rng));
  Material shoes;
  shoes.pattern = Material::Pattern::kNoise;
  shoes.color_a = jitter(Srgb(45, 40, 38), 0.3);
  shoes.color_b = Srgb(200, 200, 200);
  shoes.scale = 0.03f;
  a.materials[kSkin] = skin;
  a.materials[kHair] = hair;
  a.materials[kShirt] = shirt;
  a.materials[kTrousers] = trouser;
  a.materials[kShoes] = shoes;
  for (int i = 0; i < kNumBodyMaterials; ++i) a.materials[i].seed = base_seed + 7919u * i;
  return a;
}

BodyMeshTemplate MakeBodyMesh(const BodyShape& shape, const Appearance& appearance,
                              const BodyMeshOptions& options) {
  options.Check();
  BodyMeshTemplate body;
  const Joints3d& r = shape.rest;
  const double s = shape.height / 1.75;
  const double w = s * shape.width;
  const int n = options.ring_segments;
  const int n_big = (3 * n / 2 + 1) / 2 * 2;
  auto constant = [](uint8_t mat) { return [mat](const Eigen::Vector3d&) { return mat; }; };

  // Limbs: (joint, child joint or end point, parent for blending, child for blending).
  struct Limb {
    int joint, end, blend_parent, blend_child;
    BodyPart part;
    double ra, rb;  // radii at the two ends (before scaling)
    uint8_t material;
  };
  const uint8_t forearm_mat = appearance.long_sleeves ? kShirt : kSkin;
  const Limb limbs[] = {
      {kRightHip, kRightKnee, kPelvis, kRightKnee, BodyPart::kThigh, 0.085, 0.058, kTrousers},
      {kLeftHip, kLeftKnee, kPelvis, kLeftKnee, BodyPart::kThigh, 0.085, 0.058, kTrousers},
      {kRightKnee, kRightAnkle, kRightHip, kRightAnkle, BodyPart::kShin, 0.058, 0.042, kTrousers},
      {kLeftKnee, kLeftAnkle, kLeftHip, kLeftAnkle, BodyPart::kShin, 0.058, 0.042, kTrousers},
      {kRightShoulder, kRightElbow, kThorax, kRightElbow, BodyPart::kUpperArm, 0.052, 0.04, kShirt},
      {kLeftShoulder, kLeftElbow, kThorax, kLeftElbow, BodyPart::kUpperArm, 0.052, 0.04, kShirt},
      {kRightElbow, kRightWrist, kRightShoulder, kRightWrist, BodyPart::kForearm, 0.04, 0.03,
       forearm_mat},
      {kLeftElbow, kLeftWrist, kLeftShoulder, kLeftWrist, BodyPart::kForearm, 0.04, 0.03,
       forearm_mat},
  };
  for (const Limb& limb : limbs) {
    TubeSpec t;
    t.joint = limb.joint;
    t.part = limb.part;
    t.a = r[limb.joint];
    t.b = r[limb.end];
    t.dir = (t.b - t.a).normalized();
    t.u = Eigen::Vector3d::UnitX();
    const double length = (t.b - t.a).norm();
    const double ra = limb.ra * std::sqrt(w * s), rb = limb.rb * std::sqrt(w * s);
    // Thighs are a little deeper than wide; arms a little flatter.
    const double depth = limb.part == BodyPart::kThigh ? 1.05 : 0.95;
    t.rings = CapsuleRings(length, 0.9 * ra, 0.9 * rb, options.cap_rings, options.limb_rings,
                           [&](double x) {
                             const double rr = Lerp(ra, rb, x) * (1 + 0.08 * std::sin(M_PI * x));
                             return std::make_pair(rr, rr * depth);
                           });
    t.segments = n;
    const Limb l = limb;
    t.bind = [l, length](const Eigen::Vector3d&, double axial) {
      return LimbBinding(l.joint, l.blend_parent, l.blend_child, length, axial);
    };
    t.material = constant(limb.material);
    AddTube(t, &body);
  }

  // Torso: elliptic sections from below the hips to the shoulders, bound to
  // pelvis / spine / thorax by height.
  {
    const double y0 = r[kPelvis].y() - 0.13 * s, y1 = r[kThorax].y() + 0.04 * s;
    const std::vector<std::pair<double, double>> half_width = {
        {0.80, 0.150}, {0.88, 0.165}, {0.98, 0.155}, {1.06, 0.135},
        {1.20, 0.150}, {1.32, 0.165}, {1.42, 0.185}, {1.46, 0.180}};
    const std::vector<std::pair<double, double>> half_depth = {
        {0.80, 0.095}, {0.88, 0.105}, {0.98, 0.100}, {1.06, 0.090},
        {1.20, 0.100}, {1.32, 0.105}, {1.42, 0.090}, {1.46, 0.085}};
    const std::vector<std::pair<double, double>> centre_z = {
        {0.80, -0.01}, {0.90, -0.015}, {1.06, 0.0}, {1.25, 0.01}, {1.46, -0.005}};
    TubeSpec t;
    t.joint = kSpine;
    t.part = BodyPart::kTorso;
    t.a = Eigen::Vector3d(0, y0, 0);
    t.b = Eigen::Vector3d(0, y1, 0);
    t.dir = Eigen::Vector3d::UnitY();
    t.u = Eigen::Vector3d::UnitZ();  // then v = y x z = x: u is depth, v is width
    const double length = y1 - y0;
    const int mid = 2 * options.limb_rings + 2;
    const int caps = options.cap_rings + 1;
    const double cap_bottom = 0.05 * s, cap_top = 0.045 * s;
    t.rings.push_back({-cap_bottom, 0, 0});
    auto section = [&](double axial, double shrink) {
      const double y = (y0 + axial) / s;
      return Ring{axial, shrink * Table(half_depth, y) * s, shrink * Table(half_width, y) * w,
                  Table(centre_z, y) * s, 0};
    };
    for (int k = 1; k <= caps; ++k) {
      const double phi = 0.5 * M_PI * k / caps;
      Ring ring = section(0, std::sin(phi));
      ring.axial = -cap_bottom * std::cos(phi);
      t.rings.push_back(ring);
    }
    for (int k = 1; k < mid; ++k) t.rings.push_back(section(length * k / mid, 1));
    for (int k = caps; k >= 1; --k) {
      const double phi = 0.5 * M_PI * k / caps;
      Ring ring = section(length, std::sin(phi));
      ring.axial = length + cap_top * std::cos(phi);
      t.rings.push_back(ring);
    }
    t.rings.push_back({length + cap_top, 0, 0, Table(centre_z, y1 / s) * s, 0});
    t.rings.front().cu = Table(centre_z, y0 / s) * s;
    t.segments = n_big;
    const double yp = r[kPelvis].y(), ys = r[kSpine].y(), yt = r[kThorax].y();
    t.bind = [yp, ys, yt](const Eigen::Vector3d& x, double) -> Binding {
      if (x.y() <= yp) return {kPelvis, kPelvis, 0};
      if (x.y() <= ys) {
        const double f = SmoothStep(yp, ys, x.y());
        return f < 0.5 ? Binding{kPelvis, kSpine, f} : Binding{kSpine, kPelvis, 1 - f};
      }
      if (x.y() <= yt) {
        const double f = SmoothStep(ys, yt, x.y());
        return f < 0.5 ? Binding{kSpine, kThorax, f} : Binding{kThorax, kSpine, 1 - f};
      }
      return {kThorax, kThorax, 0};
    };
    const double waist = r[kPelvis].y() + 0.08 * s;
    t.material = [waist](const Eigen::Vector3d& c) -> uint8_t {
      return c.y() > waist ? kShirt : kTrousers;
    };
    AddTube(t, &body);
  }

  // Neck: thorax -> head base, skin.
  {
    TubeSpec t;
    t.joint = kNeck;
    t.part = BodyPart::kHead;
    t.a = r[kThorax] + Eigen::Vector3d(0, 0.02 * s, -0.01 * s);
    t.b = r[kNeck] + Eigen::Vector3d(0, 0.05 * s, -0.012 * s);
    t.dir = (t.b - t.a).normalized();
    t.u = Eigen::Vector3d::UnitX();
    const double length = (t.b - t.a).norm();
    const double rn = 0.052 * s;
    t.rings = CapsuleRings(length, 0.6 * rn, 0.6 * rn, options.cap_rings, 3,
                           [&](double) { return std::make_pair(rn * shape.width, rn); });
    t.segments = n;
    t.bind = [length](const Eigen::Vector3d&, double axial) -> Binding {
      const double f = 0.5 * (1 - SmoothStep(0.2 * length, 0.8 * length, axial));
      return {kNeck, kThorax, f};
    };
    t.material = constant(kSkin);
    AddTube(t, &body);
  }

  // Head: an ellipsoid on the neck segment; hair on top and at the back.
  {
    const Eigen::Vector3d c = shape.rest_head_centre;
    const Eigen::Vector3d rad = shape.head_radii;
    TubeSpec t;
    t.joint = kNeck;
    t.part = BodyPart::kHead;
    t.a = c;
    t.b = c;
    t.dir = Eigen::Vector3d::UnitY();
    t.u = Eigen::Vector3d::UnitZ();  // v = y x z = x
    const int rings = (n_big / 2) + 1;
    for (int k = 0; k <= rings; ++k) {
      const double th = M_PI * k / rings;
      // Slightly flattened chin: the lower half is narrower.
      const double narrow = th > 0.5 * M_PI ? 1.0 : 1.0 - 0.12 * std::cos(th);
      t.rings.push_back({-rad.y() * std::cos(th), rad.z() * std::sin(th) * narrow,
                         rad.x() * std::sin(th) * narrow});
    }
    t.segments = n_big;
    t.bind = [](const Eigen::Vector3d&, double) { return Binding{kNeck, kNeck, 0}; };
    t.material = [c, rad](const Eigen::Vector3d& x) -> uint8_t {
      const Eigen::Vector3d q = (x - c).cwiseQuotient(rad);
      const bool top = q.y() > 0.35 - 0.25 * std::max(0.0, -q.z());
      const bool back = q.z() < -0.35 && q.y() > -0.45;
      return (top || back) ? kHair : kSkin;
    };
    AddTube(t, &body);
  }

  // Hands: flattened, wider front to back; on the wrist segment.
  for (int side = 0; side < 2; ++side) {
    const int wrist = side == 0 ? kRightWrist : kLeftWrist;
    const int elbow = side == 0 ? kRightElbow : kLeftElbow;
    TubeSpec t;
    t.joint = wrist;
    t.part = BodyPart::kHand;
    t.a = r[wrist];
    t.b = shape.rest_hand_tip[side];
    t.dir = (t.b - t.a).normalized();
    t.u = Eigen::Vector3d::UnitZ();
    const double length = (t.b - t.a).norm();
    t.rings = {{-0.01 * s, 0, 0},
               {0.0, 0.026 * s, 0.018 * s},
               {0.25 * length, 0.040 * s, 0.016 * s},
               {0.50 * length, 0.044 * s, 0.015 * s},
               {0.75 * length, 0.038 * s, 0.012 * s},
               {0.92 * length, 0.028 * s, 0.010 * s},
               {length, 0, 0}};
    t.segments = std::max(8, n / 2 * 2 - 4);
    t.bind = [wrist, elbow](const Eigen::Vector3d&, double axial) -> Binding {
      return {wrist, elbow, axial < 0.02 ? 0.3 : 0.0};
    };
    t.material = constant(kSkin);
    AddTube(t, &body);
  }

  // Feet: heel to toe along the floor, flat bottom at the floor in rest.
  for (int side = 0; side < 2; ++side) {
    const int ankle = side == 0 ? kRightAnkle : kLeftAnkle;
    const int knee = side == 0 ? kRightKnee : kLeftKnee;
    TubeSpec t;
    t.joint = ankle;
    t.part = BodyPart::kFoot;
    t.a = shape.rest_heel[side];
    t.b = shape.rest_toe[side];
    t.dir = (t.b - t.a).normalized();
    t.u = Eigen::Vector3d::UnitX();  // v = z x x = y (up)
    const double length = (t.b - t.a).norm();
    const std::vector<std::pair<double, double>> width = {{0.0, 0.02}, {0.06, 0.036}, {0.3, 0.04},
                                                          {0.7, 0.05}, {0.9, 0.042},  {1.0, 0.02}};
    const std::vector<std::pair<double, double>> height = {
        {0.0, 0.02}, {0.06, 0.045}, {0.3, 0.065}, {0.6, 0.04}, {0.9, 0.025}, {1.0, 0.015}};
    t.rings.push_back({0, 0, 0});
    const int steps = options.limb_rings + 3;
    for (int k = 0; k <= steps; ++k) {
      const double x = 0.02 + 0.96 * k / steps;
      const double hv = Table(height, x) * s;
      t.rings.push_back({x * length, Table(width, x) * w, hv, 0, hv});
    }
    t.rings.push_back({length, 0, 0, 0, 0.012 * s});
    t.segments = n;
    t.bind = [ankle, knee](const Eigen::Vector3d& x, double) -> Binding {
      return {ankle, knee, x.y() > 0.09 ? 0.25 : 0.0};
    };
    t.material = constant(kShoes);
    AddTube(t, &body);
  }

  // Texture coordinates are the rest positions.
  body.rest.texcoords = body.rest.vertices;
  return body;
}

void PoseBodyMesh(const BodyMeshTemplate& body, const BodyShape& shape, const BodyPose& pose,
                  SurfaceMesh* mesh) {
  std::array<Rigid3d, kNumJoints> t;
  for (int j = 0; j < kNumJoints; ++j) t[j] = SegmentTransform(shape, pose, j);
  mesh->texcoords = body.rest.texcoords;
  mesh->faces = body.rest.faces;
  mesh->face_material = body.rest.face_material;
  mesh->vertex_part = body.rest.vertex_part;
  const size_t n = body.rest.vertices.size();
  mesh->vertices.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d x = body.rest.vertices[i].cast<double>();
    const auto& j = body.vertex_joints[i];
    const double w = body.vertex_weight[i];
    Eigen::Vector3d y = t[j[0]] * x;
    if (w > 0) y = (1 - w) * y + w * (t[j[1]] * x);
    mesh->vertices[i] = y.cast<float>();
  }
}

}  // namespace u4d::synth
