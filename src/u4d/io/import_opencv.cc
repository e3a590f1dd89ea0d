// `u4d import opencv` (import_opencv.h).
#include "u4d/io/import_opencv.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "u4d/io/file_storage.h"
#include "u4d/io/import_internal.h"
#include "u4d/util/check.h"

namespace u4d {

using namespace import_internal;  // NOLINT(google-build-using-namespace): the importers' helpers

namespace {

const std::vector<std::string> kIntrinsicKeys = {
    "camera_matrix", "CameraMatrix", "cameraMatrix", "K", "intrinsic_matrix", "IntrinsicMatrix"};
const std::vector<std::string> kDistortionKeys = {"distortion_coefficients",
                                                  "DistortionCoeffs",
                                                  "DistortionCoefficients",
                                                  "distCoeffs",
                                                  "dist_coeffs",
                                                  "dist",
                                                  "D"};
const std::vector<std::string> kRotationKeys = {"rvec", "RotationValues",  "rotation",      "R",
                                                "Rot",  "rotation_matrix", "RotationMatrix"};
const std::vector<std::string> kTranslationKeys = {"tvec", "TranslationValues", "translation", "T",
                                                   "t"};
const std::vector<std::pair<std::string, std::string>> kSizeKeyPairs = {
    {"image_width", "image_height"}, {"ImageWidth", "ImageHeight"}, {"width", "height"}};
const std::vector<std::string> kSizeKeys = {"image_size", "imageSize", "ImageSize"};

std::string KeyList(const std::vector<std::string>& keys) {
  std::string s;
  for (const std::string& k : keys) s += (s.empty() ? "" : ", ") + k;
  return s;
}

// The first spelling present; throws naming the spellings when none is.
std::string RequiredKey(const cv::FileNode& map, const std::vector<std::string>& keys,
                        const std::string& what, const std::string& context) {
  std::string key = FirstKey(map, keys);
  U4D_CHECK(!key.empty(), "{}: no {} (expected one of the keys {})", context, what, KeyList(keys));
  return key;
}

// Width and height from the size keys, or 0 x 0 when there are none.
cv::Size ReadImageSize(const cv::FileNode& map, const std::string& context) {
  cv::Size size(0, 0);
  for (const auto& [w, h] : kSizeKeyPairs) {
    if (!HasKey(map, w) || !HasKey(map, h)) continue;
    size = {ReadInt(map, w, context), ReadInt(map, h, context)};
    U4D_CHECK(size.width > 0 && size.height > 0, "{}: '{}' x '{}' must be positive, found {}x{}",
              context, w, h, size.width, size.height);
    return size;
  }
  const std::string key = FirstKey(map, kSizeKeys);
  if (key.empty()) return size;
  const std::vector<double> v = ReadNumbers(map, key, {2}, context);
  const std::string what = fmt::format("'{}'", key);
  return {ImageDimension(v[0], context, what + " width"),
          ImageDimension(v[1], context, what + " height")};
}

// One camera from a map holding the keys; `context` names file and camera.
Camera ReadCamera(const cv::FileNode& map, double metres_per_unit, const std::string& context) {
  Camera cam;
  const std::string k_key = RequiredKey(map, kIntrinsicKeys, "camera matrix", context);
  cam.K = RowMajor3x3(ReadNumbers(map, k_key, {9}, context).data());
  const std::string d_key = FirstKey(map, kDistortionKeys);
  if (!d_key.empty()) {
    const std::vector<double> d = ReadNumbers(map, d_key, {4, 5, 8, 12, 14}, context);
    for (size_t i = 0; i < d.size(); ++i) {
      if (i < 5) {
        cam.dist[i] = d[i];
      } else {
        U4D_CHECK(d[i] == 0,
                  "{}: '{}' value {} is {}: only k1, k2, p1, p2, k3 are supported (the rational, "
                  "thin-prism and tilt terms must be 0)",
                  context, d_key, i + 1, d[i]);
      }
    }
  }
  const std::string r_key = RequiredKey(map, kRotationKeys, "rotation", context);
  const std::string t_key = RequiredKey(map, kTranslationKeys, "translation", context);
  const std::vector<double> r = ReadNumbers(map, r_key, {3, 9}, context);
  cam.cam_from_world.rotation =
      CleanRotation(RotationFromValues(r), fmt::format("{}: '{}'", context, r_key), 1e-4);
  const std::vector<double> t = ReadNumbers(map, t_key, {3}, context);
  cam.cam_from_world.translation = Eigen::Vector3d(t[0], t[1], t[2]) * metres_per_unit;
  const cv::Size size = ReadImageSize(map, context);
  cam.width = size.width;
  cam.height = size.height;
  if (cam.width > 0) cam.Check(context);
  return cam;
}

// The cameras of one file: itself one camera, or one per top-level map.
std::vector<NamedCamera> ReadFile(const fs::path& path, double metres_per_unit) {
  const cv::FileStorage storage = OpenFileStorage(path, "OpenCV calibration");
  const cv::FileNode root = storage.root();
  const std::string ctx = path.string();
  if (!FirstKey(root, kIntrinsicKeys).empty())
    return {{path.stem().string(), ReadCamera(root, metres_per_unit, ctx)}};
  std::vector<NamedCamera> out;
  if (root.isMap()) {
    for (const cv::FileNode& node : root) {
      if (!node.isMap() || FirstKey(node, kIntrinsicKeys).empty()) continue;
      const std::string cctx = fmt::format("{}: camera {}", ctx, node.name());
      out.push_back({node.name(), ReadCamera(node, metres_per_unit, cctx)});
    }
  }
  U4D_CHECK(!out.empty(),
            "{}: no camera found (expected a camera matrix key, one of {}, at the top level or "
            "in one top-level section per camera)",
            ctx, KeyList(kIntrinsicKeys));
  return out;
}

bool IsCalibrationFile(const fs::path& p) {
  const std::string ext = Lower(p.extension().string());
  return fs::is_regular_file(p) && (ext == ".xml" || ext == ".yml" || ext == ".yaml");
}

// The calibration files of a folder source, and the folder the frames are under.
std::vector<fs::path> CalibrationFiles(const fs::path& source, fs::path* media_root) {
  if (fs::is_regular_file(source)) {
    *media_root = Absolute(source).parent_path();
    const std::string folder = media_root->filename().string();
    if (folder == "calibration" || folder == "calib") *media_root = media_root->parent_path();
    return {source};
  }
  CheckDirExists(source, "OpenCV calibration source");
  *media_root = Absolute(source);
  for (const fs::path& dir : {source, source / "calibration", source / "calib"}) {
    if (!fs::is_directory(dir)) continue;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
      if (IsCalibrationFile(e.path())) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    if (!files.empty()) return files;
  }
  ThrowError(
      fmt::format("{}: no calibration file (*.xml, *.yml, *.yaml) in it or in its "
                  "calibration/ or calib/ subfolder",
                  source.string()));
}

// The frame number of an image: the last run of digits of its stem (the
// stem itself when it has none), so cam1_0007.png and cam2_0007.png pair.
std::string FrameKey(const fs::path& p) {
  std::string stem = p.stem().string();
  size_t end = stem.size();
  while (end > 0 && !std::isdigit(static_cast<unsigned char>(stem[end - 1]))) --end;
  size_t begin = end;
  while (begin > 0 && std::isdigit(static_cast<unsigned char>(stem[begin - 1]))) --begin;
  if (begin == end) return stem;
  const std::string digits = stem.substr(begin, end - begin);
  // Numeric order as text order: pad to a fixed width.
  return std::string(std::max<size_t>(0, 12 - digits.size()), '0') + digits;
}

fs::path FindImageFolder(const fs::path& root, const std::string& name) {
  for (const fs::path& dir : {root / name, root / "images" / name})
    if (fs::is_directory(dir) && !SortedImages(dir).empty()) return dir;
  return {};
}

fs::path FindVideo(const fs::path& root, const std::string& name) {
  for (const fs::path& dir : {root, root / "videos"}) {
    if (!fs::is_directory(dir)) continue;
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string ext = Lower(e.path().extension().string());
      const bool video = ext == ".mp4" || ext == ".avi" || ext == ".mov" || ext == ".mkv" ||
                         ext == ".webm" || ext == ".mpg" || ext == ".m4v";
      if (video && e.is_regular_file() && e.path().stem() == name) return e.path();
    }
  }
  return {};
}

// Sets each view's size from its first frame where the files gave none
// (and checks the camera), or checks the files' size against the frames.
void SizeFromFrames(Capture& capture, const std::vector<cv::Size>& frame_sizes) {
  for (size_t v = 0; v < capture.views.size(); ++v) {
    Camera& cam = capture.views[v].cameras[0];
    const std::string ctx =
        fmt::format("{}: camera {}", capture.root.string(), capture.views[v].name);
    if (cam.width == 0) {
      cam.width = frame_sizes[v].width;
      cam.height = frame_sizes[v].height;
      cam.Check(ctx);
    }
    U4D_CHECK(cam.width == frame_sizes[v].width && cam.height == frame_sizes[v].height,
              "{}: the calibration gives {}x{} but the frames are {}x{}", ctx, cam.width,
              cam.height, frame_sizes[v].width, frame_sizes[v].height);
  }
}

}  // namespace

std::vector<NamedCamera> ReadOpenCvCalibration(const fs::path& source, double metres_per_unit) {
  U4D_CHECK(metres_per_unit > 0 && std::isfinite(metres_per_unit),
            "ReadOpenCvCalibration({}): metres_per_unit must be > 0, found {}", source.string(),
            metres_per_unit);
  fs::path media_root;
  std::vector<NamedCamera> out;
  for (const fs::path& file : CalibrationFiles(source, &media_root)) {
    for (NamedCamera& nc : ReadFile(file, metres_per_unit)) {
      for (const NamedCamera& seen : out)
        U4D_CHECK(seen.name != nc.name, "{}: camera '{}' is given twice", file.string(), nc.name);
      out.push_back(std::move(nc));
    }
  }
  return out;
}

Capture ImportOpenCv(const fs::path& source, const ImportOptions& options) {
  options.Check();
  const std::vector<NamedCamera> cameras = ReadOpenCvCalibration(source, options.MetresPerUnit());
  fs::path root;
  CalibrationFiles(source, &root);
  Capture capture;
  capture.root = root;
  capture.name = root.filename().string();
  std::vector<std::vector<fs::path>> images;
  std::vector<fs::path> videos;
  std::vector<cv::Size> sizes;
  for (const NamedCamera& nc : cameras) {
    capture.views.push_back({nc.name, {nc.camera}, {}});
    const fs::path folder = FindImageFolder(root, nc.name);
    if (!folder.empty()) {
      images.push_back(SortedImages(folder));
      sizes.push_back(ImageSize(images.back()[0]));
      continue;
    }
    const fs::path video = FindVideo(root, nc.name);
    U4D_CHECK(!video.empty(),
              "{}: no frames for camera '{}' (expected an image folder {}/ or images/{}/, or a "
              "video {}.mp4 (.avi, .mov, ...) or videos/{}.mp4 there)",
              root.string(), nc.name, nc.name, nc.name, nc.name, nc.name);
    videos.push_back(video);
  }
  U4D_CHECK(images.empty() || videos.empty(),
            "{}: some cameras have image folders and others videos; give one kind", root.string());
  double fps = 30.0;
  if (!images.empty()) {
    FillCommonImageFrames(capture, images, FrameKey);
  } else {
    for (size_t v = 0; v < videos.size(); ++v) {
      const VideoInfo info = ProbeVideo(videos[v]);
      FrameSource& src = capture.views[v].source;
      src.kind = FrameSource::Kind::kVideo;
      src.path = Absolute(videos[v]).string();
      capture.num_frames = v == 0 ? info.frames : std::min(capture.num_frames, info.frames);
      if (v == 0 && info.fps > 0) fps = info.fps;
      sizes.push_back(info.size);
    }
  }
  SizeFromFrames(capture, sizes);
  Finish(capture, options, fps);
  return capture;
}

}  // namespace u4d
