// Tests of the mesh-sequence readers: exact round trips of small hand-written
// OBJ / OBJ.gz / PLY folders and PC2 caches, corrupt inputs, and the real
// captured sequences in ../shared/data/captured_meshes (skipped when absent).
#include "u4d/io/mesh_sequence.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

using test_util::ExpectErrorMentions;

const fs::path kCaptured = DataDir() / "captured_meshes";

fs::path FreshDir(const std::string& name) {
  return test_util::FreshTestDir("mesh_sequence_test", name);
}

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void WriteGzip(const fs::path& path, const std::string& text) {
  gzFile f = gzopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr) << path;
  ASSERT_EQ(gzwrite(f, text.data(), static_cast<unsigned>(text.size())),
            static_cast<int>(text.size()));
  ASSERT_EQ(gzclose(f), Z_OK);
}

// A square (4 vertices) and a triangle over it (vertex 4), with positions
// that are not short decimals, so an exact round trip means no rounding.
std::vector<Eigen::Vector3f> Positions(int frame) {
  std::vector<Eigen::Vector3f> p;
  for (int i = 0; i < 5; ++i)
    p.emplace_back(0.1f * i + 0.0123456789f * frame, std::sqrt(2.0f) * i - frame / 3.0f,
                   -1e-3f * i * i + 1.0f / (frame + 7.0f));
  return p;
}

const std::vector<Eigen::Vector3f> kColors = {
    {0.0f, 0.5f, 1.0f}, {0.25f, 0.75f, 0.125f}, {1, 1, 1}, {0, 0, 0}, {0.5f, 0.5f, 0.5f}};

// The quad 1 2 3 4 fans to (0 1 2), (0 2 3); the triangle uses slashes and
// negative indices (-1 is the last vertex read so far, here vertex 5).
const std::vector<Eigen::Vector3i> kFaces = {{0, 1, 2}, {0, 2, 3}, {1, 2, 4}};

std::string Obj(const std::vector<Eigen::Vector3f>& p, bool colors) {
  std::string s = "# hand-written\no square\nvn 0 0 1\nvt 0 0\n";
  for (size_t i = 0; i < p.size(); ++i) {
    s += fmt::format("v {:.9g} {:.9g} {:.9g}", p[i].x(), p[i].y(), p[i].z());
    if (colors) s += fmt::format(" {} {} {}", kColors[i].x(), kColors[i].y(), kColors[i].z());
    s += "\n";
  }
  s += "s off\nf 1 2 3 4\nf 2/1/1 3//1 -1/1\n";
  return s;
}

std::string AsciiPly(const std::vector<Eigen::Vector3f>& p) {
  std::string s = fmt::format(
      "ply\nformat ascii 1.0\ncomment hand-written\nelement vertex {}\nproperty float x\n"
      "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n",
      p.size());
  for (size_t i = 0; i < p.size(); ++i)
    s += fmt::format("{:.9g} {:.9g} {:.9g} {} {} {}\n", p[i].x(), p[i].y(), p[i].z(),
                     int(kColors[i].x() * 255), int(kColors[i].y() * 255),
                     int(kColors[i].z() * 255));
  s += "4 0 1 2 3\n3 1 2 4\n";
  return s;
}

template <typename T>
void Put(T v, bool big, std::string* out) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big) std::reverse(b, b + sizeof(T));
  out->append(b, sizeof(T));
}

// Binary PLY with double positions, a float "confidence" before the colour,
// and an extra element after the faces.
std::string BinaryPly(const std::vector<Eigen::Vector3f>& p, bool big) {
  std::string s = fmt::format(
      "ply\nformat {} 1.0\nelement vertex {}\nproperty double x\nproperty double y\n"
      "property double z\nproperty float confidence\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nelement face 2\nproperty list uchar uint vertex_indices\n"
      "element extra 1\nproperty int something\nend_header\n",
      big ? "binary_big_endian" : "binary_little_endian", p.size());
  for (size_t i = 0; i < p.size(); ++i) {
    for (int c = 0; c < 3; ++c) Put<double>(p[i][c], big, &s);
    Put<float>(0.5f, big, &s);
    for (int c = 0; c < 3; ++c) Put<uint8_t>(uint8_t(kColors[i][c] * 255), big, &s);
  }
  Put<uint8_t>(4, big, &s);
  for (uint32_t v : {0u, 1u, 2u, 3u}) Put<uint32_t>(v, big, &s);
  Put<uint8_t>(3, big, &s);
  for (uint32_t v : {1u, 2u, 4u}) Put<uint32_t>(v, big, &s);
  Put<int32_t>(42, big, &s);
  return s;
}

// A PC2 file written byte by byte from the documented layout (independent of
// WritePointCache).
std::string Pc2(const std::vector<std::vector<Eigen::Vector3f>>& frames,
                int32_t claimed_points = -1, int32_t claimed_samples = -1) {
  std::string s("POINTCACHE2\0", 12);
  Put<int32_t>(1, false, &s);
  Put<int32_t>(claimed_points >= 0 ? claimed_points : int32_t(frames[0].size()), false, &s);
  Put<float>(1.0f, false, &s);
  Put<float>(1.0f, false, &s);
  Put<int32_t>(claimed_samples >= 0 ? claimed_samples : int32_t(frames.size()), false, &s);
  for (const auto& f : frames)
    for (const Eigen::Vector3f& p : f)
      for (int c = 0; c < 3; ++c) Put<float>(p[c], false, &s);
  return s;
}

void ExpectExactFrame(const std::vector<Eigen::Vector3f>& got,
                      const std::vector<Eigen::Vector3f>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i)
    EXPECT_EQ(got[i], want[i]) << "vertex " << i << ": " << got[i].transpose() << " vs "
                               << want[i].transpose();
}

// Frames written under names whose natural order differs from the
// lexicographic one: frame k is written to names[k].
const std::vector<std::string> kStems = {"pose_1", "pose_2", "pose_10", "pose_011"};

TEST(MeshSequence, ObjFolderRoundTripInNaturalOrder) {
  const fs::path dir = FreshDir("obj");
  for (int k = 0; k < 4; ++k) WriteBytes(dir / (kStems[k] + ".obj"), Obj(Positions(k), true));
  WriteBytes(dir / "README.txt", "not a mesh");
  fs::create_directories(dir / "sub");
  const MeshSequence s = ReadMeshSequence(dir);
  EXPECT_EQ(s.faces, kFaces);
  ASSERT_EQ(s.frames.size(), 4u);
  for (int k = 0; k < 4; ++k) ExpectExactFrame(s.frames[k], Positions(k));
  EXPECT_EQ(s.colors, kColors);
  EXPECT_EQ(s.source_frames, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(s.source_frame_count, 4);
  EXPECT_EQ(s.NumVertices(), 5);
}

TEST(MeshSequence, ObjGzFolderRoundTrip) {
  const fs::path dir = FreshDir("objgz");
  for (int k = 0; k < 4; ++k) WriteGzip(dir / (kStems[k] + ".obj.gz"), Obj(Positions(k), false));
  const MeshSequence s = ReadMeshSequence(dir);
  EXPECT_EQ(s.faces, kFaces);
  ASSERT_EQ(s.frames.size(), 4u);
  for (int k = 0; k < 4; ++k) ExpectExactFrame(s.frames[k], Positions(k));
  EXPECT_TRUE(s.colors.empty());
}

TEST(MeshSequence, PlyFoldersRoundTrip) {
  for (const std::string kind : {"ascii", "little", "big"}) {
    SCOPED_TRACE(kind);
    const fs::path dir = FreshDir("ply_" + kind);
    for (int k = 0; k < 4; ++k)
      WriteBytes(dir / (kStems[k] + ".ply"),
                 kind == "ascii" ? AsciiPly(Positions(k)) : BinaryPly(Positions(k), kind == "big"));
    const MeshSequence s = ReadMeshSequence(dir);
    EXPECT_EQ(s.faces, kFaces);
    ASSERT_EQ(s.frames.size(), 4u);
    for (int k = 0; k < 4; ++k) ExpectExactFrame(s.frames[k], Positions(k));
    ASSERT_EQ(s.colors.size(), 5u);
    for (int i = 0; i < 5; ++i)
      EXPECT_LT((s.colors[i] - kColors[i]).cwiseAbs().maxCoeff(), 1.0f / 255) << i;
  }
}

TEST(MeshSequence, PlyGzFileReads) {
  const fs::path dir = FreshDir("plygz");
  WriteGzip(dir / "m.ply.gz", BinaryPly(Positions(3), false));
  const MeshSequence s = ReadMeshFile(dir / "m.ply.gz");
  EXPECT_EQ(s.faces, kFaces);
  ASSERT_EQ(s.frames.size(), 1u);
  ExpectExactFrame(s.frames[0], Positions(3));
}

TEST(MeshSequence, FrameSelectionReadsOnlyTheChosenFiles) {
  const fs::path dir = FreshDir("select");
  for (int k = 0; k < 10; ++k) {
    // Odd frames are garbage: a selection of even frames must never open them.
    WriteBytes(dir / fmt::format("{}.obj", k + 1),
               k % 2 == 0 ? Obj(Positions(k), false) : std::string("v not a number\n"));
  }
  MeshSequenceOptions o;
  o.first_frame = 2;
  o.stride = 2;
  o.max_frames = 3;
  const MeshSequence s = ReadMeshSequence(dir, o);
  EXPECT_EQ(s.source_frames, (std::vector<int>{2, 4, 6}));
  EXPECT_EQ(s.source_frame_count, 10);
  ASSERT_EQ(s.frames.size(), 3u);
  for (int k = 0; k < 3; ++k) ExpectExactFrame(s.frames[k], Positions(2 + 2 * k));

  o.max_frames = -1;
  o.first_frame = 8;
  EXPECT_EQ(ReadMeshSequence(dir, o).source_frames, (std::vector<int>{8}));
  o.first_frame = 10;
  ExpectErrorMentions([&] { ReadMeshSequence(dir, o); },
                      {dir.string(), "first_frame 10", "10 frames"});
  o.first_frame = 1;  // a garbage frame is selected: its file is named
  ExpectErrorMentions([&] { ReadMeshSequence(dir, o); }, {"2.obj", "not a number"});
}

TEST(MeshSequence, OptionsCheck) {
  MeshSequenceOptions o;
  EXPECT_NO_THROW(o.Check());
  o.stride = 0;
  ExpectErrorMentions([&] { o.Check(); }, {"stride"});
  o = {};
  o.max_frames = 0;
  ExpectErrorMentions([&] { o.Check(); }, {"max_frames"});
  o = {};
  o.first_frame = -1;
  ExpectErrorMentions([&] { o.Check(); }, {"first_frame"});
}

TEST(MeshSequence, PointCacheRoundTrip) {
  const fs::path dir = FreshDir("pc2");
  std::vector<std::vector<Eigen::Vector3f>> frames;
  for (int k = 0; k < 6; ++k) frames.push_back(Positions(k + 1));
  WriteGzip(dir / "template.obj.gz", Obj(Positions(0), true));
  WriteBytes(dir / "anim.pc2", Pc2(frames));
  EXPECT_EQ(ReadPointCacheHeader(dir / "anim.pc2").num_samples, 6);

  const MeshSequence a = ReadPointCache(dir / "template.obj.gz", dir / "anim.pc2");
  EXPECT_EQ(a.faces, kFaces);
  EXPECT_EQ(a.colors, kColors);
  ASSERT_EQ(a.frames.size(), 6u);
  for (int k = 0; k < 6; ++k) ExpectExactFrame(a.frames[k], frames[k]);

  // The same through ReadMeshSequence: given the .pc2 or its folder; with a
  // selection that seeks.
  MeshSequenceOptions o;
  o.first_frame = 1;
  o.stride = 3;
  for (const fs::path& source : {dir / "anim.pc2", dir}) {
    const MeshSequence b = ReadMeshSequence(source, o);
    EXPECT_EQ(b.source_frames, (std::vector<int>{1, 4}));
    EXPECT_EQ(b.source_frame_count, 6);
    ASSERT_EQ(b.frames.size(), 2u);
    ExpectExactFrame(b.frames[0], frames[1]);
    ExpectExactFrame(b.frames[1], frames[4]);
  }

  // WritePointCache writes the same bytes apart from the start frame (0 there).
  WritePointCache(dir / "written.pc2", frames);
  std::string want = Pc2(frames);
  const float zero = 0;
  std::memcpy(want.data() + 20, &zero, 4);
  EXPECT_EQ(ReadBytes(dir / "written.pc2"), want);
}

TEST(MeshSequence, CorruptPointCachesThrowNamingTheFile) {
  const fs::path dir = FreshDir("pc2_bad");
  const fs::path obj = dir / "t.obj";
  WriteBytes(obj, Obj(Positions(0), false));
  const std::vector<std::vector<Eigen::Vector3f>> frames = {Positions(1), Positions(2)};
  const std::string good = Pc2(frames);
  const fs::path pc2 = dir / "bad.pc2";
  auto expect = [&](const std::string& bytes, const std::vector<std::string>& parts) {
    WriteBytes(pc2, bytes);
    std::vector<std::string> all = parts;
    all.push_back(pc2.string());
    ExpectErrorMentions([&] { ReadPointCache(obj, pc2); }, all);
  };
  expect(good.substr(0, good.size() - 5), {"truncated"});
  expect(good.substr(0, 20), {"shorter than the 32-byte"});
  expect("POINTCACHE3" + good.substr(11), {"POINTCACHE2"});
  expect(good + "xyz", {"trailing"});
  expect(Pc2(frames, -1, 99999), {"99999 samples"});
  expect(Pc2(frames, 99999, 99999), {"99999 samples x 99999 points"});
  expect(Pc2(frames, 0, -1), {"0 points"});
  std::string version = good;
  version[12] = 2;
  expect(version, {"version 2"});
  // The header and size agree, but the template has 5 vertices.
  expect(Pc2({{Eigen::Vector3f(1, 2, 3)}, {Eigen::Vector3f(4, 5, 6)}}),
         {"1 points", "5 vertices", obj.string()});
  std::string nan = good;
  const float q = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan.data() + 32 + 12 * 5 + 4, &q, 4);  // sample 1, point 0, y
  expect(nan, {"sample 1 point 0", "non-finite"});

  // Template found beside the cache: none, or two.
  const fs::path lone = FreshDir("pc2_lone");
  WriteBytes(lone / "a.pc2", good);
  ExpectErrorMentions([&] { ReadMeshSequence(lone / "a.pc2"); }, {"a.pc2", "found 0"});
  WriteBytes(lone / "t1.obj", Obj(Positions(0), false));
  WriteBytes(lone / "t2.obj", Obj(Positions(0), false));
  ExpectErrorMentions([&] { ReadMeshSequence(lone / "a.pc2"); }, {"a.pc2", "found 2"});
}

TEST(MeshSequence, CorruptFoldersThrowNamingTheFile) {
  auto folder = [](const std::string& name, const std::vector<std::string>& objs) {
    const fs::path dir = FreshDir(name);
    for (size_t k = 0; k < objs.size(); ++k)
      WriteBytes(dir / fmt::format("f{:03d}.obj", k), objs[k]);
    return dir;
  };
  const std::string good = Obj(Positions(0), false);

  const fs::path empty = folder("empty", {});
  WriteBytes(empty / "notes.txt", "x");
  ExpectErrorMentions([&] { ReadMeshSequence(empty); }, {empty.string(), "no mesh files"});
  ExpectErrorMentions([&] { ReadMeshSequence(empty / "missing"); }, {"missing"});

  // Vertex count differs from the first frame's.
  const fs::path more = folder("more", {good, good + "v 1 2 3\n"});
  ExpectErrorMentions([&] { ReadMeshSequence(more); }, {"f001.obj", "6 vertices", "has 5"});
  // Faces differ.
  std::string other_faces = good;
  other_faces.replace(other_faces.find("f 1 2 3 4"), 9, "f 1 2 4 3");
  const fs::path faces = folder("faces", {good, other_faces});
  ExpectErrorMentions([&] { ReadMeshSequence(faces); }, {"f001.obj", "triangle 0", "topology"});
  const fs::path fewer = folder("fewer", {good, good + "f 1 2 5\n"});
  ExpectErrorMentions([&] { ReadMeshSequence(fewer); }, {"f001.obj", "4 triangles"});

  // Bad face indices.
  const fs::path high = folder("high", {good + "f 1 2 6\n"});
  ExpectErrorMentions([&] { ReadMeshSequence(high); }, {"f000.obj", "vertex 5", "5 vertices"});
  const fs::path low = folder("low", {good + "f 1 2 -6\n"});
  ExpectErrorMentions([&] { ReadMeshSequence(low); }, {"f000.obj:", "-6", "out of range"});
  const fs::path zero = folder("zero", {good + "f 0 1 2\n"});
  ExpectErrorMentions([&] { ReadMeshSequence(zero); }, {"f000.obj:", "bad face corner"});
  const fs::path two = folder("two", {good + "f 1 2\n"});
  ExpectErrorMentions([&] { ReadMeshSequence(two); }, {"f000.obj:", "at least 3"});

  // Non-finite coordinates and malformed vertices.
  const fs::path nan = folder("nan", {"v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n"});
  ExpectErrorMentions([&] { ReadMeshSequence(nan); }, {"f000.obj:2", "non-finite"});
  const fs::path inf = folder("inf", {"v 0 0 0\nv 1 1e39 0\nv 0 1 0\nf 1 2 3\n"});
  ExpectErrorMentions([&] { ReadMeshSequence(inf); }, {"f000.obj:2"});
  const fs::path shortv = folder("shortv", {"v 0 0\n"});
  ExpectErrorMentions([&] { ReadMeshSequence(shortv); }, {"f000.obj:1", "found 2"});
  const fs::path novert = folder("novert", {"# nothing\n"});
  ExpectErrorMentions([&] { ReadMeshSequence(novert); }, {"f000.obj", "no vertices"});

  // Names: no number, the same number twice, mixed formats.
  const fs::path unnamed = folder("unnamed", {good});
  WriteBytes(unnamed / "rest.obj", good);
  ExpectErrorMentions([&] { ReadMeshSequence(unnamed); }, {"rest.obj", "no frame number"});
  const fs::path dup = folder("dup", {good});
  WriteBytes(dup / "f0.obj", good);
  ExpectErrorMentions([&] { ReadMeshSequence(dup); }, {"f0.obj", "f000.obj", "same frame number"});
  const fs::path mixed = folder("mixed", {good});
  WriteBytes(mixed / "f001.ply", AsciiPly(Positions(0)));
  ExpectErrorMentions([&] { ReadMeshSequence(mixed); }, {mixed.string(), "mixes mesh formats"});

  // A single file is not a sequence.
  ExpectErrorMentions([&] { ReadMeshSequence(high / "f000.obj"); }, {"f000.obj", "ReadMeshFile"});
}

TEST(MeshSequence, CorruptGzipAndPlyThrowNamingTheFile) {
  const fs::path dir = FreshDir("gz_bad");
  const std::string text = Obj(Positions(0), false);
  WriteGzip(dir / "whole.obj.gz", text);
  const std::string gz = ReadBytes(dir / "whole.obj.gz");
  WriteBytes(dir / "cut.obj.gz", gz.substr(0, gz.size() / 2));
  ExpectErrorMentions([&] { ReadMeshFile(dir / "cut.obj.gz"); }, {"cut.obj.gz", "truncated"});
  // Only the 8-byte trailer (CRC, size) missing.
  WriteBytes(dir / "trailer.obj.gz", gz.substr(0, gz.size() - 4));
  ExpectErrorMentions([&] { ReadMeshFile(dir / "trailer.obj.gz"); },
                      {"trailer.obj.gz", "truncated"});
  std::string crc = gz;
  crc[crc.size() - 6] ^= 0x55;  // inside the CRC-32
  WriteBytes(dir / "crc.obj.gz", crc);
  ExpectErrorMentions([&] { ReadMeshFile(dir / "crc.obj.gz"); }, {"crc.obj.gz", "corrupt"});
  WriteBytes(dir / "plain.obj.gz", text);
  ExpectErrorMentions([&] { ReadMeshFile(dir / "plain.obj.gz"); }, {"plain.obj.gz", "not a gzip"});
  WriteBytes(dir / "junk.obj.gz", gz + "junk");
  ExpectErrorMentions([&] { ReadMeshFile(dir / "junk.obj.gz"); }, {"junk.obj.gz", "non-gzip data"});
  // Two concatenated members are one valid gzip file.
  WriteBytes(dir / "two.obj.gz", gz + gz);
  EXPECT_EQ(ReadMeshFile(dir / "two.obj.gz").frames[0].size(), 10u);

  const std::string ply = BinaryPly(Positions(0), false);
  WriteBytes(dir / "cut.ply", ply.substr(0, ply.size() - 10));
  ExpectErrorMentions([&] { ReadMeshFile(dir / "cut.ply"); }, {"cut.ply", "ends early"});
  std::string huge = ply;
  huge.replace(huge.find("element vertex 5"), 16, "element vertex 999999999");
  WriteBytes(dir / "huge.ply", huge);
  ExpectErrorMentions([&] { ReadMeshFile(dir / "huge.ply"); }, {"huge.ply", "999999999 entries"});
  std::string index = AsciiPly(Positions(0));
  index.replace(index.find("3 1 2 4"), 7, "3 1 2 9");
  WriteBytes(dir / "index.ply", index);
  ExpectErrorMentions([&] { ReadMeshFile(dir / "index.ply"); }, {"index.ply", "vertex 9"});
  WriteBytes(dir / "magic.ply", "plx\n" + ply.substr(4));
  ExpectErrorMentions([&] { ReadMeshFile(dir / "magic.ply"); }, {"magic.ply", "not a PLY"});
}

// ---------------------------------------------------------------- real data

TEST(MeshSequenceReal, PdanceFramesHaveFixedTopology) {
  const fs::path frames = kCaptured / "pdance" / "frames";
  U4D_SKIP_WITHOUT_SHARED_DATA(frames);
  const std::vector<fs::path> files = ListMeshFrameFiles(frames);
  ASSERT_EQ(files.size(), 201u);
  EXPECT_EQ(files.front().filename(), "0001.obj.gz");
  EXPECT_EQ(files.back().filename(), "0201.obj.gz");

  // Reading all frames checks that every frame's faces equal the first's.
  const MeshSequence s = ReadMeshSequence(frames);
  ASSERT_EQ(s.frames.size(), 201u);
  EXPECT_EQ(s.source_frame_count, 201);
  EXPECT_EQ(s.NumVertices(), 7061);
  EXPECT_EQ(s.faces.size(), 14118u);
  EXPECT_TRUE(s.colors.empty());
  // And explicitly, the last file on its own.
  const MeshSequence last = ReadMeshFile(files.back());
  EXPECT_EQ(last.faces, s.faces);
  ExpectExactFrame(last.frames[0], s.frames.back());

  // SOURCE.txt: y up, a body 1.92-1.96 units tall; arms may rise above the
  // head in some frames, never by much. No frame repeats its predecessor.
  for (size_t k = 0; k < s.frames.size(); ++k) {
    float lo = 1e9f, hi = -1e9f;
    for (const Eigen::Vector3f& p : s.frames[k]) lo = std::min(lo, p.y()), hi = std::max(hi, p.y());
    if (k == 0) {
      EXPECT_GT(hi - lo, 1.92f);
      EXPECT_LT(hi - lo, 1.96f);
    }
    EXPECT_GT(hi - lo, 1.8f) << "frame " << k;
    EXPECT_LT(hi - lo, 2.2f) << "frame " << k;
    if (k > 0) {
      float moved = 0;
      for (int i = 0; i < s.NumVertices(); ++i)
        moved = std::max(moved, (s.frames[k][i] - s.frames[k - 1][i]).norm());
      EXPECT_GT(moved, 1e-4f) << "frame " << k << " repeats frame " << k - 1;
    }
  }

  // Twelve frames from the middle.
  MeshSequenceOptions o;
  o.first_frame = 100;
  o.max_frames = 12;
  const MeshSequence twelve = ReadMeshSequence(frames, o);
  ASSERT_EQ(twelve.frames.size(), 12u);
  for (int k = 0; k < 12; ++k) ExpectExactFrame(twelve.frames[k], s.frames[100 + k]);
}

TEST(MeshSequenceReal, PjumpPointCacheMatchesTemplate) {
  const fs::path dir = kCaptured / "pjump";
  const fs::path pc2 = dir / "pjump_positions.pc2";
  const fs::path obj = dir / "template_frame0001.obj.gz";
  U4D_SKIP_WITHOUT_SHARED_DATA(pc2);
  U4D_SKIP_WITHOUT_SHARED_DATA(obj);
  const PointCacheHeader h = ReadPointCacheHeader(pc2);
  EXPECT_EQ(h.num_points, 15830);
  EXPECT_EQ(h.num_samples, 222);

  const MeshSequence s = ReadMeshSequence(pc2);  // template found beside it
  ASSERT_EQ(s.frames.size(), 222u);
  EXPECT_EQ(s.NumVertices(), 15830);
  EXPECT_EQ(s.faces.size(), 31660u);

  // Sample 0 is the template's frame 1 (float32 rounding only).
  const MeshSequence t = ReadMeshFile(obj);
  EXPECT_EQ(t.faces, s.faces);
  float worst = 0;
  for (int i = 0; i < s.NumVertices(); ++i)
    worst = std::max(worst, (s.frames[0][i] - t.frames[0][i]).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 1e-5f);
  // ... and the last sample is not (the body moves).
  float moved = 0;
  for (int i = 0; i < s.NumVertices(); ++i)
    moved = std::max(moved, (s.frames.back()[i] - t.frames[0][i]).norm());
  EXPECT_GT(moved, 0.05f);

  // The folder as the source, a strided selection.
  MeshSequenceOptions o;
  o.first_frame = 10;
  o.stride = 20;
  const MeshSequence strided = ReadMeshSequence(dir, o);
  ASSERT_EQ(strided.frames.size(), 11u);  // 10, 30, ..., 210
  for (size_t k = 0; k < strided.frames.size(); ++k)
    ExpectExactFrame(strided.frames[k], s.frames[10 + 20 * k]);
}

}  // namespace
}  // namespace u4d
