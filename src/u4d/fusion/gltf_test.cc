// The animated .glb of a segment, parsed back byte by byte against the
// glTF 2.0 rules a viewer relies on.
#include "u4d/fusion/gltf.h"

#include <cstring>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <open3d/geometry/TriangleMesh.h>
#include <nlohmann/json.hpp>

#include "u4d/eval/mesh_metrics.h"
#include "u4d/fusion/fusion_test_util.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

uint32_t U32(const std::string& s, size_t at) {
  uint32_t v;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}

int ComponentsOf(const std::string& type) { return type == "VEC3" ? 3 : type == "VEC4" ? 4 : 1; }

// A segment made of the GT meshes of person 1 (same topology in every frame).
TEST(GltfTest, GlbOfGtSegmentParsesBack) {
  const fs::path dir = fusion_test::WriteSmallCapture("fusion_gltf_test");
  AnimatedMesh seg;
  seg.object_id = 1;
  for (int f = 0; f < 3; ++f) {
    const auto m = eval::ReadMesh(dir / layout::GtMesh(1, f));
    if (f == 0) {
      seg.triangles = m.triangles_;
      seg.colors.assign(m.vertices_.size(), Eigen::Vector3d(0.8, 0.3, 0.2));
    }
    seg.positions.push_back(m.vertices_);
  }
  fs::remove_all(dir);
  const fs::path path =
      test_util::FreshTestDir("fusion", "gltf") / layout::SceneSegmentDir(0) / "1.glb";
  GltfOptions opt;
  opt.fps = 25;
  WriteSegmentGlb(path, seg, opt);

  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string glb = ss.str();
  ASSERT_GE(glb.size(), 28u);
  EXPECT_EQ(U32(glb, 0), 0x46546C67u);  // "glTF"
  EXPECT_EQ(U32(glb, 4), 2u);
  EXPECT_EQ(U32(glb, 8), glb.size());
  const uint32_t json_len = U32(glb, 12);
  EXPECT_EQ(U32(glb, 16), 0x4E4F534Au);  // "JSON"
  EXPECT_EQ(json_len % 4, 0u);
  const nlohmann::json j = nlohmann::json::parse(glb.substr(20, json_len));
  const size_t bin_at = 20 + json_len;
  const uint32_t bin_len = U32(glb, bin_at);
  EXPECT_EQ(U32(glb, bin_at + 4), 0x004E4942u);  // "BIN\0"
  EXPECT_EQ(bin_at + 8 + bin_len, glb.size());
  EXPECT_EQ(j["asset"]["version"], "2.0");
  EXPECT_EQ(j["buffers"][0]["byteLength"].get<size_t>(), bin_len);

  // Every accessor fits its bufferView and every view fits the buffer.
  for (const auto& a : j["accessors"]) {
    const auto& v = j["bufferViews"][a["bufferView"].get<int>()];
    const size_t need = a["count"].get<size_t>() * ComponentsOf(a["type"]) * 4;
    EXPECT_EQ(v["byteLength"].get<size_t>(), need);
    EXPECT_LE(v["byteOffset"].get<size_t>() + v["byteLength"].get<size_t>(), bin_len);
    EXPECT_EQ(v["byteOffset"].get<size_t>() % 4, 0u);
  }
  const auto& prim = j["meshes"][0]["primitives"][0];
  const size_t nv = seg.positions[0].size();
  const auto& pos = j["accessors"][prim["attributes"]["POSITION"].get<int>()];
  EXPECT_EQ(pos["count"].get<size_t>(), nv);
  ASSERT_TRUE(pos.contains("min") && pos.contains("max"));
  EXPECT_EQ(j["accessors"][prim["attributes"]["COLOR_0"].get<int>()]["count"].get<size_t>(), nv);
  EXPECT_EQ(j["accessors"][prim["attributes"]["NORMAL"].get<int>()]["count"].get<size_t>(), nv);
  EXPECT_EQ(j["accessors"][prim["indices"].get<int>()]["count"].get<size_t>(),
            3 * seg.triangles.size());
  // Frames 1, 2 are morph targets 0, 1 whose deltas reproduce the positions.
  ASSERT_EQ(prim["targets"].size(), 2u);
  for (int t = 0; t < 2; ++t) {
    const auto& acc = j["accessors"][prim["targets"][t]["POSITION"].get<int>()];
    EXPECT_EQ(acc["count"].get<size_t>(), nv);
    ASSERT_TRUE(acc.contains("min") && acc.contains("max"));
    const auto& view = j["bufferViews"][acc["bufferView"].get<int>()];
    const size_t off = bin_at + 8 + view["byteOffset"].get<size_t>();
    const auto& base = j["bufferViews"][pos["bufferView"].get<int>()];
    const size_t base_off = bin_at + 8 + base["byteOffset"].get<size_t>();
    double worst = 0;
    for (size_t i = 0; i < nv; ++i)
      for (int k = 0; k < 3; ++k) {
        float b, d;
        std::memcpy(&b, glb.data() + base_off + (3 * i + k) * 4, 4);
        std::memcpy(&d, glb.data() + off + (3 * i + k) * 4, 4);
        worst = std::max(worst, std::abs(b + d - seg.positions[t + 1][i][k]));
        EXPECT_GE(d, acc["min"][k].get<double>());
        EXPECT_LE(d, acc["max"][k].get<double>());
      }
    EXPECT_LT(worst, 1e-5);  // float rounding of metres
  }
  // Step animation of the weights: 3 key times, 3 x 2 weights.
  const auto& anim = j["animations"][0];
  EXPECT_EQ(anim["samplers"][0]["interpolation"], "STEP");
  EXPECT_EQ(anim["channels"][0]["target"]["path"], "weights");
  EXPECT_EQ(j["accessors"][anim["samplers"][0]["input"].get<int>()]["count"], 3);
  EXPECT_EQ(j["accessors"][anim["samplers"][0]["output"].get<int>()]["count"], 6);
  EXPECT_DOUBLE_EQ(j["accessors"][anim["samplers"][0]["input"].get<int>()]["max"][0].get<double>(),
                   static_cast<float>(2 / 25.0));
}

// ReadSegmentGlb returns what WriteSegmentGlb wrote (to float precision), and
// names the file and the problem for a truncated or foreign file.
TEST(GltfTest, ReadsBackWhatWasWritten) {
  AnimatedMesh seg;
  seg.object_id = 7;
  seg.first_frame = 12;
  seg.class_name = "box";
  seg.triangles = {{0, 1, 2}, {0, 2, 3}};
  seg.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5, 0.5, 0.5}};
  seg.positions.push_back({{0, 0, 3}, {1, 0, 3}, {1, 1, 3}, {0, 1, 3}});
  for (int k = 1; k < 4; ++k) {
    seg.positions.push_back(seg.positions[0]);
    for (auto& p : seg.positions.back()) p += Eigen::Vector3d(0.01 * k, -0.02 * k, 0.003 * k * k);
  }
  const fs::path dir = test_util::FreshTestDir("fusion", "gltf_read");
  WriteSegmentGlb(dir / "7.glb", seg, {});
  const AnimatedMesh back = ReadSegmentGlb(dir / "7.glb");
  EXPECT_EQ(back.object_id, 7);
  EXPECT_EQ(back.first_frame, 12);
  EXPECT_EQ(back.class_name, "box");
  EXPECT_EQ(back.triangles, seg.triangles);
  ASSERT_EQ(back.NumFrames(), 4);
  ASSERT_EQ(back.colors.size(), 4u);
  double worst = 0;
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 4; ++i)
      worst = std::max(worst, (back.positions[k][i] - seg.positions[k][i]).norm());
  EXPECT_LT(worst, 1e-5);  // float rounding of metres
  EXPECT_LT((back.colors[2] - seg.colors[2]).norm(), 1e-6);

  // Truncated: the header's length no longer matches.
  std::ifstream in(dir / "7.glb", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(dir / "cut.glb", std::ios::binary).write(bytes.data(), 100);
  test_util::ExpectErrorMentions([&] { ReadSegmentGlb(dir / "cut.glb"); },
                                 {"cut.glb", "the header says"});
  std::ofstream(dir / "text.glb") << "solid not a glb\n";
  test_util::ExpectErrorMentions([&] { ReadSegmentGlb(dir / "text.glb"); },
                                 {"text.glb", "not a binary glTF"});
  test_util::ExpectErrorMentions([&] { ReadSegmentGlb(dir / "none.glb"); },
                                 {"none.glb", "cannot open"});
}

TEST(GltfTest, BadSegmentsThrow) {
  AnimatedMesh seg;
  const fs::path path = test_util::FreshTestDir("fusion", "gltf_bad") / "x.glb";
  test_util::ExpectErrorMentions([&] { WriteSegmentGlb(path, seg, {}); }, {"no frame"});
  seg.positions = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {1, 0, 0}}};
  seg.triangles = {{0, 1, 2}};
  test_util::ExpectErrorMentions([&] { WriteSegmentGlb(path, seg, {}); },
                                 {"frame 1 has 2 vertices"});
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace u4d
