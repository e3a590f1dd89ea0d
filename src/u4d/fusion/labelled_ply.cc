#include "u4d/fusion/labelled_ply.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include <open3d/geometry/TriangleMesh.h>

#include "u4d/util/check.h"

namespace u4d {

namespace {

template <typename T>
void Put(std::string& buf, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  buf.append(b, sizeof(T));
}

uint8_t ToByte(double c) {
  return static_cast<uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255.0));
}

}  // namespace

void WriteLabelledMesh(const fs::path& path, const open3d::geometry::TriangleMesh& mesh, int label,
                       const std::string& class_name) {
  WriteLabelledMesh(path, mesh, std::vector<int>(mesh.vertices_.size(), label), class_name);
}

void WriteLabelledMesh(const fs::path& path, const open3d::geometry::TriangleMesh& mesh,
                       const std::vector<int>& labels, const std::string& class_name) {
  const size_t nv = mesh.vertices_.size();
  U4D_CHECK(nv > 0, "WriteLabelledMesh {}: the mesh has no vertex", path.string());
  U4D_CHECK(labels.size() == nv, "WriteLabelledMesh {}: {} labels for {} vertices", path.string(),
            labels.size(), nv);
  U4D_CHECK(class_name.find_first_of("\r\n") == std::string::npos,
            "WriteLabelledMesh {}: the class name '{}' holds a line break", path.string(),
            class_name);
  const bool normals = mesh.vertex_normals_.size() == nv;
  const bool colors = mesh.vertex_colors_.size() == nv;
  for (const Eigen::Vector3i& t : mesh.triangles_)
    for (int k = 0; k < 3; ++k)
      U4D_CHECK(t[k] >= 0 && static_cast<size_t>(t[k]) < nv,
                "WriteLabelledMesh {}: face index {} out of range [0, {})", path.string(), t[k],
                nv);
  std::string buf;
  buf += "ply\nformat binary_little_endian 1.0\ncomment written by u4d\n";
  if (!class_name.empty()) buf += "comment class " + class_name + "\n";
  buf += "element vertex " + std::to_string(nv) + "\n";
  buf += "property float x\nproperty float y\nproperty float z\n";
  if (normals) buf += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colors) buf += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  buf += "property int label\n";
  buf += "element face " + std::to_string(mesh.triangles_.size()) + "\n";
  buf += "property list uchar int vertex_indices\nend_header\n";
  for (size_t i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) Put<float>(buf, static_cast<float>(mesh.vertices_[i][k]));
    if (normals)
      for (int k = 0; k < 3; ++k) Put<float>(buf, static_cast<float>(mesh.vertex_normals_[i][k]));
    if (colors)
      for (int k = 0; k < 3; ++k) Put<uint8_t>(buf, ToByte(mesh.vertex_colors_[i][k]));
    Put<int32_t>(buf, labels[i]);
  }
  for (const Eigen::Vector3i& t : mesh.triangles_) {
    Put<uint8_t>(buf, 3);
    for (int k = 0; k < 3; ++k) Put<int32_t>(buf, t[k]);
  }
  WriteAtomically(path, [&](const fs::path& tmp) {
    std::ofstream f(tmp, std::ios::binary);
    f.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    U4D_CHECK(f.good(), "WriteLabelledMesh: cannot write {}", tmp.string());
  });
}

namespace {

struct Property {
  std::string name, type;
  bool is_list = false;
  std::string count_type;
};
struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> props;
};

int TypeSize(const std::string& t, const std::string& ctx) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32")
    return 4;
  if (t == "double" || t == "float64") return 8;
  ThrowError(fmt::format("{}: unknown PLY property type '{}'", ctx, t));
}

class Reader {
 public:
  Reader(const std::string& data, size_t pos, bool ascii, std::string ctx)
      : data_(data), pos_(pos), ascii_(ascii), ctx_(std::move(ctx)) {
    if (ascii_) text_.str(data_.substr(pos_));
  }
  double Read(const std::string& t) {
    if (ascii_) {
      double v;
      U4D_CHECK(static_cast<bool>(text_ >> v), "{}: truncated or malformed ascii data", ctx_);
      return v;
    }
    const int n = TypeSize(t, ctx_);
    U4D_CHECK(pos_ + n <= data_.size(), "{}: file is truncated (binary data ends early)", ctx_);
    const char* p = data_.data() + pos_;
    pos_ += n;
    auto get = [p](auto v) {
      std::memcpy(&v, p, sizeof(v));
      return static_cast<double>(v);
    };
    if (t == "char" || t == "int8") return get(int8_t{});
    if (t == "uchar" || t == "uint8") return get(uint8_t{});
    if (t == "short" || t == "int16") return get(int16_t{});
    if (t == "ushort" || t == "uint16") return get(uint16_t{});
    if (t == "int" || t == "int32") return get(int32_t{});
    if (t == "uint" || t == "uint32") return get(uint32_t{});
    if (t == "float" || t == "float32") return get(float{});
    return get(double{});
  }

 private:
  const std::string& data_;
  size_t pos_;
  bool ascii_;
  std::string ctx_;
  std::istringstream text_;
};

}  // namespace

LabelledMesh ReadLabelledMesh(const fs::path& path) {
  CheckFileExists(path, "PLY mesh");
  const std::string ctx = path.string();
  std::string data;
  {
    std::ifstream f(path, std::ios::binary);
    std::ostringstream ss;
    ss << f.rdbuf();
    data = ss.str();
  }
  const size_t end = data.find("end_header\n");
  U4D_CHECK(data.rfind("ply", 0) == 0 && end != std::string::npos,
            "{}: not a PLY file (expected 'ply' ... 'end_header')", ctx);
  std::istringstream header(data.substr(0, end));
  std::string line, format, class_name;
  std::vector<Element> elements;
  while (std::getline(header, line)) {
    std::istringstream ls(line);
    std::string kw;
    ls >> kw;
    if (kw == "format") {
      ls >> format;
    } else if (kw == "comment" && line.rfind("comment class ", 0) == 0) {
      class_name = line.substr(std::strlen("comment class "));
      if (!class_name.empty() && class_name.back() == '\r') class_name.pop_back();
    } else if (kw == "element") {
      Element e;
      ls >> e.name >> e.count;
      elements.push_back(e);
    } else if (kw == "property") {
      U4D_CHECK(!elements.empty(), "{}: property before any element", ctx);
      Property p;
      ls >> p.type;
      if (p.type == "list") {
        p.is_list = true;
        ls >> p.count_type >> p.type;
      }
      ls >> p.name;
      elements.back().props.push_back(p);
    }
  }
  U4D_CHECK(format == "ascii" || format == "binary_little_endian",
            "{}: PLY format must be ascii or binary_little_endian, found '{}'", ctx, format);
  Reader in(data, end + std::strlen("end_header\n"), format == "ascii", ctx);

  LabelledMesh out;
  out.class_name = class_name;
  out.mesh = std::make_shared<open3d::geometry::TriangleMesh>();
  auto& m = *out.mesh;
  bool has_vertices = false;
  for (const Element& e : elements) {
    if (e.name == "vertex") {
      has_vertices = true;
      auto has = [&](const char* n) {
        return std::any_of(e.props.begin(), e.props.end(),
                           [&](const Property& p) { return p.name == n; });
      };
      const bool normals = has("nx"), colors = has("red"), labels = has("label");
      m.vertices_.resize(e.count);
      if (normals) m.vertex_normals_.resize(e.count);
      if (colors) m.vertex_colors_.resize(e.count);
      out.labels.assign(e.count, 0);
      for (size_t i = 0; i < e.count; ++i)
        for (const Property& p : e.props) {
          U4D_CHECK(!p.is_list, "{}: unexpected list property '{}' in vertex", ctx, p.name);
          const double v = in.Read(p.type);
          const std::string& n = p.name;
          if (n == "x")
            m.vertices_[i].x() = v;
          else if (n == "y")
            m.vertices_[i].y() = v;
          else if (n == "z")
            m.vertices_[i].z() = v;
          else if (n == "nx")
            m.vertex_normals_[i].x() = v;
          else if (n == "ny")
            m.vertex_normals_[i].y() = v;
          else if (n == "nz")
            m.vertex_normals_[i].z() = v;
          else if (n == "red")
            m.vertex_colors_[i].x() = v / 255.0;
          else if (n == "green")
            m.vertex_colors_[i].y() = v / 255.0;
          else if (n == "blue")
            m.vertex_colors_[i].z() = v / 255.0;
          else if (n == "label")
            out.labels[i] = static_cast<int>(v);
        }
      (void)labels;
    } else {
      for (size_t i = 0; i < e.count; ++i)
        for (const Property& p : e.props) {
          if (!p.is_list) {
            in.Read(p.type);
            continue;
          }
          const int n = static_cast<int>(in.Read(p.count_type));
          std::vector<int> idx(n);
          for (int k = 0; k < n; ++k) idx[k] = static_cast<int>(in.Read(p.type));
          if (e.name != "face" || (p.name != "vertex_indices" && p.name != "vertex_index"))
            continue;
          for (int k = 2; k < n; ++k) m.triangles_.emplace_back(idx[0], idx[k - 1], idx[k]);
        }
    }
  }
  U4D_CHECK(has_vertices, "{}: PLY has no vertex element", ctx);
  for (const Eigen::Vector3i& t : m.triangles_)
    for (int k = 0; k < 3; ++k)
      U4D_CHECK(t[k] >= 0 && static_cast<size_t>(t[k]) < m.vertices_.size(),
                "{}: face index {} out of range [0, {})", ctx, t[k], m.vertices_.size());
  return out;
}

}  // namespace u4d
