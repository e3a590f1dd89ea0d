#include "u4d/io/import_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "u4d/io/frame_reader.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

// ---- small parsing helpers ---------------------------------------------------

double ParseFinite(const std::string& token, const std::string& context, const std::string& what) {
  char* end = nullptr;
  const double v = std::strtod(token.c_str(), &end);
  U4D_CHECK(end != token.c_str() && *end == '\0', "{}: {} must be a number, found '{}'", context,
            what, token);
  U4D_CHECK(std::isfinite(v), "{}: {} is not finite ('{}')", context, what, token);
  return v;
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

// Checks `m` is a rotation to within `tol` (files write few digits), then
// returns the nearest exact rotation.
Eigen::Matrix3d CleanRotation(const Eigen::Matrix3d& m, const std::string& context,
                              double tol = 1e-2) {
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

cv::Size ImageSize(const fs::path& path) {
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  U4D_CHECK(!image.empty(), "{}: cannot read image", path.string());
  return image.size();
}

struct VideoInfo {
  int frames = 0;
  double fps = 0;
  cv::Size size;
};

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
}

// ---- Qualisys XML ------------------------------------------------------------

// The text of every "<tag ...>" start tag (attributes included) in `xml`.
std::vector<std::string> StartTags(const std::string& xml, const std::string& tag) {
  std::vector<std::string> out;
  const std::string open = "<" + tag + " ";
  for (size_t pos = xml.find(open); pos != std::string::npos; pos = xml.find(open, pos + 1)) {
    const size_t end = xml.find('>', pos);
    if (end == std::string::npos) break;
    out.push_back(xml.substr(pos, end - pos + 1));
  }
  return out;
}

std::string Attribute(const std::string& tag_text, const std::string& name,
                      const std::string& context) {
  const std::regex re("\\s" + name + "=\"([^\"]*)\"");
  std::smatch m;
  U4D_CHECK(std::regex_search(tag_text, m, re), "{}: missing attribute '{}' in {}", context, name,
            tag_text.substr(0, 60));
  return m[1].str();
}

double NumberAttribute(const std::string& tag_text, const std::string& name,
                       const std::string& context) {
  return ParseFinite(Attribute(tag_text, name, context), context, name);
}

// ---- EasyMocap YAML ----------------------------------------------------------

cv::Mat ReadYamlMat(const cv::FileStorage& fs, const std::string& key, int numel,
                    const std::string& context) {
  const cv::FileNode node = fs[key];
  U4D_CHECK(!node.empty() && !node.isNone(), "{}: missing key '{}'", context, key);
  cv::Mat m;
  try {
    node >> m;
  } catch (const cv::Exception& e) {
    ThrowError(fmt::format("{}: '{}' is not a matrix ({})", context, key, e.what()));
  }
  U4D_CHECK(!m.empty() && static_cast<int>(m.total()) * m.channels() == numel,
            "{}: '{}' must have {} values, found {}x{}", context, key, numel, m.rows, m.cols);
  m.convertTo(m, CV_64F);
  m = m.reshape(1, 1);
  for (int i = 0; i < numel; ++i)
    U4D_CHECK(std::isfinite(m.at<double>(i)), "{}: '{}' has a non-finite value", context, key);
  return m;
}

cv::FileStorage OpenYaml(const fs::path& path) {
  CheckFileExists(path, "EasyMocap calibration");
  cv::FileStorage fs;
  try {
    fs.open(path.string(), cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    ThrowError(fmt::format("{}: cannot parse as OpenCV YAML ({})", path.string(), e.what()));
  }
  U4D_CHECK(fs.isOpened(), "{}: cannot open as OpenCV YAML", path.string());
  return fs;
}

std::vector<std::string> YamlNames(const cv::FileStorage& fs, const std::string& context) {
  const cv::FileNode node = fs["names"];
  U4D_CHECK(node.isSeq(), "{}: missing 'names' list", context);
  std::vector<std::string> names;
  for (const auto& n : node) {
    U4D_CHECK(n.isString(), "{}: 'names' must hold strings", context);
    names.push_back(n.string());
  }
  U4D_CHECK(!names.empty(), "{}: 'names' is empty", context);
  return names;
}

}  // namespace

// ---- formats -----------------------------------------------------------------

std::string ToString(ImportFormat format) {
  switch (format) {
    case ImportFormat::kPanoptic:
      return "panoptic";
    case ImportFormat::kQualisys:
      return "qualisys";
    case ImportFormat::kFourda:
      return "fourda";
    case ImportFormat::kMiddlebury:
      return "middlebury";
    case ImportFormat::kEasyMocap:
      return "easymocap";
  }
  U4D_ASSERT(false);
  return {};
}

ImportFormat ImportFormatFromString(const std::string& s) {
  for (ImportFormat f : {ImportFormat::kPanoptic, ImportFormat::kQualisys, ImportFormat::kFourda,
                         ImportFormat::kMiddlebury, ImportFormat::kEasyMocap})
    if (ToString(f) == s) return f;
  ThrowError(fmt::format(
      "unknown import format '{}' (expected panoptic, qualisys, fourda, middlebury or easymocap)",
      s));
}

void ImportOptions::Check() const {
  U4D_CHECK(max_frames >= 0, "ImportOptions: max_frames must be >= 0, found {}", max_frames);
  U4D_CHECK(fps >= 0 && std::isfinite(fps), "ImportOptions: fps must be >= 0, found {}", fps);
}

// ---- Panoptic ----------------------------------------------------------------

std::vector<NamedCamera> ReadPanopticCalibration(const fs::path& json_path) {
  const nlohmann::json j = ReadJsonFile(json_path);
  const std::string ctx = json_path.string();
  U4D_CHECK(j.is_object() && j.contains("cameras") && j["cameras"].is_array(),
            "{}: missing 'cameras' array", ctx);
  std::vector<NamedCamera> out;
  for (const auto& c : j["cameras"]) {
    NamedCamera nc;
    nc.name = JsonGet<std::string>(c, "name", ctx);
    const std::string cctx = fmt::format("{}: camera {}", ctx, nc.name);
    const auto res = JsonNumbers(c, "resolution", 2, cctx);
    const auto k = JsonNumbers(c, "K", 9, cctx);
    const auto d = JsonNumbers(c, "distCoef", 5, cctx);
    const auto r = JsonNumbers(c, "R", 9, cctx);
    const auto t = JsonNumbers(c, "t", 3, cctx);
    Camera& cam = nc.camera;
    cam.width = static_cast<int>(res[0]);
    cam.height = static_cast<int>(res[1]);
    cam.K = RowMajor3x3(k.data());
    for (int i = 0; i < 5; ++i) cam.dist[i] = d[i];
    cam.cam_from_world.rotation = CleanRotation(RowMajor3x3(r.data()), cctx, 1e-4);
    cam.cam_from_world.translation = Eigen::Vector3d(t[0], t[1], t[2]) / 100.0;  // cm -> m
    cam.Check(cctx);
    out.push_back(std::move(nc));
  }
  U4D_CHECK(!out.empty(), "{}: no cameras", ctx);
  return out;
}

Capture ImportPanoptic(const fs::path& dir, const ImportOptions& options) {
  options.Check();
  CheckDirExists(dir, "Panoptic folder");
  const auto cameras = ReadPanopticCalibration(dir / "camera_parameters.json");
  Capture capture;
  capture.root = Absolute(dir);
  capture.name = capture.root.filename().string();
  std::vector<std::vector<fs::path>> files;
  for (const NamedCamera& nc : cameras) {
    const fs::path view_dir = dir / nc.name;
    if (!fs::is_directory(view_dir)) continue;
    std::vector<fs::path> images = SortedImages(view_dir);
    if (images.empty()) continue;
    CaptureView view;
    view.name = nc.name;
    view.cameras = {nc.camera};
    capture.views.push_back(view);
    files.push_back(std::move(images));
  }
  U4D_CHECK(!capture.views.empty(), "{}: no image folder named after a camera", dir.string());
  // <cam>_<frame>.jpg: the frame key is what follows the last '_'.
  FillCommonImageFrames(capture, files, [](const fs::path& p) {
    const std::string stem = p.stem().string();
    return stem.substr(stem.rfind('_') + 1);
  });
  Finish(capture, options, 29.97);
  return capture;
}

// ---- Qualisys ----------------------------------------------------------------

std::vector<NamedCamera> ReadQualisysCalibration(const fs::path& qca_path) {
  const std::string xml = ReadTextFile(qca_path);
  const std::string ctx = qca_path.string();
  U4D_CHECK(xml.find("<calibration") != std::string::npos, "{}: not a Qualisys calibration", ctx);
  std::vector<NamedCamera> out;
  size_t pos = 0;
  while ((pos = xml.find("<camera ", pos)) != std::string::npos) {
    const size_t end = xml.find("</camera>", pos);
    U4D_CHECK(end != std::string::npos, "{}: a <camera> element is not closed", ctx);
    const std::string block = xml.substr(pos, end - pos);
    pos = end;
    const auto camera_tag = StartTags(block, "camera");
    U4D_ASSERT(!camera_tag.empty());
    NamedCamera nc;
    nc.name = Attribute(camera_tag[0], "serial", ctx);
    const std::string cctx = fmt::format("{}: camera {}", ctx, nc.name);
    const auto fov = StartTags(block, "fov_video");
    const auto transform = StartTags(block, "transform");
    const auto intrinsic = StartTags(block, "intrinsic");
    U4D_CHECK(fov.size() == 1 && transform.size() == 1 && intrinsic.size() == 1,
              "{}: expected one fov_video, transform and intrinsic element", cctx);
    const double left = NumberAttribute(fov[0], "left", cctx);
    const double top = NumberAttribute(fov[0], "top", cctx);
    const double right = NumberAttribute(fov[0], "right", cctx);
    const double bottom = NumberAttribute(fov[0], "bottom", cctx);
    Camera& cam = nc.camera;
    cam.width = static_cast<int>(right - left + 1);
    cam.height = static_cast<int>(bottom - top + 1);
    auto in = [&](const char* name) { return NumberAttribute(intrinsic[0], name, cctx); };
    cam.K << in("focalLengthU") / 64.0, 0, in("centerPointU") / 64.0 - left,  //
        0, in("focalLengthV") / 64.0, in("centerPointV") / 64.0 - top,        //
        0, 0, 1;
    cam.dist = {in("radialDistortion1"), in("radialDistortion2"), in("tangentalDistortion1"),
                in("tangentalDistortion2"), in("radialDistortion3")};
    // r11..r33 fill the camera-to-world rotation column by column.
    Eigen::Matrix3d world_from_qcam_rot;
    const char* r_names[9] = {"r11", "r12", "r13", "r21", "r22", "r23", "r31", "r32", "r33"};
    for (int i = 0; i < 9; ++i)
      world_from_qcam_rot(i % 3, i / 3) = NumberAttribute(transform[0], r_names[i], cctx);
    Rigid3d world_from_qcam;
    world_from_qcam.rotation = CleanRotation(world_from_qcam_rot, cctx, 1e-4);
    world_from_qcam.translation = Eigen::Vector3d(NumberAttribute(transform[0], "x", cctx),
                                                  NumberAttribute(transform[0], "y", cctx),
                                                  NumberAttribute(transform[0], "z", cctx)) /
                                  1000.0;  // mm -> m
    // Qualisys cameras look along -z with y up: turn by pi about x into OpenCV's frame.
    Rigid3d cam_from_qcam;
    cam_from_qcam.rotation = Eigen::Vector3d(1, -1, -1).asDiagonal();
    cam.cam_from_world = cam_from_qcam * world_from_qcam.Inverse();
    cam.Check(cctx);
    out.push_back(std::move(nc));
  }
  U4D_CHECK(!out.empty(), "{}: no <camera> element", ctx);
  return out;
}

Capture ImportQualisys(const fs::path& source, const ImportOptions& options) {
  options.Check();
  const fs::path qca = FindOneFile(source, ".qca.txt");
  const auto cameras = ReadQualisysCalibration(qca);
  Capture capture;
  capture.root = Absolute(qca.parent_path());
  capture.name = capture.root.filename().string();
  capture.num_frames = 0;
  double fps = 0;
  for (const NamedCamera& nc : cameras) {
    const fs::path video = capture.root / "videos" / (nc.name + ".mp4");
    const VideoInfo info = ProbeVideo(video);
    // Videos may be coded with the size rounded up to a multiple of 16 and
    // cropped on decoding (1088 -> 1080): accept a crop of fewer than 16
    // pixels at the right/bottom, which leaves K unchanged.
    const int dw = nc.camera.width - info.size.width, dh = nc.camera.height - info.size.height;
    U4D_CHECK(dw >= 0 && dw < 16 && dh >= 0 && dh < 16,
              "{}: video is {}x{} but {} gives camera {} as {}x{}", video.string(), info.size.width,
              info.size.height, qca.string(), nc.name, nc.camera.width, nc.camera.height);
    CaptureView view;
    view.name = nc.name;
    view.cameras = {nc.camera};
    view.cameras[0].width = info.size.width;
    view.cameras[0].height = info.size.height;
    view.source.kind = FrameSource::Kind::kVideo;
    view.source.path = video.string();
    capture.views.push_back(view);
    capture.num_frames =
        capture.num_frames == 0 ? info.frames : std::min(capture.num_frames, info.frames);
    if (fps == 0 && info.fps > 0) fps = info.fps;
  }
  Finish(capture, options, fps > 0 ? fps : 60.0);
  return capture;
}

// ---- 4D Association ----------------------------------------------------------

std::vector<NamedCamera> ReadFourdaCalibration(const fs::path& json_path) {
  const nlohmann::json j = ReadJsonFile(json_path);
  const std::string ctx = json_path.string();
  U4D_CHECK(j.is_object() && !j.empty(), "{}: expected an object of cameras", ctx);
  std::vector<NamedCamera> out;
  for (const auto& [name, c] : j.items()) {
    NamedCamera nc;
    nc.name = name;
    const std::string cctx = fmt::format("{}: camera {}", ctx, name);
    const auto k = JsonNumbers(c, "K", 9, cctx);
    const auto rt = JsonNumbers(c, "RT", 12, cctx);
    const auto size = JsonNumbers(c, "imgSize", 2, cctx);
    Camera& cam = nc.camera;
    cam.width = static_cast<int>(size[0]);
    cam.height = static_cast<int>(size[1]);
    cam.K = RowMajor3x3(k.data());
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i)
      for (int c2 = 0; c2 < 3; ++c2) r(i, c2) = rt[4 * i + c2];
    cam.cam_from_world.rotation = CleanRotation(r, cctx);
    cam.cam_from_world.translation = {rt[3], rt[7], rt[11]};
    cam.Check(cctx);
    out.push_back(std::move(nc));
  }
  std::sort(out.begin(), out.end(),
            [](const NamedCamera& a, const NamedCamera& b) { return a.name < b.name; });
  return out;
}

Capture ImportFourda(const fs::path& dir, const ImportOptions& options) {
  options.Check();
  CheckDirExists(dir, "4D Association folder");
  const auto cameras = ReadFourdaCalibration(dir / "calibration.json");
  Capture capture;
  capture.root = Absolute(dir);
  capture.name = capture.root.filename().string();
  double fps = 0;
  for (const NamedCamera& nc : cameras) {
    CaptureView view;
    view.name = nc.name;
    view.cameras = {nc.camera};
    view.source.kind = FrameSource::Kind::kVideo;
    fs::path video = capture.root / "video" / (nc.name + ".mp4");
    if (!fs::exists(video)) video = capture.root / "videos" / (nc.name + ".mp4");
    view.source.path = video.string();
    if (fs::exists(video)) {
      const VideoInfo info = ProbeVideo(video);
      capture.num_frames =
          capture.num_frames == 0 ? info.frames : std::min(capture.num_frames, info.frames);
      if (fps == 0 && info.fps > 0) fps = info.fps;
    }
    capture.views.push_back(view);
  }
  if (capture.num_frames == 0) {
    // No videos (e.g. the Shelf files as published): take the frame count from
    // the detections or the ground truth; reading a frame then names the
    // missing video.
    for (const fs::path& p : {dir / "detection" / (cameras[0].name + ".txt"), dir / "gt.txt"}) {
      if (!fs::exists(p)) continue;
      std::istringstream in(ReadTextFile(p));
      int first = 0, frames = 0;
      U4D_CHECK(static_cast<bool>(in >> first >> frames) && frames > 0,
                "{}: bad header (expected '<type or joints> <frameCount>')", p.string());
      capture.num_frames = frames;
      break;
    }
  }
  U4D_CHECK(capture.num_frames > 0, "{}: no video, detection or gt.txt gives the frame count",
            dir.string());
  Finish(capture, options, fps > 0 ? fps : 25.0);
  return capture;
}

// ---- Middlebury --------------------------------------------------------------

std::vector<NamedCamera> ReadMiddleburyCalibration(const fs::path& par_path, int width,
                                                   int height) {
  const std::string ctx = par_path.string();
  std::istringstream in(ReadTextFile(par_path));
  std::string token;
  U4D_CHECK(static_cast<bool>(in >> token), "{}: empty file", ctx);
  const double count_d = ParseFinite(token, ctx, "the image count");
  const int count = static_cast<int>(count_d);
  U4D_CHECK(count > 0 && count == count_d, "{}: bad image count '{}'", ctx, token);
  std::vector<NamedCamera> out;
  for (int i = 0; i < count; ++i) {
    NamedCamera nc;
    U4D_CHECK(static_cast<bool>(in >> nc.name), "{}: file ends after {} of {} images", ctx, i,
              count);
    const std::string cctx = fmt::format("{}: image {}", ctx, nc.name);
    double v[21];
    for (int k = 0; k < 21; ++k) {
      U4D_CHECK(static_cast<bool>(in >> token), "{}: line ends after {} of 21 numbers", cctx, k);
      v[k] = ParseFinite(token, cctx, fmt::format("value {}", k + 1));
    }
    Camera& cam = nc.camera;
    cam.width = width;
    cam.height = height;
    cam.K = RowMajor3x3(v);
    cam.cam_from_world.rotation = CleanRotation(RowMajor3x3(v + 9), cctx, 1e-4);
    cam.cam_from_world.translation = {v[18], v[19], v[20]};
    cam.Check(cctx);
    out.push_back(std::move(nc));
  }
  U4D_CHECK(!(in >> token), "{}: unexpected text after {} images: '{}'", ctx, count, token);
  return out;
}

Capture ImportMiddlebury(const fs::path& source, const ImportOptions& options) {
  options.Check();
  const fs::path par = FindOneFile(source, "_par.txt");
  const fs::path dir = Absolute(par.parent_path());
  // The image size is not in the file: take it from the first image listed.
  std::istringstream in(ReadTextFile(par));
  std::string count, first;
  U4D_CHECK(static_cast<bool>(in >> count >> first), "{}: no image listed", par.string());
  CheckFileExists(dir / first, "image listed in " + par.string());
  const cv::Size size = ImageSize(dir / first);
  const auto cameras = ReadMiddleburyCalibration(par, size.width, size.height);
  Capture capture;
  capture.root = dir;
  capture.name = par.stem().string();
  capture.num_frames = 1;
  for (const NamedCamera& nc : cameras) {
    CaptureView view;
    view.name = fs::path(nc.name).stem().string();
    view.cameras = {nc.camera};
    view.source.files = {(dir / nc.name).string()};
    capture.views.push_back(view);
  }
  Finish(capture, options, 1.0);
  return capture;
}

// ---- EasyMocap ---------------------------------------------------------------

std::vector<NamedCamera> ReadEasyMocapCalibration(const fs::path& intri_path,
                                                  const fs::path& extri_path,
                                                  const fs::path& image_root) {
  const cv::FileStorage intri = OpenYaml(intri_path);
  const cv::FileStorage extri = OpenYaml(extri_path);
  const std::string ictx = intri_path.string(), ectx = extri_path.string();
  const std::vector<std::string> names = YamlNames(intri, ictx);
  std::vector<NamedCamera> out;
  for (const std::string& name : names) {
    NamedCamera nc;
    nc.name = name;
    Camera& cam = nc.camera;
    const cv::Mat k = ReadYamlMat(intri, "K_" + name, 9, ictx);
    cam.K = RowMajor3x3(k.ptr<double>());
    const cv::FileNode dist_node = intri["dist_" + name];
    const int dist_count = dist_node.empty() ? 0 : static_cast<int>(dist_node["data"].size());
    U4D_CHECK(dist_count == 4 || dist_count == 5, "{}: 'dist_{}' must have 4 or 5 values, found {}",
              ictx, name, dist_count);
    const cv::Mat d = ReadYamlMat(intri, "dist_" + name, dist_count, ictx);
    for (int i = 0; i < dist_count; ++i) cam.dist[i] = d.at<double>(i);
    if (!intri["H_" + name].empty() && !intri["W_" + name].empty()) {
      cam.height = static_cast<int>(intri["H_" + name]);
      cam.width = static_cast<int>(intri["W_" + name]);
    } else {
      const fs::path folder = image_root / name;
      U4D_CHECK(!image_root.empty() && fs::is_directory(folder) && !SortedImages(folder).empty(),
                "{}: no H_{} / W_{} and no images in {} to take the size from", ictx, name, name,
                folder.string());
      const cv::Size size = ImageSize(SortedImages(folder)[0]);
      cam.width = size.width;
      cam.height = size.height;
    }
    Eigen::Matrix3d r;
    if (!extri["Rot_" + name].empty()) {
      const cv::Mat rot = ReadYamlMat(extri, "Rot_" + name, 9, ectx);
      r = RowMajor3x3(rot.ptr<double>());
    } else {
      const cv::Mat rvec = ReadYamlMat(extri, "R_" + name, 3, ectx);
      cv::Mat rot;
      cv::Rodrigues(rvec.reshape(1, 3), rot);
      r = RowMajor3x3(rot.ptr<double>());
    }
    const std::string cctx = fmt::format("{} / {}: camera {}", ictx, ectx, name);
    cam.cam_from_world.rotation = CleanRotation(r, cctx, 1e-4);
    const cv::Mat t = ReadYamlMat(extri, "T_" + name, 3, ectx);
    cam.cam_from_world.translation = {t.at<double>(0), t.at<double>(1), t.at<double>(2)};
    cam.Check(cctx);
    out.push_back(std::move(nc));
  }
  return out;
}

Capture ImportEasyMocap(const fs::path& dir, const ImportOptions& options) {
  options.Check();
  CheckDirExists(dir, "EasyMocap folder");
  const auto cameras =
      ReadEasyMocapCalibration(dir / "intri.yml", dir / "extri.yml", dir / "images");
  Capture capture;
  capture.root = Absolute(dir);
  capture.name = capture.root.filename().string();
  double fps = 30.0;
  if (fs::is_directory(dir / "images")) {
    std::vector<std::vector<fs::path>> files;
    for (const NamedCamera& nc : cameras) {
      const fs::path folder = dir / "images" / nc.name;
      CheckDirExists(folder, "image folder of camera " + nc.name);
      files.push_back(SortedImages(folder));
      U4D_CHECK(!files.back().empty(), "{}: no images", folder.string());
      capture.views.push_back({nc.name, {nc.camera}, {}});
    }
    FillCommonImageFrames(capture, files, [](const fs::path& p) { return p.stem().string(); });
  } else {
    for (const NamedCamera& nc : cameras) {
      const fs::path video = capture.root / "videos" / (nc.name + ".mp4");
      const VideoInfo info = ProbeVideo(video);
      CaptureView view{nc.name, {nc.camera}, {}};
      view.source.kind = FrameSource::Kind::kVideo;
      view.source.path = video.string();
      capture.views.push_back(view);
      capture.num_frames =
          capture.num_frames == 0 ? info.frames : std::min(capture.num_frames, info.frames);
      if (info.fps > 0) fps = info.fps;
    }
  }
  Finish(capture, options, fps);
  return capture;
}

void WriteEasyMocap(const Capture& capture, const fs::path& out_dir, int max_frames) {
  capture.Check("WriteEasyMocap(" + out_dir.string() + ")");
  for (const CaptureView& v : capture.views)
    U4D_CHECK(!v.IsMoving(),
              "WriteEasyMocap: view {} has a moving camera; EasyMocap holds one "
              "camera per view",
              v.name);
  auto write_yaml = [&](const fs::path& path, bool intrinsics) {
    WriteAtomically(path, [&](const fs::path& tmp) {
      cv::FileStorage fs(tmp.string(), cv::FileStorage::WRITE);
      U4D_CHECK(fs.isOpened(), "cannot open {} for writing", tmp.string());
      fs << "names"
         << "[";
      for (const CaptureView& v : capture.views) fs << v.name;
      fs << "]";
      for (const CaptureView& v : capture.views) {
        const Camera& cam = v.cameras[0];
        if (intrinsics) {
          cv::Mat k(3, 3, CV_64F), d(1, 5, CV_64F);
          for (int i = 0; i < 9; ++i) k.at<double>(i / 3, i % 3) = cam.K(i / 3, i % 3);
          for (int i = 0; i < 5; ++i) d.at<double>(i) = cam.dist[i];
          fs << "K_" + v.name << k << "dist_" + v.name << d;
          fs << "H_" + v.name << cam.height << "W_" + v.name << cam.width;
        } else {
          cv::Mat rot(3, 3, CV_64F), rvec, t(3, 1, CV_64F);
          for (int i = 0; i < 9; ++i)
            rot.at<double>(i / 3, i % 3) = cam.cam_from_world.rotation(i / 3, i % 3);
          for (int i = 0; i < 3; ++i) t.at<double>(i) = cam.cam_from_world.translation[i];
          cv::Rodrigues(rot, rvec);
          fs << "R_" + v.name << rvec << "Rot_" + v.name << rot << "T_" + v.name << t;
        }
      }
      fs.release();
    });
  };
  write_yaml(out_dir / "intri.yml", true);
  write_yaml(out_dir / "extri.yml", false);
  const int frames = max_frames > 0 ? std::min(max_frames, capture.num_frames) : capture.num_frames;
  FrameReader reader(capture);
  for (int v = 0; v < capture.NumViews(); ++v) {
    for (int f = 0; f < frames; ++f) {
      const fs::path dst =
          out_dir / "images" / capture.views[v].name / (layout::FrameName(f) + ".jpg");
      const bool is_jpeg = capture.views[v].source.kind == FrameSource::Kind::kImages &&
                           Lower(capture.ImagePath(v, f).extension().string()) == ".jpg";
      if (is_jpeg) {
        const fs::path src = capture.ImagePath(v, f);
        CheckFileExists(src, "frame");
        WriteAtomically(dst, [&](const fs::path& tmp) {
          fs::copy_file(src, tmp, fs::copy_options::overwrite_existing);
        });
      } else {
        const cv::Mat image = reader.Read(v, f);
        WriteAtomically(dst, [&](const fs::path& tmp) {
          U4D_CHECK(cv::imwrite(tmp.string(), image), "cannot write {}", tmp.string());
        });
      }
    }
  }
}

// ---- dispatch and self-contained copy ----------------------------------------

Capture ImportCapture(ImportFormat format, const fs::path& source, const ImportOptions& options) {
  switch (format) {
    case ImportFormat::kPanoptic:
      return ImportPanoptic(source, options);
    case ImportFormat::kQualisys:
      return ImportQualisys(source, options);
    case ImportFormat::kFourda:
      return ImportFourda(source, options);
    case ImportFormat::kMiddlebury:
      return ImportMiddlebury(source, options);
    case ImportFormat::kEasyMocap:
      return ImportEasyMocap(source, options);
  }
  U4D_ASSERT(false);
  return {};
}

Capture WriteImportedCapture(const Capture& capture, const fs::path& dir) {
  capture.Check("WriteImportedCapture(" + dir.string() + ")");
  Capture out = capture;
  fs::create_directories(dir);
  auto copy = [](const fs::path& src, const fs::path& dst) {
    CheckFileExists(src, "frame source");
    WriteAtomically(dst, [&](const fs::path& tmp) {
      fs::copy_file(src, tmp, fs::copy_options::overwrite_existing);
    });
  };
  for (int v = 0; v < capture.NumViews(); ++v) {
    const CaptureView& in_view = capture.views[v];
    FrameSource& src = out.views[v].source;
    if (in_view.source.kind == FrameSource::Kind::kImages) {
      std::vector<std::string> files;
      std::set<std::string> exts;
      for (int f = 0; f < capture.num_frames; ++f) {
        const fs::path from = capture.ImagePath(v, f);
        const std::string ext = Lower(from.extension().string());
        const fs::path rel = fs::path("images") / in_view.name / (layout::FrameName(f) + ext);
        copy(from, dir / rel);
        files.push_back(rel.string());
        exts.insert(ext);
      }
      src.first_index = 0;
      if (exts.size() == 1) {
        src.files.clear();
        src.path = "images/" + in_view.name + "/{:06d}" + *exts.begin();
      } else {
        src.files = files;
        src.path.clear();
      }
    } else {
      const fs::path from = capture.root / in_view.source.path;
      if (!fs::exists(from)) {
        src.path = Absolute(from).string();  // stays unreadable, but names itself
        continue;
      }
      const fs::path rel = fs::path("videos") / (in_view.name + from.extension().string());
      copy(from, dir / rel);
      src.path = rel.string();
    }
  }
  WriteCapture(out, dir);
  return ReadCapture(dir);
}

}  // namespace u4d
