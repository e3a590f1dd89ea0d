#include "u4d/fusion/gltf.h"

#include <cstring>
#include <fstream>
#include <iterator>
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
  if (!segment.class_name.empty()) gltf["extras"]["class"] = segment.class_name;
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

namespace {

// The accessors of a parsed .glb, bounds-checked against its binary chunk.
class GlbReader {
 public:
  GlbReader(const nlohmann::json& gltf, const std::string& bin, const std::string& ctx)
      : gltf_(gltf), bin_(bin), ctx_(ctx) {}

  // Accessor `index` as `components` floats (or uint32) per element.
  template <typename T>
  std::vector<T> Read(int index, int component_type, const std::string& type) const {
    U4D_CHECK(gltf_.contains("accessors") && index >= 0 &&
                  index < static_cast<int>(gltf_["accessors"].size()),
              "{}: accessor {} does not exist", ctx_, index);
    const nlohmann::json& a = gltf_["accessors"][index];
    U4D_CHECK(a.value("componentType", 0) == component_type && a.value("type", "") == type,
              "{}: accessor {} is not of the expected layout ({} {})", ctx_, index, component_type,
              type);
    const size_t comps = type == "VEC3" ? 3 : 1;
    const size_t count = a.value("count", size_t{0});
    const int view_index = a.value("bufferView", -1);
    U4D_CHECK(view_index >= 0 && view_index < static_cast<int>(gltf_["bufferViews"].size()),
              "{}: accessor {} has no valid bufferView", ctx_, index);
    const nlohmann::json& v = gltf_["bufferViews"][view_index];
    const size_t offset = v.value("byteOffset", size_t{0}) + a.value("byteOffset", size_t{0});
    const size_t bytes = count * comps * sizeof(T);
    U4D_CHECK(bytes <= v.value("byteLength", size_t{0}) && offset + bytes <= bin_.size(),
              "{}: accessor {} reaches beyond the binary chunk", ctx_, index);
    std::vector<T> out(count * comps);
    if (bytes > 0) std::memcpy(out.data(), bin_.data() + offset, bytes);
    return out;
  }
  std::vector<Eigen::Vector3d> Vec3(int index) const {
    const std::vector<float> f = Read<float>(index, kFloat, "VEC3");
    std::vector<Eigen::Vector3d> out(f.size() / 3);
    for (size_t i = 0; i < out.size(); ++i) out[i] = {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
    return out;
  }

 private:
  const nlohmann::json& gltf_;
  const std::string& bin_;
  std::string ctx_;
};

uint32_t U32At(const std::string& s, size_t at) {
  uint32_t v;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}

}  // namespace

AnimatedMesh ReadSegmentGlb(const fs::path& path) {
  const std::string ctx = "ReadSegmentGlb " + path.string();
  std::ifstream f(path, std::ios::binary);
  U4D_CHECK(f.good(), "{}: cannot open the file", ctx);
  const std::string glb((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  U4D_CHECK(glb.size() >= 28 && U32At(glb, 0) == 0x46546C67 && U32At(glb, 4) == 2,
            "{}: not a binary glTF 2.0 file", ctx);
  U4D_CHECK(U32At(glb, 8) == glb.size(), "{}: the header says {} bytes, the file has {}", ctx,
            U32At(glb, 8), glb.size());
  const size_t json_len = U32At(glb, 12);
  U4D_CHECK(U32At(glb, 16) == 0x4E4F534A && 20 + json_len + 8 <= glb.size(),
            "{}: the JSON chunk is missing or truncated", ctx);
  const size_t bin_at = 20 + json_len;
  const size_t bin_len = U32At(glb, bin_at);
  U4D_CHECK(U32At(glb, bin_at + 4) == 0x004E4942 && bin_at + 8 + bin_len <= glb.size(),
            "{}: the binary chunk is missing or truncated", ctx);
  nlohmann::json gltf;
  try {
    gltf = nlohmann::json::parse(glb.substr(20, json_len));
  } catch (const nlohmann::json::exception& e) {
    ThrowError(fmt::format("{}: the JSON chunk does not parse: {}", ctx, e.what()));
  }
  const std::string bin = glb.substr(bin_at + 8, bin_len);
  const GlbReader r(gltf, bin, ctx);
  U4D_CHECK(gltf.contains("meshes") && !gltf["meshes"].empty() &&
                gltf["meshes"][0].contains("primitives") &&
                !gltf["meshes"][0]["primitives"].empty(),
            "{}: no mesh primitive", ctx);
  const nlohmann::json& prim = gltf["meshes"][0]["primitives"][0];
  U4D_CHECK(prim.contains("attributes") && prim["attributes"].contains("POSITION") &&
                prim.contains("indices"),
            "{}: the primitive has no POSITION or no indices", ctx);

  AnimatedMesh seg;
  const nlohmann::json extras = gltf.value("extras", nlohmann::json::object());
  seg.object_id = extras.value("object_id", 0);
  seg.first_frame = extras.value("first_frame", 0);
  seg.class_name = extras.value("class", std::string());
  seg.positions.push_back(r.Vec3(prim["attributes"]["POSITION"].get<int>()));
  const size_t nv = seg.positions[0].size();
  if (prim["attributes"].contains("COLOR_0")) {
    seg.colors = r.Vec3(prim["attributes"]["COLOR_0"].get<int>());
    U4D_CHECK(seg.colors.size() == nv, "{}: {} colours for {} vertices", ctx, seg.colors.size(),
              nv);
  }
  const std::vector<uint32_t> idx = r.Read<uint32_t>(prim["indices"].get<int>(), kUint, "SCALAR");
  U4D_CHECK(idx.size() % 3 == 0, "{}: {} indices is not a triangle list", ctx, idx.size());
  for (size_t i = 0; i < idx.size(); i += 3) {
    for (int k = 0; k < 3; ++k)
      U4D_CHECK(idx[i + k] < nv, "{}: index {} out of range [0, {})", ctx, idx[i + k], nv);
    seg.triangles.emplace_back(idx[i], idx[i + 1], idx[i + 2]);
  }
  if (prim.contains("targets"))
    for (const nlohmann::json& t : prim["targets"]) {
      U4D_CHECK(t.contains("POSITION"), "{}: a morph target has no POSITION", ctx);
      std::vector<Eigen::Vector3d> p = r.Vec3(t["POSITION"].get<int>());
      U4D_CHECK(p.size() == nv, "{}: a morph target has {} vertices, the mesh {}", ctx, p.size(),
                nv);
      for (size_t i = 0; i < nv; ++i) p[i] += seg.positions[0][i];
      seg.positions.push_back(std::move(p));
    }
  return seg;
}

}  // namespace u4d
