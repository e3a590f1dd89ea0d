#include "u4d/util/file.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "u4d/util/check.h"

namespace u4d {

void CheckFileExists(const fs::path& path, const std::string& what) {
  U4D_CHECK(fs::exists(path), "{} not found: {}", what, path.string());
  U4D_CHECK(fs::is_regular_file(path), "{} is not a regular file: {}", what, path.string());
}

void CheckDirExists(const fs::path& path, const std::string& what) {
  U4D_CHECK(fs::exists(path), "{} not found: {}", what, path.string());
  U4D_CHECK(fs::is_directory(path), "{} is not a directory: {}", what, path.string());
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
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    ThrowError(fmt::format("{}: invalid JSON ({})", path.string(), e.what()));
  }
}

double JsonNumber(const nlohmann::json& v, const std::string& context, const std::string& what) {
  U4D_CHECK(v.is_number(), "{}: {} must be a number, found {}", context, what, v.dump());
  const double d = v.get<double>();
  U4D_CHECK(std::isfinite(d), "{}: {} is not finite", context, what);
  return d;
}

int64_t JsonInteger(const nlohmann::json& v, const std::string& context, const std::string& what) {
  U4D_CHECK(v.is_number_integer(), "{}: {} must be an integer, found {}", context, what, v.dump());
  return v.get<int64_t>();
}

void WriteAtomically(const fs::path& path, const std::function<void(const fs::path&)>& write_to) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  // Keep the extension last so writers that pick the format from it work.
  const fs::path tmp =
      path.parent_path() /
      (path.stem().string() + ".tmp-" + std::to_string(::getpid()) + path.extension().string());
  try {
    write_to(tmp);
    U4D_CHECK(fs::exists(tmp), "writing {} produced no file", path.string());
    fs::rename(tmp, path);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
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
