#include "u4d/io/import_calibration.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "u4d/io/file_storage.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/import_internal.h"
#include "u4d/io/import_opencv.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d {

using namespace import_internal;  // NOLINT(google-build-using-namespace): the importers' helpers

namespace {

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

// The value of name="value" (after white space) in a start tag. Searched by
// hand: std::regex recurses per character and overflows the stack on a long
// tag.
std::string Attribute(const std::string& tag_text, const std::string& name,
                      const std::string& context) {
  const std::string key = name + "=\"";
  for (size_t pos = tag_text.find(key); pos != std::string::npos;
       pos = tag_text.find(key, pos + 1)) {
    if (pos == 0 || !std::isspace(static_cast<unsigned char>(tag_text[pos - 1]))) continue;
    const size_t begin = pos + key.size();
    const size_t end = tag_text.find('"', begin);
    if (end == std::string::npos) break;
    return tag_text.substr(begin, end - begin);
  }
  ThrowError(
      fmt::format("{}: missing attribute '{}' in {}", context, name, tag_text.substr(0, 60)));
}

double NumberAttribute(const std::string& tag_text, const std::string& name,
                       const std::string& context) {
  return ParseFinite(Attribute(tag_text, name, context), context, name);
}

// ---- EasyMocap YAML ----------------------------------------------------------

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
    case ImportFormat::kOpenCv:
      return "opencv";
  }
  U4D_ASSERT(false);
  return {};
}

ImportFormat ImportFormatFromString(const std::string& s) {
  for (ImportFormat f :
       {ImportFormat::kPanoptic, ImportFormat::kQualisys, ImportFormat::kFourda,
        ImportFormat::kMiddlebury, ImportFormat::kEasyMocap, ImportFormat::kOpenCv})
    if (ToString(f) == s) return f;
  ThrowError(fmt::format(
      "unknown import format '{}' (expected panoptic, qualisys, fourda, middlebury, easymocap "
      "or opencv)",
      s));
}

void ImportOptions::Check() const {
  U4D_CHECK(max_frames >= 0, "ImportOptions: max_frames must be >= 0, found {}", max_frames);
  U4D_CHECK(fps >= 0 && std::isfinite(fps), "ImportOptions: fps must be >= 0, found {}", fps);
  U4D_CHECK(unit == "m" || unit == "cm" || unit == "mm",
            "ImportOptions: unit must be m, cm or mm, found '{}'", unit);
}

double ImportOptions::MetresPerUnit() const {
  Check();
  return unit == "mm" ? 1e-3 : unit == "cm" ? 1e-2 : 1.0;
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
    cam.width = ImageDimension(res[0], cctx, "width");
    cam.height = ImageDimension(res[1], cctx, "height");
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
    U4D_CHECK(!camera_tag.empty(), "{}: a <camera> start tag is not closed", ctx);
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
    cam.width = ImageDimension(right - left + 1, cctx, "width (fov_video right - left + 1)");
    cam.height = ImageDimension(bottom - top + 1, cctx, "height (fov_video bottom - top + 1)");
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
    cam.width = ImageDimension(size[0], cctx, "width");
    cam.height = ImageDimension(size[1], cctx, "height");
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
  U4D_CHECK(count_d >= 1 && count_d <= 1e6 && count_d == std::floor(count_d),
            "{}: bad image count '{}' (an integer in [1, 1000000])", ctx, token);
  const int count = static_cast<int>(count_d);
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

static std::vector<NamedCamera> EasyMocapCameras(const fs::path& intri_path,
                                                 const fs::path& extri_path,
                                                 const fs::path& image_root) {
  const cv::FileStorage intri_file = OpenFileStorage(intri_path, "EasyMocap intrinsics");
  const cv::FileStorage extri_file = OpenFileStorage(extri_path, "EasyMocap extrinsics");
  const cv::FileNode intri = intri_file.root(), extri = extri_file.root();
  const std::string ictx = intri_path.string(), ectx = extri_path.string();
  const std::vector<std::string> names = YamlNames(intri_file, ictx);
  std::vector<NamedCamera> out;
  for (const std::string& name : names) {
    NamedCamera nc;
    nc.name = name;
    Camera& cam = nc.camera;
    cam.K = RowMajor3x3(ReadNumbers(intri, "K_" + name, {9}, ictx).data());
    const std::vector<double> d = ReadNumbers(intri, "dist_" + name, {4, 5}, ictx);
    for (size_t i = 0; i < d.size(); ++i) cam.dist[i] = d[i];
    if (HasKey(intri, "H_" + name) && HasKey(intri, "W_" + name)) {
      cam.height = ReadInt(intri, "H_" + name, ictx);
      cam.width = ReadInt(intri, "W_" + name, ictx);
    } else {
      const fs::path folder = image_root / name;
      U4D_CHECK(!image_root.empty() && fs::is_directory(folder) && !SortedImages(folder).empty(),
                "{}: no H_{} / W_{} and no images in {} to take the size from", ictx, name, name,
                folder.string());
      const cv::Size size = ImageSize(SortedImages(folder)[0]);
      cam.width = size.width;
      cam.height = size.height;
    }
    const std::vector<double> r = HasKey(extri, "Rot_" + name)
                                      ? ReadNumbers(extri, "Rot_" + name, {9}, ectx)
                                      : ReadNumbers(extri, "R_" + name, {3}, ectx);
    const std::string cctx = fmt::format("{} / {}: camera {}", ictx, ectx, name);
    cam.cam_from_world.rotation = CleanRotation(RotationFromValues(r), cctx, 1e-4);
    const std::vector<double> t = ReadNumbers(extri, "T_" + name, {3}, ectx);
    cam.cam_from_world.translation = {t[0], t[1], t[2]};
    cam.Check(cctx);
    out.push_back(std::move(nc));
  }
  return out;
}

std::vector<NamedCamera> ReadEasyMocapCalibration(const fs::path& intri_path,
                                                  const fs::path& extri_path,
                                                  const fs::path& image_root) {
  // OpenCV's FileNode accessors fail with cv::Exception on a node of another
  // kind than asked (a map expected, a list found).
  try {
    return EasyMocapCameras(intri_path, extri_path, image_root);
  } catch (const cv::Exception& e) {
    ThrowError(fmt::format("{}, {}: not an EasyMocap calibration ({})", intri_path.string(),
                           extri_path.string(), e.what()));
  }
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
    case ImportFormat::kOpenCv:
      return ImportOpenCv(source, options);
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
