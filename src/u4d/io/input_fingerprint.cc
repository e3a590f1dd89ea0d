#include "u4d/io/input_fingerprint.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <set>
#include <system_error>

#include <fmt/format.h>

#include "u4d/io/layout.h"
#include "u4d/util/check.h"
#include "u4d/util/json_checked.h"

namespace u4d {
namespace {

constexpr const char* kFormat = "u4d-inputs";

std::string Relative(const fs::path& path, const fs::path& root) {
  return path.lexically_relative(root).generic_string();
}

// "m:<size>:<mtime ns>", or "absent".
std::string SizeAndTime(const fs::path& path) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec || !fs::exists(status)) return "absent";
  U4D_CHECK(fs::is_regular_file(status), "{}: an input frame must be a file", path.string());
  const uintmax_t size = fs::file_size(path, ec);
  U4D_CHECK(!ec, "{}: cannot read its size ({})", path.string(), ec.message());
  const auto time = fs::last_write_time(path, ec);
  U4D_CHECK(!ec, "{}: cannot read its modification time ({})", path.string(), ec.message());
  const int64_t ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch()).count();
  return fmt::format("m:{}:{}", size, ns);
}

// Every regular file under root/sub, recursively (nothing when absent).
std::vector<fs::path> FilesUnder(const fs::path& root, const std::string& sub) {
  std::vector<fs::path> files;
  const fs::path dir = root / sub;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
       it.increment(ec))
    if (it->is_regular_file(ec)) files.push_back(it->path());
  U4D_CHECK(!ec, "{}: cannot list its files ({})", dir.string(), ec.message());
  return files;
}

// The files a view's frames are read from: one video, or one image per frame.
std::set<fs::path> FrameFiles(const Capture& capture, int view) {
  const FrameSource& src = capture.views[view].source;
  if (src.kind == FrameSource::Kind::kVideo) return {capture.root / src.path};
  std::set<fs::path> files;
  for (int f = 0; f < capture.num_frames; ++f) files.insert(capture.ImagePath(view, f));
  return files;
}

}  // namespace

std::string HashFileContent(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  U4D_CHECK(in, "{}: cannot open it to fingerprint the inputs", path.string());
  uint64_t h = 14695981039346656037ull;  // FNV-1a, 64 bit
  char buffer[1 << 16];
  while (in) {
    in.read(buffer, sizeof(buffer));
    const std::streamsize n = in.gcount();
    for (std::streamsize i = 0; i < n; ++i) {
      h ^= static_cast<unsigned char>(buffer[i]);
      h *= 1099511628211ull;
    }
  }
  U4D_CHECK(in.eof(), "{}: read error while fingerprinting the inputs", path.string());
  return fmt::format("c:{:016x}", h);
}

InputFingerprint FingerprintCapture(const Capture& capture) {
  const fs::path& root = capture.root;
  InputFingerprint fp;
  for (const char* name : {"capture.json", "calibration.json"})
    fp.files[name] = HashFileContent(root / name);
  for (const char* sub : {"masks", "poses2d", "poses3d"})
    for (const fs::path& file : FilesUnder(root, sub))
      fp.files[Relative(file, root)] = HashFileContent(file);
  for (const fs::path& file : FilesUnder(root, layout::CleanPlateDir().string()))
    fp.files[Relative(file, root)] = SizeAndTime(file);
  for (int v = 0; v < capture.NumViews(); ++v)
    for (const fs::path& file : FrameFiles(capture, v))
      fp.files[Relative(file, root)] = SizeAndTime(file);
  return fp;
}

nlohmann::json FingerprintToJson(const InputFingerprint& fingerprint) {
  return {{"format", kFormat}, {"files", fingerprint.files}};
}

InputFingerprint FingerprintFromJson(const nlohmann::json& json, const std::string& context) {
  JsonObject(json, context);
  U4D_CHECK(JsonOptional<std::string>(json, "format", "", context) == kFormat,
            "{}: 'format' must be '{}'", context, kFormat);
  const nlohmann::json files = JsonRequired<nlohmann::json>(json, "files", context);
  JsonObject(files, context + ": 'files'");
  InputFingerprint fp;
  for (const auto& [path, entry] : files.items())
    fp.files[path] = JsonAs<std::string>(entry, context, fmt::format("'files' entry '{}'", path));
  return fp;
}

std::vector<std::string> ChangedInputs(const InputFingerprint& before,
                                       const InputFingerprint& now) {
  std::vector<std::string> changed;
  for (const auto& [path, entry] : before.files) {
    const auto it = now.files.find(path);
    if (it == now.files.end() || it->second != entry) changed.push_back(path);
  }
  for (const auto& [path, entry] : now.files)
    if (!before.files.count(path)) changed.push_back(path);
  std::sort(changed.begin(), changed.end());
  return changed;
}

}  // namespace u4d
