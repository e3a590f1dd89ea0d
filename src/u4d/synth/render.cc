#include "u4d/synth/render.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "u4d/synth/texture.h"
#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

constexpr int kMaxObjects = 65534;

// The frame's objects in `object` value order (people, then statics), with
// smooth vertex normals, shared by all views of a frame.
struct PreparedFrame {
  std::vector<const SceneObject*> objects;  // objects[value - 1]
  std::vector<std::vector<Eigen::Vector3f>> normals;
  int num_people = 0;
};

PreparedFrame Prepare(const SceneFrame& frame) {
  PreparedFrame p;
  p.num_people = static_cast<int>(frame.people.size());
  for (const SceneObject& o : frame.people) p.objects.push_back(&o);
  for (const SceneObject& o : frame.statics) p.objects.push_back(&o);
  p.normals.resize(p.objects.size());
  tbb::parallel_for(size_t{0}, p.objects.size(), [&](size_t i) {
    const SurfaceMesh& mesh = p.objects[i]->mesh;
    std::vector<Eigen::Vector3f>& n = p.normals[i];
    n.assign(mesh.vertices.size(), Eigen::Vector3f::Zero());
    for (const Eigen::Vector3i& f : mesh.faces) {
      const Eigen::Vector3f c = (mesh.vertices[f[1]] - mesh.vertices[f[0]])
                                    .cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]);
      for (int k = 0; k < 3; ++k) n[f[k]] += c;
    }
    for (Eigen::Vector3f& v : n) {
      const float len = v.norm();
      if (len > 0) v /= len;
    }
  });
  return p;
}

uint32_t MixSeed(uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33;
  return static_cast<uint32_t>(h);
}

uint32_t StreamSeed(uint32_t seed, int view, double time, uint32_t salt) {
  const uint64_t t = static_cast<uint64_t>(std::llround(time * 1e6));
  return MixSeed(seed * 0x9e3779b97f4a7c15ULL ^ MixSeed(t + 0x1234567ULL * (view + 1)) ^
                 (static_cast<uint64_t>(salt) << 40));
}

// Target buffers of the rasteriser. Coverage-only mode writes `coverage` and
// ignores the rest.
struct Buffers {
  int width = 0, height = 0;
  float* depth = nullptr;
  uint16_t* object = nullptr;
  int32_t* face = nullptr;
  float* bary = nullptr;
  uint8_t* coverage = nullptr;
};

struct Intrinsics {
  double fx, skew, cx, fy, cy;
};

struct ClipVertex {
  Eigen::Vector3d p;     // camera frame
  Eigen::Vector3d bary;  // with respect to the original triangle
};

// One directed edge with a canonical reference vertex so that the edge function
// is exactly antisymmetric between the two triangles sharing the edge.
struct Edge {
  double rx, ry, dx, dy, sign;
  bool owns_ties;
  void Init(double ax, double ay, double bx, double by) {
    const bool a_first = ax < bx || (ax == bx && ay < by);
    if (a_first) {
      rx = ax, ry = ay, dx = bx - ax, dy = by - ay, sign = 1;
    } else {
      rx = bx, ry = by, dx = ax - bx, dy = ay - by, sign = -1;
    }
    // Top-left rule for positively oriented triangles: the edge a -> b is a
    // left edge when it goes up (dy < 0) and a top edge when horizontal, going right.
    const double ey = by - ay, ex = bx - ax;
    owns_ties = ey < 0 || (ey == 0 && ex > 0);
  }
  double operator()(double px, double py) const { return sign * (dx * (py - ry) - dy * (px - rx)); }
  bool Inside(double e) const { return e > 0 || (e == 0 && owns_ties); }
};

template <bool kCoverageOnly>
void RasterTriangle(const ClipVertex* v, const Intrinsics& in, bool cull, uint16_t object_value,
                    int32_t face_index, Buffers& buf) {
  double sx[3], sy[3], iz[3];
  for (int k = 0; k < 3; ++k) {
    iz[k] = 1.0 / v[k].p.z();
    const double nx = v[k].p.x() * iz[k], ny = v[k].p.y() * iz[k];
    sx[k] = in.fx * nx + in.skew * ny + in.cx;
    sy[k] = in.fy * ny + in.cy;
  }
  int order[3] = {0, 1, 2};
  Edge probe;
  probe.Init(sx[0], sy[0], sx[1], sy[1]);
  const double area = probe(sx[2], sy[2]);
  if (!(std::abs(area) > 0)) return;  // degenerate or NaN
  if (area < 0) {
    if (cull) return;
    std::swap(order[1], order[2]);
  }
  const int i0 = order[0], i1 = order[1], i2 = order[2];
  Edge e0, e1, e2;  // opposite vertex i0, i1, i2
  e0.Init(sx[i1], sy[i1], sx[i2], sy[i2]);
  e1.Init(sx[i2], sy[i2], sx[i0], sy[i0]);
  e2.Init(sx[i0], sy[i0], sx[i1], sy[i1]);
  const double min_x = std::min({sx[0], sx[1], sx[2]}), max_x = std::max({sx[0], sx[1], sx[2]});
  const double min_y = std::min({sy[0], sy[1], sy[2]}), max_y = std::max({sy[0], sy[1], sy[2]});
  const int x0 = static_cast<int>(std::max(0.0, std::ceil(min_x)));
  const int x1 = static_cast<int>(std::min<double>(buf.width - 1, std::floor(max_x)));
  const int y0 = static_cast<int>(std::max(0.0, std::ceil(min_y)));
  const int y1 = static_cast<int>(std::min<double>(buf.height - 1, std::floor(max_y)));
  for (int y = y0; y <= y1; ++y) {
    const size_t row = static_cast<size_t>(y) * buf.width;
    for (int x = x0; x <= x1; ++x) {
      const double a0 = e0(x, y);
      if (!e0.Inside(a0)) continue;
      const double a1 = e1(x, y);
      if (!e1.Inside(a1)) continue;
      const double a2 = e2(x, y);
      if (!e2.Inside(a2)) continue;
      const size_t idx = row + x;
      if constexpr (kCoverageOnly) {
        buf.coverage[idx] = 1;
      } else {
        const double sum = a0 + a1 + a2;
        const double w0 = a0 / sum * iz[i0], w1 = a1 / sum * iz[i1], w2 = a2 / sum * iz[i2];
        const double inv_z = w0 + w1 + w2;
        const float z = static_cast<float>(1.0 / inv_z);
        if (!(z < buf.depth[idx])) continue;
        buf.depth[idx] = z;
        buf.object[idx] = object_value;
        buf.face[idx] = face_index;
        const Eigen::Vector3d b = (w0 * v[i0].bary + w1 * v[i1].bary + w2 * v[i2].bary) / inv_z;
        buf.bary[2 * idx] = static_cast<float>(b[1]);
        buf.bary[2 * idx + 1] = static_cast<float>(b[2]);
      }
    }
  }
}

// Clips every face of `mesh` (vertices already in the camera frame) against
// the near plane and rasterises it.
template <bool kCoverageOnly>
void RasterObject(const std::vector<Eigen::Vector3d>& cam_vertices, const SurfaceMesh& mesh,
                  const Intrinsics& in, double near, bool cull, uint16_t object_value,
                  Buffers& buf) {
  static const Eigen::Vector3d kUnit[3] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                           Eigen::Vector3d::UnitZ()};
  for (size_t fi = 0; fi < mesh.faces.size(); ++fi) {
    const Eigen::Vector3i& f = mesh.faces[fi];
    ClipVertex tri[3];
    int num_in_front = 0;
    for (int k = 0; k < 3; ++k) {
      tri[k] = {cam_vertices[f[k]], kUnit[k]};
      num_in_front += tri[k].p.z() >= near;
    }
    if (num_in_front == 0) continue;
    if (num_in_front == 3) {
      RasterTriangle<kCoverageOnly>(tri, in, cull, object_value, static_cast<int32_t>(fi), buf);
      continue;
    }
    // Sutherland-Hodgman against z >= near: at most 4 vertices.
    ClipVertex poly[4];
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      const ClipVertex& a = tri[k];
      const ClipVertex& b = tri[(k + 1) % 3];
      const bool a_in = a.p.z() >= near, b_in = b.p.z() >= near;
      if (a_in) poly[n++] = a;
      if (a_in != b_in) {
        const double t = (near - a.p.z()) / (b.p.z() - a.p.z());
        poly[n++] = {a.p + t * (b.p - a.p), a.bary + t * (b.bary - a.bary)};
        poly[n - 1].p.z() = near;
      }
    }
    for (int k = 1; k + 1 < n; ++k) {
      const ClipVertex fan[3] = {poly[0], poly[k], poly[k + 1]};
      RasterTriangle<kCoverageOnly>(fan, in, cull, object_value, static_cast<int32_t>(fi), buf);
    }
  }
}

std::vector<Eigen::Vector3d> ToCamera(const Camera& camera, const SurfaceMesh& mesh) {
  std::vector<Eigen::Vector3d> out(mesh.vertices.size());
  for (size_t i = 0; i < out.size(); ++i)
    out[i] = camera.cam_from_world * mesh.vertices[i].cast<double>();
  return out;
}

float ViewGain(const RenderOptions& o, int view, double time) {
  if (o.gain_jitter == 0) return o.gain;
  const uint32_t h = StreamSeed(o.noise_seed, view, 0.0, 7);
  const float u = static_cast<float>(h >> 8) / 16777216.0f * 2 - 1;
  return o.gain * (1 + o.gain_jitter * u);
}

// Linear shaded colour (albedo times light, before gain, gamma and noise) of
// the surface point (face, b1, b2) of object `oi`, seen at depth `depth`.
Eigen::Vector3f ShadeLinear(const PreparedFrame& prep, int oi, int face, float b1, float b2,
                            float depth, const Eigen::Vector3f& center,
                            const Eigen::Vector3f& light, double fx, const RenderOptions& o) {
  const SceneObject& obj = *prep.objects[oi];
  const SurfaceMesh& mesh = obj.mesh;
  const Eigen::Vector3i& f = mesh.faces[face];
  const float b0 = 1 - b1 - b2;
  const Eigen::Vector3f point =
      b0 * mesh.vertices[f[0]] + b1 * mesh.vertices[f[1]] + b2 * mesh.vertices[f[2]];
  const Eigen::Vector3f tc =
      b0 * mesh.texcoords[f[0]] + b1 * mesh.texcoords[f[1]] + b2 * mesh.texcoords[f[2]];
  const std::vector<Eigen::Vector3f>& vn = prep.normals[oi];
  Eigen::Vector3f normal = b0 * vn[f[0]] + b1 * vn[f[1]] + b2 * vn[f[2]];
  if (normal.squaredNorm() < 1e-12f)
    normal = (mesh.vertices[f[1]] - mesh.vertices[f[0]])
                 .cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]);
  normal.normalize();
  Eigen::Vector3f to_eye = center - point;
  to_eye.normalize();
  float facing = normal.dot(to_eye);
  if (facing < 0) {
    normal = -normal;
    facing = -facing;
  }
  const float footprint =
      o.texture_filtering ? static_cast<float>(depth / fx) / std::max(facing, 0.25f) : 0;
  const size_t mi = mesh.face_material.empty() ? 0 : mesh.face_material[face];
  const Eigen::Vector3f albedo = EvaluateMaterial(obj.materials[mi], tc, footprint);
  const float lambert = std::max(0.0f, normal.dot(light));
  return albedo * (o.ambient + o.light_intensity * lambert);
}

// Rasterises objects [first, last) of `prep` into `out`'s id buffers.
void RasterRange(const Camera& camera, const PreparedFrame& prep, int first, int last,
                 const RenderOptions& o, RenderedView* out,
                 std::vector<std::vector<Eigen::Vector3d>>* cam_vertices) {
  Buffers buf;
  buf.width = camera.width;
  buf.height = camera.height;
  buf.depth = out->depth.ptr<float>();
  buf.object = out->object.ptr<uint16_t>();
  buf.face = out->face.ptr<int32_t>();
  buf.bary = out->barycentric.ptr<float>();
  const Intrinsics in{camera.K(0, 0), camera.K(0, 1), camera.K(0, 2), camera.K(1, 1),
                      camera.K(1, 2)};
  cam_vertices->resize(prep.objects.size());
  for (int i = first; i < last; ++i) {
    (*cam_vertices)[i] = ToCamera(camera, prep.objects[i]->mesh);
    RasterObject<false>((*cam_vertices)[i], prep.objects[i]->mesh, in, o.near_plane,
                        o.cull_back_faces, static_cast<uint16_t>(i + 1), buf);
  }
}

void InitIdBuffers(int w, int h, RenderedView* out) {
  out->depth = cv::Mat(h, w, CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity()));
  out->object = cv::Mat(h, w, CV_16UC1, cv::Scalar(0));
  out->face = cv::Mat(h, w, CV_32SC1, cv::Scalar(-1));
  out->barycentric = cv::Mat(h, w, CV_32FC2, cv::Scalar(0, 0));
}

bool SameCamera(const Camera& a, const Camera& b) {
  return a.width == b.width && a.height == b.height && a.K == b.K && a.dist == b.dist &&
         a.cam_from_world.rotation == b.cam_from_world.rotation &&
         a.cam_from_world.translation == b.cam_from_world.translation;
}

RenderedView RenderPrepared(const Camera& camera, const SceneFrame& frame,
                            const PreparedFrame& prep, const RenderOptions& o, int view_index,
                            const StaticLayer* layer) {
  const int w = camera.width, h = camera.height;
  RenderedView out;
  std::vector<std::vector<Eigen::Vector3d>> cam_vertices;
  if (layer != nullptr) {
    U4D_CHECK(SameCamera(layer->camera, camera),
              "RenderView: the static layer was rendered for another camera");
    U4D_CHECK(layer->num_statics == frame.statics.size(),
              "RenderView: the static layer has {} static objects, the frame {}",
              layer->num_statics, frame.statics.size());
    out.depth = layer->depth.clone();
    out.face = layer->face.clone();
    out.barycentric = layer->barycentric.clone();
    // Layer values are 1 + static index; in this frame statics follow the people.
    out.object = cv::Mat(h, w, CV_16UC1);
    layer->object.forEach<uint16_t>([&](const uint16_t& v, const int* pos) {
      out.object.at<uint16_t>(pos[0], pos[1]) =
          v == 0 ? 0 : static_cast<uint16_t>(v + prep.num_people);
    });
    RasterRange(camera, prep, 0, prep.num_people, o, &out, &cam_vertices);
  } else {
    InitIdBuffers(w, h, &out);
    RasterRange(camera, prep, 0, static_cast<int>(prep.objects.size()), o, &out, &cam_vertices);
  }

  // Deferred shading and the id maps.
  out.instance = cv::Mat(h, w, CV_16UC1, cv::Scalar(0));
  out.part = cv::Mat(h, w, CV_8UC1, cv::Scalar(0));
  cv::Mat color_f(h, w, CV_32FC3, cv::Scalar(0, 0, 0));
  const Eigen::Vector3f light = (-o.light_direction.normalized()).cast<float>();
  const Eigen::Vector3f center = camera.Center().cast<float>();
  const float gain = ViewGain(o, view_index, frame.time);
  // Gamma encoding by table: linear [0, 1] in kGammaSteps steps, interpolated.
  constexpr int kGammaSteps = 1024;
  std::array<float, kGammaSteps + 2> gamma_table;
  for (int i = 0; i <= kGammaSteps + 1; ++i)
    gamma_table[i] =
        255.0f * std::pow(std::min(1.0f, static_cast<float>(i) / kGammaSteps), 1.0f / o.gamma);
  const double fx = camera.K(0, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 16), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      float* depth = out.depth.ptr<float>(y);
      const uint16_t* object = out.object.ptr<uint16_t>(y);
      const int32_t* face = out.face.ptr<int32_t>(y);
      const float* bary = out.barycentric.ptr<float>(y);
      uint16_t* instance = out.instance.ptr<uint16_t>(y);
      uint8_t* part = out.part.ptr<uint8_t>(y);
      cv::Vec3f* color = color_f.ptr<cv::Vec3f>(y);
      const cv::Vec3f* cached = layer != nullptr ? layer->shade.ptr<cv::Vec3f>(y) : nullptr;
      for (int x = 0; x < w; ++x) {
        if (object[x] == 0) {
          depth[x] = 0;
          continue;
        }
        const int oi = object[x] - 1;
        const float b1 = bary[2 * x], b2 = bary[2 * x + 1];
        Eigen::Vector3f lin;
        if (oi < prep.num_people) {
          const SceneObject& obj = *prep.objects[oi];
          instance[x] = static_cast<uint16_t>(obj.instance_id);
          if (!obj.mesh.vertex_part.empty()) {
            const float b0 = 1 - b1 - b2;
            const Eigen::Vector3i& f = obj.mesh.faces[face[x]];
            const int k = (b0 >= b1 && b0 >= b2) ? 0 : (b1 >= b2 ? 1 : 2);
            part[x] = static_cast<uint8_t>(obj.mesh.vertex_part[f[k]]);
          }
        }
        if (cached != nullptr && oi >= prep.num_people) {
          lin = Eigen::Vector3f(cached[x][0], cached[x][1], cached[x][2]);
        } else {
          lin = ShadeLinear(prep, oi, face[x], b1, b2, depth[x], center, light, fx, o);
        }
        for (int c = 0; c < 3; ++c) {
          const float s = std::clamp(lin[c] * gain, 0.0f, 1.0f) * kGammaSteps;
          const int i = static_cast<int>(s);
          color[x][c] = gamma_table[i] + (s - i) * (gamma_table[i + 1] - gamma_table[i]);
        }
      }
    }
  });
  if (o.noise_sigma > 0) {
    cv::Mat noise(h, w, CV_32FC3);
    cv::RNG rng(StreamSeed(o.noise_seed, view_index, frame.time, 1));
    rng.fill(noise, cv::RNG::NORMAL, 0.0, o.noise_sigma);
    color_f += noise;
  }
  color_f.convertTo(out.color, CV_8UC3);

  if (o.compute_visibility) {
    const Intrinsics in{camera.K(0, 0), camera.K(0, 1), camera.K(0, 2), camera.K(1, 1),
                        camera.K(1, 2)};
    cv::Mat coverage(h, w, CV_8UC1);
    Buffers cov;
    cov.width = w;
    cov.height = h;
    cov.coverage = coverage.ptr<uint8_t>();
    for (int k = 0; k < prep.num_people; ++k) {
      coverage.setTo(0);
      RasterObject<true>(cam_vertices[k], prep.objects[k]->mesh, in, o.near_plane,
                         o.cull_back_faces, 0, cov);
      VisibilityStats s;
      s.instance_id = prep.objects[k]->instance_id;
      s.amodal_pixels = cv::countNonZero(coverage);
      s.visible_pixels = cv::countNonZero(out.object == k + 1);
      out.visibility.push_back(s);
    }
  }
  return out;
}

void CheckMesh(const SceneObject& o, const std::string& what) {
  const SurfaceMesh& m = o.mesh;
  const size_t nv = m.vertices.size();
  U4D_CHECK(m.texcoords.size() == nv, "{}: {} texcoords for {} vertices", what, m.texcoords.size(),
            nv);
  U4D_CHECK(m.vertex_part.empty() || m.vertex_part.size() == nv,
            "{}: {} vertex parts for {} vertices", what, m.vertex_part.size(), nv);
  U4D_CHECK(m.face_material.empty() || m.face_material.size() == m.faces.size(),
            "{}: {} face materials for {} faces", what, m.face_material.size(), m.faces.size());
  U4D_CHECK(!o.materials.empty() || m.faces.empty(), "{}: has faces but no materials", what);
  for (const Eigen::Vector3f& v : m.vertices)
    U4D_CHECK(v.allFinite(), "{}: non-finite vertex", what);
  for (size_t i = 0; i < m.faces.size(); ++i)
    for (int k = 0; k < 3; ++k)
      U4D_CHECK(m.faces[i][k] >= 0 && static_cast<size_t>(m.faces[i][k]) < nv,
                "{}: face {} uses vertex {} but there are {} vertices", what, i, m.faces[i][k], nv);
  for (uint8_t mi : m.face_material)
    U4D_CHECK(mi < o.materials.size(), "{}: face material {} but {} materials", what, mi,
              o.materials.size());
  for (const Material& mat : o.materials)
    U4D_CHECK(std::isfinite(mat.scale) && mat.scale > 0, "{}: material scale must be > 0, got {}",
              what, mat.scale);
}

}  // namespace

void RenderOptions::Check() const {
  U4D_CHECK(light_direction.allFinite() && light_direction.norm() > 0,
            "RenderOptions: light_direction must be a non-zero finite vector");
  U4D_CHECK(light_intensity >= 0 && ambient >= 0 && std::isfinite(light_intensity) &&
                std::isfinite(ambient),
            "RenderOptions: light_intensity and ambient must be >= 0, got {} and {}",
            light_intensity, ambient);
  U4D_CHECK(std::isfinite(gain) && gain > 0, "RenderOptions: gain must be > 0, got {}", gain);
  U4D_CHECK(gain_jitter >= 0 && gain_jitter < 1,
            "RenderOptions: gain_jitter must be in [0, 1), got {}", gain_jitter);
  U4D_CHECK(std::isfinite(gamma) && gamma > 0, "RenderOptions: gamma must be > 0, got {}", gamma);
  U4D_CHECK(std::isfinite(noise_sigma) && noise_sigma >= 0,
            "RenderOptions: noise_sigma must be >= 0, got {}", noise_sigma);
  U4D_CHECK(std::isfinite(near_plane) && near_plane > 0,
            "RenderOptions: near_plane must be > 0, got {}", near_plane);
}

void FlowOptions::Check() const {
  U4D_CHECK(depth_tolerance >= 0 && relative_depth_tolerance >= 0,
            "FlowOptions: tolerances must be >= 0, got {} and {}", depth_tolerance,
            relative_depth_tolerance);
}

void CheckSceneFrame(const SceneFrame& frame) {
  U4D_CHECK(frame.people.size() + frame.statics.size() <= static_cast<size_t>(kMaxObjects),
            "scene frame: {} objects, at most {} supported",
            frame.people.size() + frame.statics.size(), kMaxObjects);
  for (size_t i = 0; i < frame.people.size(); ++i) {
    U4D_CHECK(frame.people[i].instance_id >= 1 && frame.people[i].instance_id <= 65535,
              "scene frame: person {} has instance_id {}, expected 1..65535", i,
              frame.people[i].instance_id);
    CheckMesh(frame.people[i], fmt::format("scene frame: person {}", i));
  }
  for (size_t i = 0; i < frame.statics.size(); ++i)
    CheckMesh(frame.statics[i], fmt::format("scene frame: static object {}", i));
}

ObjectRef DecodeObject(const SceneFrame& frame, int value) {
  const int np = static_cast<int>(frame.people.size());
  const int ns = static_cast<int>(frame.statics.size());
  U4D_CHECK(value >= 0 && value <= np + ns,
            "object id {} out of range: the frame has {} people and {} static objects", value, np,
            ns);
  if (value == 0) return {};
  if (value <= np) return {true, value - 1};
  return {false, value - 1 - np};
}

const SceneObject* FindObject(const SceneFrame& frame, int value) {
  const ObjectRef r = DecodeObject(frame, value);
  if (r.index < 0) return nullptr;
  return r.is_person ? &frame.people[r.index] : &frame.statics[r.index];
}

RenderedView RenderView(const Camera& camera, const SceneFrame& frame, const RenderOptions& options,
                        int view_index, const StaticLayer* layer) {
  options.Check();
  camera.Check("RenderView camera");
  U4D_CHECK(
      !camera.HasDistortion(),
      "RenderView: the camera has lens distortion; the rasteriser supports pinhole cameras only");
  CheckSceneFrame(frame);
  return RenderPrepared(camera, frame, Prepare(frame), options, view_index, layer);
}

std::vector<RenderedView> RenderViews(const std::vector<Camera>& cameras, const SceneFrame& frame,
                                      const RenderOptions& options,
                                      const std::vector<StaticLayer>* layers) {
  U4D_CHECK(layers == nullptr || layers->size() == cameras.size(),
            "RenderViews: {} static layers for {} cameras", layers ? layers->size() : 0,
            cameras.size());
  options.Check();
  for (size_t v = 0; v < cameras.size(); ++v) {
    cameras[v].Check(fmt::format("RenderViews camera {}", v));
    U4D_CHECK(
        !cameras[v].HasDistortion(),
        "RenderViews: camera {} has lens distortion; the rasteriser supports pinhole cameras only",
        v);
  }
  CheckSceneFrame(frame);
  const PreparedFrame prep = Prepare(frame);
  std::vector<RenderedView> views(cameras.size());
  tbb::parallel_for(size_t{0}, cameras.size(), [&](size_t v) {
    views[v] = RenderPrepared(cameras[v], frame, prep, options, static_cast<int>(v),
                              layers != nullptr ? &(*layers)[v] : nullptr);
  });
  return views;
}

StaticLayer RenderStaticLayer(const Camera& camera, const std::vector<SceneObject>& statics,
                              const RenderOptions& options) {
  options.Check();
  camera.Check("RenderStaticLayer camera");
  U4D_CHECK(!camera.HasDistortion(),
            "RenderStaticLayer: the camera has lens distortion; pinhole cameras only");
  SceneFrame frame;
  frame.statics = statics;
  CheckSceneFrame(frame);
  const PreparedFrame prep = Prepare(frame);
  RenderedView ids;
  InitIdBuffers(camera.width, camera.height, &ids);
  std::vector<std::vector<Eigen::Vector3d>> cam_vertices;
  RasterRange(camera, prep, 0, static_cast<int>(prep.objects.size()), options, &ids, &cam_vertices);
  StaticLayer layer;
  layer.camera = camera;
  layer.num_statics = statics.size();
  layer.depth = ids.depth;
  layer.object = ids.object;
  layer.face = ids.face;
  layer.barycentric = ids.barycentric;
  layer.shade = cv::Mat(camera.height, camera.width, CV_32FC3, cv::Scalar(0, 0, 0));
  const Eigen::Vector3f light = (-options.light_direction.normalized()).cast<float>();
  const Eigen::Vector3f center = camera.Center().cast<float>();
  tbb::parallel_for(0, camera.height, [&](int y) {
    const uint16_t* object = layer.object.ptr<uint16_t>(y);
    const int32_t* face = layer.face.ptr<int32_t>(y);
    const float* bary = layer.barycentric.ptr<float>(y);
    const float* depth = layer.depth.ptr<float>(y);
    cv::Vec3f* shade = layer.shade.ptr<cv::Vec3f>(y);
    for (int x = 0; x < camera.width; ++x) {
      if (object[x] == 0) continue;
      const Eigen::Vector3f lin =
          ShadeLinear(prep, object[x] - 1, face[x], bary[2 * x], bary[2 * x + 1], depth[x], center,
                      light, camera.K(0, 0), options);
      shade[x] = cv::Vec3f(lin[0], lin[1], lin[2]);
    }
  });
  return layer;
}

std::vector<StaticLayer> RenderStaticLayers(const std::vector<Camera>& cameras,
                                            const std::vector<SceneObject>& statics,
                                            const RenderOptions& options) {
  std::vector<StaticLayer> layers(cameras.size());
  tbb::parallel_for(size_t{0}, cameras.size(),
                    [&](size_t v) { layers[v] = RenderStaticLayer(cameras[v], statics, options); });
  return layers;
}

namespace {

Eigen::Vector3d SurfacePoint(const SurfaceMesh& mesh, int face, double b1, double b2) {
  const Eigen::Vector3i& f = mesh.faces[face];
  return (1 - b1 - b2) * mesh.vertices[f[0]].cast<double>() +
         b1 * mesh.vertices[f[1]].cast<double>() + b2 * mesh.vertices[f[2]].cast<double>();
}

void CheckView(const RenderedView& v, const Camera& c, const char* what) {
  U4D_CHECK(v.object.type() == CV_16UC1 && v.face.type() == CV_32SC1 &&
                v.barycentric.type() == CV_32FC2 && v.depth.type() == CV_32FC1,
            "ForwardFlow: {} is not a RenderedView (wrong or missing buffers)", what);
  U4D_CHECK(v.object.cols == c.width && v.object.rows == c.height,
            "ForwardFlow: {} is {}x{} but its camera is {}x{}", what, v.object.cols, v.object.rows,
            c.width, c.height);
}

}  // namespace

FlowField ForwardFlow(const RenderedView& view_t, const SceneFrame& frame_t,
                      const SceneFrame& frame_t1, const Camera& camera_t, const Camera& camera_t1,
                      const RenderedView& view_t1, const FlowOptions& options) {
  options.Check();
  camera_t.Check("ForwardFlow camera_t");
  camera_t1.Check("ForwardFlow camera_t1");
  CheckView(view_t, camera_t, "view_t");
  CheckView(view_t1, camera_t1, "view_t1");
  U4D_CHECK(frame_t.people.size() == frame_t1.people.size() &&
                frame_t.statics.size() == frame_t1.statics.size(),
            "ForwardFlow: frames differ in objects ({}+{} vs {}+{} people+statics)",
            frame_t.people.size(), frame_t.statics.size(), frame_t1.people.size(),
            frame_t1.statics.size());
  const int num_objects = static_cast<int>(frame_t.people.size() + frame_t.statics.size());
  for (int v = 1; v <= num_objects; ++v) {
    const SurfaceMesh& a = FindObject(frame_t, v)->mesh;
    const SurfaceMesh& b = FindObject(frame_t1, v)->mesh;
    U4D_CHECK(a.vertices.size() == b.vertices.size() && a.faces.size() == b.faces.size(),
              "ForwardFlow: object {} changes its mesh between frames ({} -> {} vertices, {} -> {} "
              "faces); vertex identity must be stable",
              v, a.vertices.size(), b.vertices.size(), a.faces.size(), b.faces.size());
  }
  const int w = camera_t.width, h = camera_t.height;
  FlowField out;
  out.flow = cv::Mat(h, w, CV_32FC2, cv::Scalar(0, 0));
  out.valid = cv::Mat(h, w, CV_8UC1, cv::Scalar(0));
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 16), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      const uint16_t* object = view_t.object.ptr<uint16_t>(y);
      const int32_t* face = view_t.face.ptr<int32_t>(y);
      const cv::Vec2f* bary = view_t.barycentric.ptr<cv::Vec2f>(y);
      cv::Vec2f* flow = out.flow.ptr<cv::Vec2f>(y);
      uint8_t* valid = out.valid.ptr<uint8_t>(y);
      for (int x = 0; x < w; ++x) {
        if (object[x] == 0) continue;
        const SceneObject* obj_t = FindObject(frame_t, object[x]);
        const SceneObject* obj_t1 = FindObject(frame_t1, object[x]);
        U4D_CHECK(face[x] >= 0 && static_cast<size_t>(face[x]) < obj_t->mesh.faces.size(),
                  "ForwardFlow: view_t names face {} of object {} which has {} faces", face[x],
                  object[x], obj_t->mesh.faces.size());
        const Eigen::Vector3d x_t = SurfacePoint(obj_t->mesh, face[x], bary[x][0], bary[x][1]);
        const Eigen::Vector3d x_t1 = SurfacePoint(obj_t1->mesh, face[x], bary[x][0], bary[x][1]);
        const Eigen::Vector2d p0 = camera_t.Project(x_t);
        const Eigen::Vector2d p1 = camera_t1.Project(x_t1);
        if (!p0.allFinite() || !p1.allFinite()) continue;
        flow[x] =
            cv::Vec2f(static_cast<float>(p1.x() - p0.x()), static_cast<float>(p1.y() - p0.y()));
        if (!camera_t1.InImage(p1)) continue;
        const int qx = std::clamp(static_cast<int>(std::lround(p1.x())), 0, w - 1);
        const int qy = std::clamp(static_cast<int>(std::lround(p1.y())), 0, h - 1);
        const int o1 = view_t1.object.at<uint16_t>(qy, qx);
        if (o1 == 0) continue;
        const int f1 = view_t1.face.at<int32_t>(qy, qx);
        if (o1 == object[x] && f1 == face[x]) {
          valid[x] = 255;
          continue;
        }
        // Depth along the ray through p1 of the plane of the triangle visible near p1.
        const SceneObject* occ = FindObject(frame_t1, o1);
        U4D_CHECK(f1 >= 0 && static_cast<size_t>(f1) < occ->mesh.faces.size(),
                  "ForwardFlow: view_t1 names face {} of object {} which has {} faces", f1, o1,
                  occ->mesh.faces.size());
        const Eigen::Vector3i& tri = occ->mesh.faces[f1];
        const Eigen::Vector3d a =
            camera_t1.cam_from_world * occ->mesh.vertices[tri[0]].cast<double>();
        const Eigen::Vector3d b =
            camera_t1.cam_from_world * occ->mesh.vertices[tri[1]].cast<double>();
        const Eigen::Vector3d c =
            camera_t1.cam_from_world * occ->mesh.vertices[tri[2]].cast<double>();
        const Eigen::Vector3d n = (b - a).cross(c - a);
        const Eigen::Vector2d ray = camera_t1.PixelToNormalized(p1);
        const Eigen::Vector3d dir(ray.x(), ray.y(), 1.0);
        const double denom = n.dot(dir);
        double visible_depth = view_t1.depth.at<float>(qy, qx);
        if (std::abs(denom) > 1e-12 * n.norm()) {
          const double t = n.dot(a) / denom;
          if (t > 0) visible_depth = t;
        }
        const double z1 = camera_t1.Depth(x_t1);
        const double tol = options.depth_tolerance + options.relative_depth_tolerance * z1;
        if (z1 <= visible_depth + tol) valid[x] = 255;
      }
    }
  });
  return out;
}

}  // namespace u4d::synth
