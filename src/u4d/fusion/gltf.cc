#include "u4d/fusion/gltf.h"

#include <cstring>
#include <fstream>
#include <limits>

#include <open3d/geometry/TriangleMesh.h>
#include <nlohmann/json.hpp>

#include "u4d/util/check.h"

namespace u4d {

void GltfOptions::Check() const {
  U4D_CHECK(fps > 0 && std::isfinite(fps), "GltfOptions.fps must be > 0, found {}", fps);
}

namespace {

constexpr int kFloat = 5126, kUint = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

class GlbBuilder {
 public:
  // Appends data as a new bufferView; returns its index.
  int View(const void* data, size_t bytes, int target) {
    while (bin_.size() % 4) bin_.push_back(0);
    nlohmann::json v = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", bytes}};
    if (target) v["target"] = target;
    views_.push_back(v);
    bin_.append(static_cast<const char*>(data), bytes);
    return static_cast<int>(views_.size()) - 1;
  }
  int Accessor(int view, int component, size_t count, const std::string& type,
               const nlohmann::json& min = nullptr, const nlohmann::json& max = nullptr) {
    nlohmann::json a = {
        {"bufferView", view}, {"componentType", component}, {"count", count}, {"type", type}};
    if (!min.is_null()) a["min"] = min;
    if (!max.is_null()) a["max"] = max;
    accessors_.push_back(a);
    return static_cast<int>(accessors_.size()) - 1;
  }
  int Vec3(const std::vector<Eigen::Vector3d>& v, bool min_max, int target = kArrayBuffer) {
    std::vector<float> f;
    f.reserve(v.size() * 3);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const Eigen::Vector3d& x : v)
      for (int k = 0; k < 3; ++k) {
        const float c = static_cast<float>(x[k]);
        f.push_back(c);
        lo[k] = std::min<double>(lo[k], c);
        hi[k] = std::max<double>(hi[k], c);
      }
    const int view = View(f.data(), f.size() * sizeof(float), target);
    if (!min_max) return Accessor(view, kFloat, v.size(), "VEC3");
    return Accessor(view, kFloat, v.size(), "VEC3", nlohmann::json::array({lo.x(), lo.y(), lo.z()}),
                    nlohmann::json::array({hi.x(), hi.y(), hi.z()}));
  }
  std::string Finish(nlohmann::json gltf) {
    while (bin_.size() % 4) bin_.push_back(0);
    nlohmann::json buffer = {{"byteLength", bin_.size()}};
    gltf["buffers"] = nlohmann::json::array({buffer});
    gltf["bufferViews"] = views_;
    gltf["accessors"] = accessors_;
    std::string json = gltf.dump();
    while (json.size() % 4) json.push_back(' ');
    std::string out;
    auto u32 = [&out](uint32_t v) {
      char b[4];
      std::memcpy(b, &v, 4);
      out.append(b, 4);
    };
    u32(0x46546C67);  // "glTF"
    u32(2);
    u32(static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin_.size()));
    u32(static_cast<uint32_t>(json.size()));
    u32(0x4E4F534A);  // "JSON"
    out += json;
    u32(static_cast<uint32_t>(bin_.size()));
    u32(0x004E4942);  // "BIN\0"
    out += bin_;
    return out;
  }

 private:
  std::string bin_;
  nlohmann::json views_ = nlohmann::json::array();
  nlohmann::json accessors_ = nlohmann::json::array();
};

}  // namespace

void WriteSegmentGlb(const fs::path& path, const AnimatedMesh& segment,
                     const GltfOptions& options) {
  options.Check();
  const std::string ctx = "WriteSegmentGlb " + path.string();
  U4D_CHECK(segment.NumFrames() >= 1, "{}: the segment has no frame", ctx);
  U4D_CHECK(!segment.triangles.empty(), "{}: the segment has no triangle", ctx);
  const size_t nv = segment.positions[0].size();
  for (int k = 0; k < segment.NumFrames(); ++k)
    U4D_CHECK(segment.positions[k].size() == nv, "{}: frame {} has {} vertices, frame 0 has {}",
              ctx, k, segment.positions[k].size(), nv);
  U4D_CHECK(segment.colors.empty() || segment.colors.size() == nv, "{}: {} colours for {} vertices",
            ctx, segment.colors.size(), nv);
  std::vector<uint32_t> indices;
  indices.reserve(segment.triangles.size() * 3);
  for (const Eigen::Vector3i& t : segment.triangles)
    for (int k = 0; k < 3; ++k) {
      U4D_CHECK(t[k] >= 0 && static_cast<size_t>(t[k]) < nv,
                "{}: triangle index {} out of range [0, {})", ctx, t[k], nv);
      indices.push_back(static_cast<uint32_t>(t[k]));
    }

  GlbBuilder b;
  nlohmann::json attributes;
  attributes["POSITION"] = b.Vec3(segment.positions[0], true);
  if (options.normals) attributes["NORMAL"] = b.Vec3(segment.MeshAt(0)->vertex_normals_, false);
  if (!segment.colors.empty()) attributes["COLOR_0"] = b.Vec3(segment.colors, false);
  const int idx_view =
      b.View(indices.data(), indices.size() * sizeof(uint32_t), kElementArrayBuffer);
  const int idx_acc =
      b.Accessor(idx_view, kUint, indices.size(), "SCALAR", nlohmann::json::array({0}),
                 nlohmann::json::array({static_cast<uint32_t>(nv - 1)}));
  nlohmann::json primitive = {{"attributes", attributes}, {"indices", idx_acc}, {"mode", 4}};
  const int n_targets = segment.NumFrames() - 1;
  nlohmann::json mesh = {{"name", fmt::format("object_{}", segment.object_id)}};
  if (n_targets > 0) {
    nlohmann::json targets = nlohmann::json::array();
    std::vector<Eigen::Vector3d> delta(nv);
    for (int k = 1; k <= n_targets; ++k) {
      for (size_t i = 0; i < nv; ++i) delta[i] = segment.positions[k][i] - segment.positions[0][i];
      nlohmann::json target_k = {{"POSITION", b.Vec3(delta, true)}};
      targets.push_back(target_k);
    }
    primitive["targets"] = targets;
    mesh["weights"] = std::vector<float>(n_targets, 0.0f);
  }
  mesh["primitives"] = nlohmann::json::array({primitive});
  nlohmann::json node = {{"mesh", 0}, {"name", fmt::format("object_{}", segment.object_id)}};
  nlohmann::json scene = {{"nodes", nlohmann::json::array({0})}};
  nlohmann::json gltf;
  gltf["asset"] = {{"version", "2.0"}, {"generator", "u4d"}};
  gltf["scene"] = 0;
  gltf["scenes"] = nlohmann::json::array({scene});
  gltf["nodes"] = nlohmann::json::array({node});
  gltf["meshes"] = nlohmann::json::array({mesh});
  gltf["extras"] = {
      {"object_id", segment.object_id}, {"first_frame", segment.first_frame}, {"fps", options.fps}};
  if (n_targets > 0) {
    const int n_frames = segment.NumFrames();
    std::vector<float> times(n_frames), weights(static_cast<size_t>(n_frames) * n_targets, 0.f);
    for (int k = 0; k < n_frames; ++k) {
      times[k] = static_cast<float>(k / options.fps);
      if (k > 0) weights[static_cast<size_t>(k) * n_targets + (k - 1)] = 1.f;
    }
    const int tv = b.View(times.data(), times.size() * sizeof(float), 0);
    const int ta =
        b.Accessor(tv, kFloat, times.size(), "SCALAR", nlohmann::json::array({times.front()}),
                   nlohmann::json::array({times.back()}));
    const int wv = b.View(weights.data(), weights.size() * sizeof(float), 0);
    const int wa = b.Accessor(wv, kFloat, weights.size(), "SCALAR");
    nlohmann::json sampler = {{"input", ta}, {"output", wa}, {"interpolation", "STEP"}};
    nlohmann::json target = {{"node", 0}, {"path", "weights"}};
    nlohmann::json channel = {{"sampler", 0}, {"target", target}};
    nlohmann::json anim = {{"name", "play"},
                           {"samplers", nlohmann::json::array({sampler})},
                           {"channels", nlohmann::json::array({channel})}};
    gltf["animations"] = nlohmann::json::array({anim});
  }
  const std::string glb = b.Finish(gltf);
  WriteAtomically(path, [&](const fs::path& tmp) {
    std::ofstream f(tmp, std::ios::binary);
    f.write(glb.data(), static_cast<std::streamsize>(glb.size()));
    U4D_CHECK(f.good(), "{}: cannot write {}", ctx, tmp.string());
  });
}

}  // namespace u4d
