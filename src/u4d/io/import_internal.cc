// Helpers shared by the importers (import_internal.h).
#include "u4d/io/import_internal.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <map>
#include <set>

#include <opencv2/calib3d.hpp>
#include <opencv2/videoio.hpp>

#include "u4d/io/image_io.h"
#include "u4d/util/check.h"

namespace u4d::import_internal {

double ParseFinite(const std::string& token, const std::string& context, const std::string& what) {
  char* end = nullptr;
  const double v = std::strtod(token.c_str(), &end);
  U4D_CHECK(end != token.c_str() && *end == '\0', "{}: {} must be a number, found '{}'", context,
            what, token);
  U4D_CHECK(std::isfinite(v), "{}: {} is not finite ('{}')", context, what, token);
  return v;
}

int ImageDimension(double value, const std::string& context, const std::string& what) {
  U4D_CHECK(std::isfinite(value) && value >= 1 && value <= (1 << 20) && value == std::floor(value),
            "{}: the image {} must be a whole number in [1, {}], found {}", context, what, 1 << 20,
            value);
  return static_cast<int>(value);
}

// All numbers of a (possibly nested) JSON array, flattened; exactly `n`.
std::vector<double> JsonNumbers(const nlohmann::json& j, const std::string& key, size_t n,
                                const std::string& context) {
  U4D_CHECK(j.is_object() && j.contains(key), "{}: missing field '{}'", context, key);
  std::vector<double> out;
  std::function<void(const nlohmann::json&)> add = [&](const nlohmann::json& x) {
    if (x.is_array()) {
      for (const auto& y : x) add(y);
    } else {
      U4D_CHECK(x.is_number(), "{}: '{}' must hold numbers, found {}", context, key, x.dump());
      out.push_back(x.get<double>());
    }
  };
  add(j.at(key));
  U4D_CHECK(out.size() == n, "{}: '{}' must have {} numbers, found {}", context, key, n,
            out.size());
  for (double d : out) U4D_CHECK(std::isfinite(d), "{}: '{}' has a non-finite value", context, key);
  return out;
}

Eigen::Matrix3d RowMajor3x3(const double* v) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = v[i];
  return m;
}

Eigen::Matrix3d RotationFromValues(const std::vector<double>& values) {
  U4D_ASSERT(values.size() == 3 || values.size() == 9);
  if (values.size() == 9) return RowMajor3x3(values.data());
  cv::Mat rvec(3, 1, CV_64F), rot;
  for (int i = 0; i < 3; ++i) rvec.at<double>(i) = values[i];
  cv::Rodrigues(rvec, rot);
  return RowMajor3x3(rot.ptr<double>());
}

// Checks `m` is a rotation to within `tol` (files write few digits), then
// returns the nearest exact rotation.
Eigen::Matrix3d CleanRotation(const Eigen::Matrix3d& m, const std::string& context, double tol) {
  U4D_CHECK(IsRotation(m, tol), "{}: the rotation is not a rotation matrix (|R R^T - I| or det)",
            context);
  return NearestRotation(m);
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool IsImageFile(const fs::path& p) {
  static const std::set<std::string> exts = {".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff"};
  return fs::is_regular_file(p) && exts.count(Lower(p.extension().string())) > 0;
}

std::vector<fs::path> SortedImages(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (IsImageFile(e.path())) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

cv::Size ImageSize(const fs::path& path) { return ReadColorImage(path).size(); }

VideoInfo ProbeVideo(const fs::path& path) {
  CheckFileExists(path, "video");
  cv::VideoCapture cap(path.string());
  U4D_CHECK(cap.isOpened(), "{}: cannot open video", path.string());
  VideoInfo info;
  info.frames = static_cast<int>(cap.get(cv::CAP_PROP_FRAME_COUNT));
  info.fps = cap.get(cv::CAP_PROP_FPS);
  info.size = {static_cast<int>(cap.get(cv::CAP_PROP_FRAME_WIDTH)),
               static_cast<int>(cap.get(cv::CAP_PROP_FRAME_HEIGHT))};
  U4D_CHECK(info.frames > 0, "{}: video reports no frames", path.string());
  return info;
}

fs::path Absolute(const fs::path& p) { return fs::absolute(p).lexically_normal(); }

// `source` itself when it is a file, else the one file in it ending in `suffix`.
fs::path FindOneFile(const fs::path& source, const std::string& suffix) {
  if (fs::is_regular_file(source)) return source;
  CheckDirExists(source, "source");
  std::vector<fs::path> found;
  for (const auto& e : fs::directory_iterator(source)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && name.size() >= suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      found.push_back(e.path());
  }
  U4D_CHECK(found.size() == 1, "{}: expected exactly one *{} file, found {}", source.string(),
            suffix, found.size());
  return found[0];
}

// Limits the capture to options.max_frames frames and sets its fps.
void Finish(Capture& capture, const ImportOptions& options, double source_fps) {
  if (options.max_frames > 0 && capture.num_frames > options.max_frames) {
    capture.num_frames = options.max_frames;
    for (CaptureView& v : capture.views)
      if (!v.source.files.empty()) v.source.files.resize(capture.num_frames);
    if (!capture.source_frames.empty()) capture.source_frames.resize(capture.num_frames);
  }
  capture.fps = options.fps > 0 ? options.fps : source_fps;
  capture.Check("import " + capture.root.string());
}

// Views from image folders: per view the sorted file stems; frames are the
// stems common to all views. `stem_to_frame` maps a file stem to a frame key.
void FillCommonImageFrames(Capture& capture, const std::vector<std::vector<fs::path>>& files,
                           const std::function<std::string(const fs::path&)>& frame_key) {
  std::vector<std::map<std::string, fs::path>> by_key(files.size());
  for (size_t v = 0; v < files.size(); ++v)
    for (const fs::path& f : files[v]) by_key[v][frame_key(f)] = f;
  std::vector<std::string> common;
  for (const auto& [key, path] : by_key[0]) {
    bool all = true;
    for (const auto& m : by_key) all = all && m.count(key);
    if (all) common.push_back(key);
  }
  U4D_CHECK(!common.empty(), "{}: the views have no frame in common", capture.root.string());
  capture.num_frames = static_cast<int>(common.size());
  for (size_t v = 0; v < files.size(); ++v) {
    FrameSource& src = capture.views[v].source;
    src.kind = FrameSource::Kind::kImages;
    for (const std::string& key : common) src.files.push_back(Absolute(by_key[v][key]).string());
  }
  capture.source_frames = SourceFrameNumbers(common);
}

// The keys as numbers when every key is one (digits only, at most 18 of
// them) and they increase, else none: the frames are then taken as
// consecutive.
std::vector<int64_t> SourceFrameNumbers(const std::vector<std::string>& keys) {
  std::vector<int64_t> numbers;
  for (const std::string& key : keys) {
    const bool digits =
        !key.empty() && key.size() <= 18 && std::all_of(key.begin(), key.end(), [](char ch) {
          return std::isdigit(static_cast<unsigned char>(ch));
        });
    if (!digits) return {};
    numbers.push_back(std::stoll(key));
    if (numbers.size() > 1 && numbers.back() <= numbers[numbers.size() - 2]) return {};
  }
  return numbers;
}

}  // namespace u4d::import_internal
