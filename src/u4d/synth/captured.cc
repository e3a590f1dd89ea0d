#include "u4d/synth/captured.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "u4d/synth/body_mesh.h"
#include "u4d/util/check.h"

namespace u4d::synth {

namespace {

// Height bands of a standing person, as fractions of the stature from the
// floor: the top of each band.
constexpr double kShoeTop = 0.05;
constexpr double kShinTop = 0.27;
constexpr double kTrouserTop = 0.47;
constexpr double kHeadBottom = 0.87;
// A headless source's top is this fraction of the stature.
constexpr double kHeadlessTop = kHeadBottom;

BodyPart PartAtHeight(double h) {
  if (h < kShoeTop) return BodyPart::kFoot;
  if (h < kShinTop) return BodyPart::kShin;
  if (h < kTrouserTop) return BodyPart::kThigh;
  if (h < kHeadBottom) return BodyPart::kTorso;
  return BodyPart::kHead;
}

uint8_t MaterialAtHeight(double h) {
  if (h < kShoeTop) return kShoes;
  if (h < kTrouserTop) return kTrousers;
  if (h < kHeadBottom) return kShirt;
  return kSkin;
}

// Source frames [first, first + count) (fewer when the source ends first).
MeshSequence ReadFrames(const fs::path& source, int first, int count) {
  MeshSequenceOptions o;
  o.first_frame = first;
  o.max_frames = count;
  return ReadMeshSequence(source, o);
}

// The similarity that stands the first frame on the floor at the options'
// place: world = yaw * (scale * (x - anchor)) + (position.x, 0, position.y).
struct Placement {
  double scale = 1;
  Eigen::Vector3f anchor = Eigen::Vector3f::Zero();  // footprint centre, floor level
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();
  Eigen::Vector3f offset = Eigen::Vector3f::Zero();
  Eigen::Vector3f Apply(const Eigen::Vector3f& x) const {
    return rotation * (static_cast<float>(scale) * (x - anchor)) + offset;
  }
};

Placement PlaceFirstFrame(const std::vector<Eigen::Vector3f>& first,
                          const CapturedPerformerOptions& o) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f hi = -lo;
  for (const Eigen::Vector3f& v : first) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const double extent = hi.y() - lo.y();
  U4D_CHECK(extent > 0, "captured performer {}: the first frame has no height", o.source.string());
  Placement p;
  p.scale = o.stature * (o.source_has_head ? 1.0 : kHeadlessTop) / extent;
  p.anchor = Eigen::Vector3f(0.5f * (lo.x() + hi.x()), lo.y(), 0.5f * (lo.z() + hi.z()));
  p.rotation = Eigen::AngleAxisf(static_cast<float>(o.yaw), Eigen::Vector3f::UnitY()).matrix();
  p.offset =
      Eigen::Vector3f(static_cast<float>(o.position.x()), 0, static_cast<float>(o.position.y()));
  return p;
}

// Rest surface: faces, texcoords (first frame, world), materials and parts by
// height band.
SurfaceMesh RestSurface(const std::vector<Eigen::Vector3f>& world_first,
                        const std::vector<Eigen::Vector3i>& faces, double stature) {
  SurfaceMesh rest;
  rest.vertices = world_first;
  rest.texcoords = world_first;
  rest.faces = faces;
  rest.vertex_part.reserve(world_first.size());
  for (const Eigen::Vector3f& v : world_first)
    rest.vertex_part.push_back(PartAtHeight(v.y() / stature));
  rest.face_material.reserve(faces.size());
  for (const Eigen::Vector3i& f : faces) {
    const double y = (world_first[f[0]].y() + world_first[f[1]].y() + world_first[f[2]].y()) / 3;
    rest.face_material.push_back(MaterialAtHeight(y / stature));
  }
  return rest;
}

}  // namespace

void CapturedPerformerOptions::Check() const {
  U4D_CHECK(!source.empty(), "captured performer: source is empty");
  U4D_CHECK(std::isfinite(stature) && stature > 0.5 && stature < 2.5,
            "captured performer {}: stature must be 0.5-2.5 m, got {}", source.string(), stature);
  U4D_CHECK(first_frame >= 0, "captured performer {}: first_frame must be >= 0, got {}",
            source.string(), first_frame);
  U4D_CHECK(frame_step >= 1, "captured performer {}: frame_step must be >= 1, got {}",
            source.string(), frame_step);
  U4D_CHECK(position.allFinite() && std::isfinite(yaw),
            "captured performer {}: position and yaw must be finite", source.string());
}

int CapturedSourceFrame(int first_frame, int frame_step, int length, int frame) {
  U4D_CHECK(length >= 1 && frame >= 0, "CapturedSourceFrame: length {} frame {}", length, frame);
  if (length == 1) return 0;
  const int period = 2 * (length - 1);
  const int s = (first_frame + frame * frame_step) % period;
  return s < length ? s : period - s;
}

CapturedPerformer LoadCapturedPerformer(const CapturedPerformerOptions& options, int num_frames) {
  options.Check();
  U4D_CHECK(num_frames >= 1, "captured performer: num_frames must be >= 1, got {}", num_frames);
  const int span = (num_frames - 1) * options.frame_step + 1;
  MeshSequence seq = ReadFrames(options.source, options.first_frame, span);
  const int length = seq.source_frame_count;
  int lo = options.first_frame;
  for (int f = 0; f < num_frames; ++f)
    lo = std::min(lo, CapturedSourceFrame(options.first_frame, options.frame_step, length, f));
  if (lo < options.first_frame) {  // the ping-pong comes back below first_frame
    MeshSequence before = ReadFrames(options.source, lo, options.first_frame - lo);
    before.frames.insert(before.frames.end(), seq.frames.begin(), seq.frames.end());
    seq.frames = std::move(before.frames);
  }

  CapturedPerformer out;
  out.first_frame = options.first_frame;
  out.frame_step = options.frame_step;
  const auto& first = seq.frames[options.first_frame - lo];
  const Placement place = PlaceFirstFrame(first, options);
  for (size_t k = 0; k < seq.frames.size(); ++k) {
    out.source_frames.push_back(lo + static_cast<int>(k));
    std::vector<Eigen::Vector3f> world;
    world.reserve(seq.frames[k].size());
    for (const Eigen::Vector3f& v : seq.frames[k]) world.push_back(place.Apply(v));
    out.vertices.push_back(std::move(world));
  }
  out.source_length = length;
  out.rest = RestSurface(out.vertices[options.first_frame - lo], seq.faces, options.stature);
  const Appearance appearance = MakeAppearance(options.appearance_seed);
  out.materials.assign(appearance.materials.begin(), appearance.materials.end());
  return out;
}

SceneObject PoseCapturedPerformer(const CapturedPerformer& performer, int frame, int instance_id) {
  const int s = CapturedSourceFrame(performer.first_frame, performer.frame_step,
                                    performer.source_length, frame);
  const int k = s - performer.source_frames.front();
  U4D_CHECK(k >= 0 && k < static_cast<int>(performer.vertices.size()),
            "captured performer: frame {} needs source frame {}, not loaded", frame, s);
  SceneObject o;
  o.instance_id = instance_id;
  o.label = "person";
  o.mesh = performer.rest;
  o.mesh.vertices = performer.vertices[k];
  o.materials = performer.materials;
  return o;
}

double PlaceAtClosestApproach(const CapturedPerformer& a, CapturedPerformer* b,
                              const Eigen::Vector2d& direction, double gap, int num_frames,
                              int vertex_stride) {
  U4D_CHECK(direction.allFinite() && std::abs(direction.norm() - 1) < 1e-6,
            "PlaceAtClosestApproach: direction must be a unit vector");
  U4D_CHECK(vertex_stride >= 1 && num_frames >= 1, "PlaceAtClosestApproach: bad stride or frames");
  const Eigen::Vector3f dir(static_cast<float>(direction.x()), 0,
                            static_cast<float>(direction.y()));
  // The smallest offset t along dir such that, in every frame, every sampled
  // pair (p of a, q of b) has |q + t dir - p| >= gap; for one pair that is
  // t >= s + sqrt(gap^2 - |r_perp|^2) with r = p - q, s = r . dir.
  double need = -std::numeric_limits<double>::infinity();
  for (int f = 0; f < num_frames; ++f) {
    const SceneObject pa = PoseCapturedPerformer(a, f, 1);
    const SceneObject pb = PoseCapturedPerformer(*b, f, 2);
    for (size_t i = 0; i < pa.mesh.vertices.size(); i += vertex_stride) {
      for (size_t j = 0; j < pb.mesh.vertices.size(); j += vertex_stride) {
        const Eigen::Vector3f r = pa.mesh.vertices[i] - pb.mesh.vertices[j];
        const double s = r.dot(dir);
        const double perp2 = r.squaredNorm() - s * s;
        if (perp2 >= gap * gap) continue;
        need = std::max(need, s + std::sqrt(gap * gap - perp2));
      }
    }
  }
  if (!std::isfinite(need)) return 0;  // no sampled pair ever lines up along `direction`
  for (auto& frame : b->vertices)
    for (Eigen::Vector3f& v : frame) v += static_cast<float>(need) * dir;
  for (Eigen::Vector3f& v : b->rest.vertices) v += static_cast<float>(need) * dir;
  return need;
}

}  // namespace u4d::synth
