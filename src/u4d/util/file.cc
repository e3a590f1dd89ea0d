#include "u4d/util/file.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "u4d/util/check.h"

namespace u4d {

namespace {

// fs::status without exceptions: an error other than "not found" (e.g. no
// permission to search a parent) is a u4d::Error naming the path.
fs::file_status StatusOf(const fs::path& path, const std::string& what) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  U4D_CHECK(!ec || st.type() == fs::file_type::not_found, "{} {}: {}", what, path.string(),
            ec.message());
  return st;
}

}  // namespace

void CheckFileExists(const fs::path& path, const std::string& what) {
  const fs::file_status st = StatusOf(path, what);
  U4D_CHECK(fs::exists(st), "{} not found: {}", what, path.string());
  U4D_CHECK(fs::is_regular_file(st), "{} is not a regular file: {}", what, path.string());
}

void CheckDirExists(const fs::path& path, const std::string& what) {
  const fs::file_status st = StatusOf(path, what);
  U4D_CHECK(fs::exists(st), "{} not found: {}", what, path.string());
  U4D_CHECK(fs::is_directory(st), "{} is not a directory: {}", what, path.string());
}

void CreateDirectories(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  U4D_CHECK(!ec, "cannot create directory {}: {}", dir.string(), ec.message());
}

std::optional<int> ParseIndexName(const std::string& name) {
  if (name.empty() || name.size() > 9) return std::nullopt;  // 9 digits fit an int
  if (name.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  return std::stoi(name);
}

std::string ReadTextFile(const fs::path& path) {
  CheckFileExists(path);
  std::ifstream in(path, std::ios::binary);
  U4D_CHECK(in.good(), "cannot open {} for reading", path.string());
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

nlohmann::json ReadJsonFile(const fs::path& path) {
  const std::string text = ReadTextFile(path);
  return ParseJsonText(text, path.string());
}

double JsonNumber(const nlohmann::json& v, const std::string& context, const std::string& what) {
  U4D_CHECK(v.is_number(), "{}: {} must be a number, found {}", context, what, v.dump());
  const double d = v.get<double>();
  U4D_CHECK(std::isfinite(d), "{}: {} is not finite", context, what);
  return d;
}

int64_t JsonInteger(const nlohmann::json& v, const std::string& context, const std::string& what) {
  return JsonAs<int64_t>(v, context, what);
}

void WriteAtomically(const fs::path& path, const std::function<void(const fs::path&)>& write_to) {
  if (path.has_parent_path()) CreateDirectories(path.parent_path());
  // Keep the extension last so writers that pick the format from it work.
  const fs::path tmp =
      path.parent_path() /
      (path.stem().string() + ".tmp-" + std::to_string(::getpid()) + path.extension().string());
  try {
    write_to(tmp);
    U4D_CHECK(fs::exists(tmp), "writing {} produced no file", path.string());
    std::error_code ec;
    fs::rename(tmp, path, ec);
    U4D_CHECK(!ec, "cannot rename {} to {}: {}", tmp.string(), path.string(), ec.message());
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
}

bool IsAtomicWriteTemporary(const fs::path& path) {
  const std::string name = path.filename().string();
  const size_t at = name.rfind(".tmp-");
  if (at == std::string::npos) return false;
  size_t end = at + 5;
  while (end < name.size() && std::isdigit(static_cast<unsigned char>(name[end]))) ++end;
  return end > at + 5 && (end == name.size() || name[end] == '.');
}

void WriteTextFileAtomic(const fs::path& path, const std::string& text) {
  WriteAtomically(path, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    U4D_CHECK(out.good(), "cannot open {} for writing", tmp.string());
    out << text;
    out.close();
    U4D_CHECK(out.good(), "failed writing {}", tmp.string());
  });
}

void WriteJsonFileAtomic(const fs::path& path, const nlohmann::json& json, int indent) {
  WriteTextFileAtomic(path, json.dump(indent) + "\n");
}

}  // namespace u4d
