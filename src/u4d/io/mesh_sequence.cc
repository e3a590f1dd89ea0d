#include "u4d/io/mesh_sequence.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <string_view>

#include "u4d/util/check.h"

namespace u4d {
namespace {

std::string Name(const fs::path& p) { return p.string(); }

// ---------------------------------------------------------------- file names

std::string LowerCase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The mesh format of a file name ("obj", "obj.gz", "ply", "ply.gz") or "".
std::string MeshFormat(const fs::path& p) {
  const std::string n = LowerCase(p.filename().string());
  for (const char* ext : {".obj.gz", ".ply.gz", ".obj", ".ply"})
    if (n.size() > std::strlen(ext) && n.ends_with(ext)) return std::string(ext + 1);
  return "";
}

bool IsGzip(const fs::path& p) { return LowerCase(p.filename().string()).ends_with(".gz"); }

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// Natural order: runs of digits compare as numbers (leading zeros ignored),
// the rest character by character. Returns <0, 0, >0.
int NaturalCompare(std::string_view a, std::string_view b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (IsDigit(a[i]) && IsDigit(b[j])) {
      size_t ie = i, je = j;
      while (ie < a.size() && IsDigit(a[ie])) ++ie;
      while (je < b.size() && IsDigit(b[je])) ++je;
      std::string_view da = a.substr(i, ie - i), db = b.substr(j, je - j);
      while (da.size() > 1 && da[0] == '0') da.remove_prefix(1);
      while (db.size() > 1 && db[0] == '0') db.remove_prefix(1);
      if (da.size() != db.size()) return da.size() < db.size() ? -1 : 1;
      if (const int c = da.compare(db); c != 0) return c;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j])
        return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]) ? -1 : 1;
      ++i;
      ++j;
    }
  }
  if (i < a.size()) return 1;
  if (j < b.size()) return -1;
  return 0;
}

// ---------------------------------------------------------------- bytes

std::string ReadBytes(const fs::path& path) {
  CheckFileExists(path, "mesh file");
  return ReadTextFile(path);
}

// Decompresses a whole gzip file (one or more members). Truncation, a bad
// CRC, corrupt data or trailing non-gzip bytes are errors.
std::string Gunzip(const std::string& in, const fs::path& path) {
  auto magic_at = [&](size_t pos) {
    return in.size() >= pos + 2 && static_cast<unsigned char>(in[pos]) == 0x1f &&
           static_cast<unsigned char>(in[pos + 1]) == 0x8b;
  };
  U4D_CHECK(magic_at(0), "{}: not a gzip file (the first bytes are not 1f 8b)", Name(path));
  U4D_CHECK(in.size() < std::numeric_limits<uInt>::max(), "{}: gzip file too large", Name(path));
  z_stream zs{};
  U4D_CHECK(inflateInit2(&zs, 16 + MAX_WBITS) == Z_OK, "{}: cannot initialise zlib", Name(path));
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  zs.avail_in = static_cast<uInt>(in.size());
  std::string out;
  std::vector<char> buf(1 << 18);
  std::string problem;
  for (;;) {
    zs.next_out = reinterpret_cast<Bytef*>(buf.data());
    zs.avail_out = static_cast<uInt>(buf.size());
    const int rc = inflate(&zs, Z_NO_FLUSH);
    out.append(buf.data(), buf.size() - zs.avail_out);
    if (rc == Z_STREAM_END) {
      if (zs.avail_in == 0) break;
      const size_t pos = in.size() - zs.avail_in;
      if (!magic_at(pos)) {
        problem = fmt::format("{} bytes of non-gzip data after the compressed stream", zs.avail_in);
        break;
      }
      inflateReset(&zs);
      continue;
    }
    if (rc == Z_OK && zs.avail_out == 0) continue;  // more output pending
    if ((rc == Z_OK || rc == Z_BUF_ERROR) && zs.avail_in == 0) {
      problem = "truncated gzip stream (unexpected end of file)";
      break;
    }
    if (rc != Z_OK) {
      problem = fmt::format("corrupt gzip stream ({})", zs.msg ? zs.msg : zError(rc));
      break;
    }
  }
  inflateEnd(&zs);
  U4D_CHECK(problem.empty(), "{}: {}", Name(path), problem);
  return out;
}

std::string ReadMaybeGzip(const fs::path& path) {
  std::string bytes = ReadBytes(path);
  return IsGzip(path) ? Gunzip(bytes, path) : bytes;
}

// ---------------------------------------------------------------- text parsing

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

// Splits on spaces and tabs into `tokens` (cleared first).
void Split(std::string_view s, std::vector<std::string_view>* tokens) {
  tokens->clear();
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    const size_t b = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != '\r') ++i;
    if (i > b) tokens->push_back(s.substr(b, i - b));
  }
}

bool ParseFloat(std::string_view t, float* v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), *v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

template <typename Int>
bool ParseInt(std::string_view t, Int* v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), *v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

// ---------------------------------------------------------------- single meshes

struct Mesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3i> faces;
  std::vector<Eigen::Vector3f> colors;  // empty or one per vertex
};

void AddFan(const std::vector<int>& polygon, std::vector<Eigen::Vector3i>* faces) {
  for (size_t k = 1; k + 1 < polygon.size(); ++k)
    faces->emplace_back(polygon[0], polygon[k], polygon[k + 1]);
}

void CheckMesh(const Mesh& m, const fs::path& path) {
  const int n = static_cast<int>(m.positions.size());
  U4D_CHECK(n > 0, "{}: no vertices", Name(path));
  for (int i = 0; i < n; ++i)
    U4D_CHECK(m.positions[i].allFinite(), "{}: vertex {} has a non-finite coordinate ({}, {}, {})",
              Name(path), i + 1, m.positions[i].x(), m.positions[i].y(), m.positions[i].z());
  for (size_t f = 0; f < m.faces.size(); ++f)
    for (int c = 0; c < 3; ++c)
      U4D_CHECK(m.faces[f][c] >= 0 && m.faces[f][c] < n,
                "{}: triangle {} refers to vertex {} (1-based {}) but the file has {} vertices",
                Name(path), f, m.faces[f][c], m.faces[f][c] + 1, n);
  U4D_CHECK(m.colors.empty() || m.colors.size() == m.positions.size(),
            "{}: {} of {} vertices have a colour; either all or none must", Name(path),
            m.colors.size(), n);
  for (size_t i = 0; i < m.colors.size(); ++i)
    U4D_CHECK(m.colors[i].allFinite() && m.colors[i].minCoeff() >= 0 && m.colors[i].maxCoeff() <= 1,
              "{}: vertex {} colour ({}, {}, {}) outside [0, 1]", Name(path), i + 1,
              m.colors[i].x(), m.colors[i].y(), m.colors[i].z());
}

Mesh ParseObj(const std::string& text, const fs::path& path) {
  Mesh m;
  std::vector<std::string_view> tok;
  std::vector<int> polygon;
  size_t pos = 0;
  int line_no = 0;
  size_t colored = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const std::string_view line = Trim(std::string_view(text).substr(pos, end - pos));
    pos = end + 1;
    ++line_no;
    if (line.size() < 2 || (line[1] != ' ' && line[1] != '\t')) continue;
    if (line[0] == 'v') {
      Split(line.substr(2), &tok);
      const size_t k = tok.size();
      U4D_CHECK(k == 3 || k == 4 || k == 6,
                "{}:{}: a vertex needs 3 (x y z), 4 (x y z w) or 6 (x y z r g b) numbers, found {}",
                Name(path), line_no, k);
      float v[6];
      for (size_t i = 0; i < k; ++i)
        U4D_CHECK(ParseFloat(tok[i], &v[i]), "{}:{}: '{}' is not a number", Name(path), line_no,
                  tok[i]);
      Eigen::Vector3f p(v[0], v[1], v[2]);
      if (k == 4) {
        U4D_CHECK(v[3] != 0, "{}:{}: vertex weight w is 0", Name(path), line_no);
        p /= v[3];
      }
      U4D_CHECK(p.allFinite(), "{}:{}: non-finite vertex coordinate", Name(path), line_no);
      m.positions.push_back(p);
      if (k == 6) {
        U4D_CHECK(colored == m.positions.size() - 1,
                  "{}:{}: vertex has a colour but earlier vertices have none", Name(path), line_no);
        m.colors.emplace_back(v[3], v[4], v[5]);
        ++colored;
      } else {
        U4D_CHECK(colored == 0, "{}:{}: vertex has no colour but earlier vertices have one",
                  Name(path), line_no);
      }
    } else if (line[0] == 'f') {
      Split(line.substr(2), &tok);
      U4D_CHECK(tok.size() >= 3, "{}:{}: a face needs at least 3 corners, found {}", Name(path),
                line_no, tok.size());
      polygon.clear();
      const int64_t n = static_cast<int64_t>(m.positions.size());
      for (std::string_view t : tok) {
        const std::string_view first = t.substr(0, t.find('/'));
        int64_t idx = 0;
        U4D_CHECK(ParseInt(first, &idx) && idx != 0, "{}:{}: bad face corner '{}'", Name(path),
                  line_no, t);
        // 1-based, or negative: relative to the vertices read so far.
        const int64_t zero_based = idx > 0 ? idx - 1 : n + idx;
        U4D_CHECK(zero_based >= 0 && zero_based < std::numeric_limits<int>::max(),
                  "{}:{}: face index {} out of range ({} vertices read so far)", Name(path),
                  line_no, idx, n);
        polygon.push_back(static_cast<int>(zero_based));
      }
      AddFan(polygon, &m.faces);
    }
  }
  CheckMesh(m, path);
  return m;
}

// ---- PLY

enum class PlyFormat { kAscii, kLittle, kBig };

struct PlyProperty {
  std::string name;
  std::string type;        // scalar type, or the item type of a list
  std::string count_type;  // non-empty for a list
};

struct PlyElement {
  std::string name;
  int64_t count = 0;
  std::vector<PlyProperty> properties;
};

int PlyTypeSize(const std::string& t) {
  static const std::map<std::string, int> sizes = {
      {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
      {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto it = sizes.find(t);
  return it == sizes.end() ? 0 : it->second;
}

bool PlyIsFloat(const std::string& t) {
  return t == "float" || t == "float32" || t == "double" || t == "float64";
}

// The fewest bytes one entry of `e` can take: binary, the scalars and list
// counts; ASCII, one character per value and a separator between values.
uint64_t MinEntryBytes(const PlyElement& e, PlyFormat format) {
  uint64_t n = 0;
  for (const PlyProperty& p : e.properties)
    n +=
        format == PlyFormat::kAscii ? 2 : PlyTypeSize(p.count_type.empty() ? p.type : p.count_type);
  return format == PlyFormat::kAscii && n > 0 ? n - 1 : n;
}

// Reads PLY values one by one from the data section, ASCII or binary.
class PlyReader {
 public:
  PlyReader(const std::string& data, size_t pos, PlyFormat format, const fs::path& path)
      : data_(data), pos_(pos), format_(format), path_(path) {}

  double Next(const std::string& type) {
    return format_ == PlyFormat::kAscii ? NextAscii() : NextBinary(type);
  }
  size_t Remaining() const { return data_.size() - pos_; }

 private:
  double NextAscii() {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    const size_t b = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    U4D_CHECK(pos_ > b, "{}: PLY data ends early", Name(path_));
    double v = 0;
    const std::string_view t(data_.data() + b, pos_ - b);
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    U4D_CHECK(r.ec == std::errc() && r.ptr == t.data() + t.size(), "{}: '{}' is not a number",
              Name(path_), t);
    return v;
  }

  double NextBinary(const std::string& type) {
    const int size = PlyTypeSize(type);
    U4D_CHECK(pos_ + size <= data_.size(), "{}: PLY data ends early (truncated file)", Name(path_));
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, size);
    pos_ += size;
    const bool little = format_ == PlyFormat::kLittle;
    if (little != (std::endian::native == std::endian::little)) std::reverse(b, b + size);
    auto as = [&]<typename T>(T) {
      T v;
      std::memcpy(&v, b, sizeof(T));
      return static_cast<double>(v);
    };
    if (type == "char" || type == "int8") return as(int8_t{});
    if (type == "uchar" || type == "uint8") return as(uint8_t{});
    if (type == "short" || type == "int16") return as(int16_t{});
    if (type == "ushort" || type == "uint16") return as(uint16_t{});
    if (type == "int" || type == "int32") return as(int32_t{});
    if (type == "uint" || type == "uint32") return as(uint32_t{});
    if (type == "float" || type == "float32") return as(float{});
    return as(double{});
  }

  const std::string& data_;
  size_t pos_;
  PlyFormat format_;
  const fs::path& path_;
};

Mesh ParsePly(const std::string& data, const fs::path& path) {
  U4D_CHECK(data.starts_with("ply\n") || data.starts_with("ply\r\n"),
            "{}: not a PLY file (no 'ply' magic line)", Name(path));
  const size_t header_end = data.find("end_header");
  U4D_CHECK(header_end != std::string::npos, "{}: PLY header has no end_header", Name(path));
  size_t data_pos = data.find('\n', header_end);
  U4D_CHECK(data_pos != std::string::npos, "{}: PLY file ends after end_header", Name(path));
  ++data_pos;

  PlyFormat format = PlyFormat::kAscii;
  bool have_format = false;
  std::vector<PlyElement> elements;
  std::vector<std::string_view> tok;
  size_t pos = 0;
  while (pos < header_end) {
    size_t end = data.find('\n', pos);
    const std::string_view line = Trim(std::string_view(data).substr(pos, end - pos));
    pos = end + 1;
    Split(line, &tok);
    if (tok.empty() || tok[0] == "ply" || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "format") {
      U4D_CHECK(tok.size() == 3, "{}: bad PLY format line '{}'", Name(path), line);
      if (tok[1] == "ascii")
        format = PlyFormat::kAscii;
      else if (tok[1] == "binary_little_endian")
        format = PlyFormat::kLittle;
      else if (tok[1] == "binary_big_endian")
        format = PlyFormat::kBig;
      else
        ThrowError(fmt::format("{}: unknown PLY format '{}'", Name(path), tok[1]));
      have_format = true;
    } else if (tok[0] == "element") {
      PlyElement e;
      U4D_CHECK(tok.size() == 3 && ParseInt(tok[2], &e.count) && e.count >= 0,
                "{}: bad PLY element line '{}'", Name(path), line);
      e.name = std::string(tok[1]);
      elements.push_back(e);
    } else if (tok[0] == "property") {
      U4D_CHECK(!elements.empty(), "{}: PLY property before any element", Name(path));
      PlyProperty p;
      if (tok.size() == 5 && tok[1] == "list") {
        p.count_type = std::string(tok[2]);
        p.type = std::string(tok[3]);
        p.name = std::string(tok[4]);
        U4D_CHECK(PlyTypeSize(p.count_type) > 0 && !PlyIsFloat(p.count_type),
                  "{}: bad PLY list count type in '{}'", Name(path), line);
      } else {
        U4D_CHECK(tok.size() == 3, "{}: bad PLY property line '{}'", Name(path), line);
        p.type = std::string(tok[1]);
        p.name = std::string(tok[2]);
      }
      U4D_CHECK(PlyTypeSize(p.type) > 0, "{}: unknown PLY type in '{}'", Name(path), line);
      elements.back().properties.push_back(p);
    } else {
      ThrowError(fmt::format("{}: unexpected PLY header line '{}'", Name(path), line));
    }
  }
  U4D_CHECK(have_format, "{}: PLY header has no format line", Name(path));

  Mesh m;
  PlyReader reader(data, data_pos, format, path);
  bool have_vertex = false;
  for (const PlyElement& e : elements) {
    // A count the remaining bytes cannot hold is a corrupt header: check it
    // before allocating anything.
    const uint64_t min_bytes = MinEntryBytes(e, format);
    U4D_CHECK(
        min_bytes == 0 || static_cast<uint64_t>(e.count) <= reader.Remaining() / min_bytes,
        "{}: PLY element '{}' claims {} entries of at least {} bytes but only {} bytes remain",
        Name(path), e.name, e.count, min_bytes, reader.Remaining());
    const auto& props = e.properties;
    auto find = [&](const char* name) {
      for (size_t i = 0; i < props.size(); ++i)
        if (props[i].name == name && props[i].count_type.empty()) return static_cast<int>(i);
      return -1;
    };
    if (e.name == "vertex") {
      have_vertex = true;
      const int ix = find("x"), iy = find("y"), iz = find("z");
      U4D_CHECK(ix >= 0 && iy >= 0 && iz >= 0, "{}: PLY vertex element lacks x, y or z",
                Name(path));
      const int ir = find("red"), ig = find("green"), ib = find("blue");
      const bool color = ir >= 0 && ig >= 0 && ib >= 0;
      const float color_scale = color && !PlyIsFloat(props[ir].type) ? 1.0f / 255 : 1.0f;
      m.positions.resize(e.count);
      if (color) m.colors.resize(e.count);
      std::vector<double> values(props.size());
      for (int64_t v = 0; v < e.count; ++v) {
        for (size_t p = 0; p < props.size(); ++p) {
          if (props[p].count_type.empty()) {
            values[p] = reader.Next(props[p].type);
          } else {  // a list on a vertex: skip it
            const double n = reader.Next(props[p].count_type);
            for (int64_t k = 0; k < static_cast<int64_t>(n); ++k) reader.Next(props[p].type);
          }
        }
        m.positions[v] = Eigen::Vector3d(values[ix], values[iy], values[iz]).cast<float>();
        if (color)
          m.colors[v] =
              color_scale * Eigen::Vector3d(values[ir], values[ig], values[ib]).cast<float>();
      }
    } else if (e.name == "face") {
      U4D_CHECK(have_vertex, "{}: PLY face element before the vertex element", Name(path));
      int il = -1;
      for (size_t i = 0; i < props.size(); ++i)
        if (!props[i].count_type.empty() &&
            (props[i].name == "vertex_indices" || props[i].name == "vertex_index"))
          il = static_cast<int>(i);
      U4D_CHECK(il >= 0, "{}: PLY face element lacks a vertex_indices list", Name(path));
      std::vector<int> polygon;
      for (int64_t f = 0; f < e.count; ++f) {
        for (size_t p = 0; p < props.size(); ++p) {
          if (props[p].count_type.empty()) {
            reader.Next(props[p].type);
            continue;
          }
          const double n = reader.Next(props[p].count_type);
          if (static_cast<int>(p) != il) {
            for (int64_t k = 0; k < static_cast<int64_t>(n); ++k) reader.Next(props[p].type);
            continue;
          }
          U4D_CHECK(n >= 3 && n <= 1e6, "{}: PLY face {} has {} corners", Name(path), f, n);
          polygon.clear();
          for (int k = 0; k < static_cast<int>(n); ++k) {
            const double idx = reader.Next(props[p].type);
            U4D_CHECK(idx >= 0 && idx < std::numeric_limits<int>::max() && idx == std::floor(idx),
                      "{}: PLY face {} has a bad vertex index {}", Name(path), f, idx);
            polygon.push_back(static_cast<int>(idx));
          }
          AddFan(polygon, &m.faces);
        }
      }
    } else if (!props.empty()) {  // another element: skip its values (none without properties)
      for (int64_t k = 0; k < e.count; ++k)
        for (const PlyProperty& p : props) {
          if (p.count_type.empty()) {
            reader.Next(p.type);
          } else {
            const double n = reader.Next(p.count_type);
            for (int64_t j = 0; j < static_cast<int64_t>(n); ++j) reader.Next(p.type);
          }
        }
    }
  }
  U4D_CHECK(have_vertex, "{}: PLY file has no vertex element", Name(path));
  CheckMesh(m, path);
  return m;
}

Mesh ReadMesh(const fs::path& path) {
  const std::string format = MeshFormat(path);
  U4D_CHECK(!format.empty(), "{}: not a mesh file (expected .obj, .obj.gz, .ply or .ply.gz)",
            Name(path));
  const std::string bytes = ReadMaybeGzip(path);
  return format.starts_with("obj") ? ParseObj(bytes, path) : ParsePly(bytes, path);
}

// ---------------------------------------------------------------- selection

// The source indices chosen by `o` out of `count` frames.
std::vector<int> SelectFrames(int count, const MeshSequenceOptions& o, const fs::path& source) {
  o.Check();
  U4D_CHECK(o.first_frame < count, "{}: first_frame {} but the sequence has {} frames",
            Name(source), o.first_frame, count);
  std::vector<int> chosen;
  for (int64_t f = o.first_frame; f < count; f += o.stride) {
    if (o.max_frames >= 0 && static_cast<int>(chosen.size()) >= o.max_frames) break;
    chosen.push_back(static_cast<int>(f));
  }
  return chosen;
}

// ---------------------------------------------------------------- PC2

constexpr char kPc2Magic[12] = {'P', 'O', 'I', 'N', 'T', 'C', 'A', 'C', 'H', 'E', '2', '\0'};
constexpr int64_t kPc2HeaderBytes = 32;

template <typename T>
T LoadLittle(const char* p) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (std::endian::native != std::endian::little) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

template <typename T>
void StoreLittle(T v, std::string* out) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (std::endian::native != std::endian::little) std::reverse(b, b + sizeof(T));
  out->append(b, sizeof(T));
}

fs::path FindTemplateBeside(const fs::path& pc2) {
  const fs::path dir = pc2.parent_path().empty() ? fs::path(".") : pc2.parent_path();
  std::vector<fs::path> found;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string f = MeshFormat(entry.path());
    if (f == "obj" || f == "obj.gz") found.push_back(entry.path());
  }
  std::sort(found.begin(), found.end());
  U4D_CHECK(
      found.size() == 1,
      "{}: expected exactly one template *.obj or *.obj.gz beside the point cache, found {}{}",
      Name(pc2), found.size(),
      found.empty() ? std::string() : fmt::format(" ({}, ...)", Name(found[0].filename())));
  return found[0];
}

}  // namespace

void MeshSequenceOptions::Check() const {
  U4D_CHECK(first_frame >= 0, "MeshSequenceOptions: first_frame must be >= 0, found {}",
            first_frame);
  U4D_CHECK(max_frames == -1 || max_frames >= 1,
            "MeshSequenceOptions: max_frames must be -1 (all) or >= 1, found {}", max_frames);
  U4D_CHECK(stride >= 1, "MeshSequenceOptions: stride must be >= 1, found {}", stride);
}

MeshSequence ReadMeshFile(const fs::path& path) {
  Mesh m = ReadMesh(path);
  MeshSequence s;
  s.faces = std::move(m.faces);
  s.colors = std::move(m.colors);
  s.frames.push_back(std::move(m.positions));
  s.source_frames = {0};
  s.source_frame_count = 1;
  return s;
}

std::vector<fs::path> ListMeshFrameFiles(const fs::path& folder) {
  CheckDirExists(folder, "mesh sequence folder");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name[0] == '.' || !entry.is_regular_file()) continue;
    if (!MeshFormat(entry.path()).empty()) files.push_back(entry.path());
  }
  U4D_CHECK(!files.empty(), "{}: no mesh files (.obj, .obj.gz, .ply, .ply.gz) in the folder",
            Name(folder));
  const std::string format = MeshFormat(files[0]);
  for (const fs::path& f : files) {
    U4D_CHECK(MeshFormat(f) == format,
              "{}: the folder mixes mesh formats ({} and {}); keep one format per sequence",
              Name(folder), Name(files[0].filename()), Name(f.filename()));
    const std::string n = f.filename().string();
    U4D_CHECK(std::any_of(n.begin(), n.end(), IsDigit),
              "{}: cannot place {} in the sequence: its name has no frame number", Name(folder), n);
  }
  std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    return NaturalCompare(a.filename().string(), b.filename().string()) < 0;
  });
  for (size_t i = 1; i < files.size(); ++i)
    U4D_CHECK(NaturalCompare(files[i - 1].filename().string(), files[i].filename().string()) != 0,
              "{}: {} and {} carry the same frame number", Name(folder),
              Name(files[i - 1].filename()), Name(files[i].filename()));
  return files;
}

MeshSequence ReadMeshFolder(const fs::path& folder, const MeshSequenceOptions& options) {
  options.Check();
  const std::vector<fs::path> files = ListMeshFrameFiles(folder);
  MeshSequence s;
  s.source_frame_count = static_cast<int>(files.size());
  s.source_frames = SelectFrames(s.source_frame_count, options, folder);
  fs::path first_file;
  for (const int f : s.source_frames) {
    Mesh m = ReadMesh(files[f]);
    if (s.frames.empty()) {
      first_file = files[f];
      s.faces = std::move(m.faces);
      s.colors = std::move(m.colors);
    } else {
      U4D_CHECK(m.positions.size() == s.frames[0].size(),
                "{}: {} vertices, but the first frame ({}) has {}; a sequence needs a fixed "
                "topology",
                Name(files[f]), m.positions.size(), Name(first_file.filename()),
                s.frames[0].size());
      U4D_CHECK(m.faces.size() == s.faces.size(),
                "{}: {} triangles, but the first frame ({}) has {}; a sequence needs a fixed "
                "topology",
                Name(files[f]), m.faces.size(), Name(first_file.filename()), s.faces.size());
      for (size_t t = 0; t < m.faces.size(); ++t)
        U4D_CHECK(m.faces[t] == s.faces[t],
                  "{}: triangle {} is ({}, {}, {}), but in the first frame ({}) it is ({}, {}, "
                  "{}); a sequence needs a fixed topology",
                  Name(files[f]), t, m.faces[t][0], m.faces[t][1], m.faces[t][2],
                  Name(first_file.filename()), s.faces[t][0], s.faces[t][1], s.faces[t][2]);
    }
    s.frames.push_back(std::move(m.positions));
  }
  return s;
}

PointCacheHeader ReadPointCacheHeader(const fs::path& pc2) {
  CheckFileExists(pc2, "point cache");
  const uint64_t size = fs::file_size(pc2);
  U4D_CHECK(size >= kPc2HeaderBytes, "{}: {} bytes, shorter than the 32-byte PC2 header", Name(pc2),
            size);
  std::ifstream in(pc2, std::ios::binary);
  U4D_CHECK(in.good(), "cannot open {} for reading", Name(pc2));
  char h[kPc2HeaderBytes];
  in.read(h, kPc2HeaderBytes);
  U4D_CHECK(in.good(), "{}: cannot read the PC2 header", Name(pc2));
  U4D_CHECK(std::memcmp(h, kPc2Magic, 12) == 0,
            "{}: not a PC2 point cache (the file does not start with \"POINTCACHE2\\0\")",
            Name(pc2));
  const int32_t version = LoadLittle<int32_t>(h + 12);
  U4D_CHECK(version == 1, "{}: PC2 version {}, expected 1", Name(pc2), version);
  PointCacheHeader header;
  header.num_points = LoadLittle<int32_t>(h + 16);
  header.start_frame = LoadLittle<float>(h + 20);
  header.sample_rate = LoadLittle<float>(h + 24);
  header.num_samples = LoadLittle<int32_t>(h + 28);
  U4D_CHECK(header.num_points > 0, "{}: PC2 header claims {} points", Name(pc2), header.num_points);
  U4D_CHECK(header.num_samples > 0, "{}: PC2 header claims {} samples", Name(pc2),
            header.num_samples);
  U4D_CHECK(std::isfinite(header.start_frame) && std::isfinite(header.sample_rate),
            "{}: PC2 header has a non-finite start frame or sample rate", Name(pc2));
  // Both counts are < 2^31, so the product times 12 fits in 64 bits unsigned.
  const uint64_t expected = kPc2HeaderBytes + static_cast<uint64_t>(header.num_points) *
                                                  static_cast<uint64_t>(header.num_samples) * 12u;
  U4D_CHECK(size == expected,
            "{}: the PC2 header claims {} samples x {} points ({} bytes with the header), but the "
            "file has {} bytes ({})",
            Name(pc2), header.num_samples, header.num_points, expected, size,
            size < expected ? "truncated or corrupt header" : "trailing data or corrupt header");
  return header;
}

MeshSequence ReadPointCache(const fs::path& template_obj, const fs::path& pc2,
                            const MeshSequenceOptions& options) {
  options.Check();
  const PointCacheHeader header = ReadPointCacheHeader(pc2);
  Mesh t = ReadMesh(template_obj);
  U4D_CHECK(static_cast<int64_t>(t.positions.size()) == header.num_points,
            "{}: the point cache has {} points but the template {} has {} vertices", Name(pc2),
            header.num_points, Name(template_obj), t.positions.size());

  MeshSequence s;
  s.faces = std::move(t.faces);
  s.colors = std::move(t.colors);
  s.source_frame_count = header.num_samples;
  s.source_frames = SelectFrames(header.num_samples, options, pc2);

  std::ifstream in(pc2, std::ios::binary);
  U4D_CHECK(in.good(), "cannot open {} for reading", Name(pc2));
  const int64_t sample_bytes = static_cast<int64_t>(header.num_points) * 12;
  std::string buf(sample_bytes, '\0');
  s.frames.reserve(s.source_frames.size());
  for (const int f : s.source_frames) {
    in.seekg(kPc2HeaderBytes + f * sample_bytes);
    in.read(buf.data(), sample_bytes);
    U4D_CHECK(in.good(), "{}: cannot read sample {}", Name(pc2), f);
    std::vector<Eigen::Vector3f> frame(header.num_points);
    for (int i = 0; i < header.num_points; ++i) {
      const char* p = buf.data() + 12 * static_cast<int64_t>(i);
      frame[i] = {LoadLittle<float>(p), LoadLittle<float>(p + 4), LoadLittle<float>(p + 8)};
      U4D_CHECK(frame[i].allFinite(), "{}: sample {} point {} has a non-finite coordinate",
                Name(pc2), f, i);
    }
    s.frames.push_back(std::move(frame));
  }
  return s;
}

MeshSequence ReadMeshSequence(const fs::path& source, const MeshSequenceOptions& options) {
  options.Check();
  if (fs::is_regular_file(source)) {
    U4D_CHECK(LowerCase(source.extension().string()) == ".pc2",
              "{}: a mesh sequence is a folder of per-frame meshes or a .pc2 point cache; for one "
              "mesh file use ReadMeshFile",
              Name(source));
    return ReadPointCache(FindTemplateBeside(source), source, options);
  }
  CheckDirExists(source, "mesh sequence source");
  // A folder with per-frame meshes and a folder with a template + PC2 both
  // hold .obj files; the presence of exactly one .pc2 decides.
  std::vector<fs::path> caches;
  for (const auto& entry : fs::directory_iterator(source))
    if (entry.is_regular_file() && LowerCase(entry.path().extension().string()) == ".pc2")
      caches.push_back(entry.path());
  U4D_CHECK(caches.size() <= 1, "{}: {} .pc2 point caches in the folder; name the one to read",
            Name(source), caches.size());
  if (caches.size() == 1) return ReadPointCache(FindTemplateBeside(caches[0]), caches[0], options);
  return ReadMeshFolder(source, options);
}

void WritePointCache(const fs::path& pc2, const std::vector<std::vector<Eigen::Vector3f>>& frames) {
  U4D_CHECK(!frames.empty() && !frames[0].empty(), "{}: nothing to write", Name(pc2));
  const size_t n = frames[0].size();
  for (size_t f = 0; f < frames.size(); ++f)
    U4D_CHECK(frames[f].size() == n, "{}: frame {} has {} points, frame 0 has {}", Name(pc2), f,
              frames[f].size(), n);
  U4D_CHECK(n < static_cast<size_t>(std::numeric_limits<int32_t>::max()) &&
                frames.size() < static_cast<size_t>(std::numeric_limits<int32_t>::max()),
            "{}: too many points or frames for PC2", Name(pc2));
  std::string out(kPc2Magic, 12);
  StoreLittle<int32_t>(1, &out);
  StoreLittle<int32_t>(static_cast<int32_t>(n), &out);
  StoreLittle<float>(0.0f, &out);
  StoreLittle<float>(1.0f, &out);
  StoreLittle<int32_t>(static_cast<int32_t>(frames.size()), &out);
  out.reserve(out.size() + frames.size() * n * 12);
  for (const auto& frame : frames)
    for (const Eigen::Vector3f& p : frame)
      for (int c = 0; c < 3; ++c) StoreLittle<float>(p[c], &out);
  WriteAtomically(pc2, [&](const fs::path& tmp) {
    std::ofstream o(tmp, std::ios::binary);
    o.write(out.data(), static_cast<std::streamsize>(out.size()));
    U4D_CHECK(o.good(), "cannot write {}", Name(tmp));
  });
}

}  // namespace u4d
