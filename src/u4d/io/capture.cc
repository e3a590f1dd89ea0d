#include "u4d/io/capture.h"

#include <set>

#include "u4d/util/check.h"
#include "u4d/util/json_checked.h"

namespace u4d {
namespace {
std::string FormatPattern(const std::string& pattern, int index, const std::string& context);
}  // namespace

std::string ToString(SceneType type) { return type == SceneType::kIndoor ? "indoor" : "outdoor"; }

SceneType SceneTypeFromString(const std::string& s, const std::string& context) {
  if (s == "indoor") return SceneType::kIndoor;
  if (s == "outdoor") return SceneType::kOutdoor;
  ThrowError(fmt::format("{}: scene must be 'indoor' or 'outdoor', found '{}'", context, s));
}

const Camera& CaptureView::CameraAt(int frame) const {
  U4D_ASSERT(!cameras.empty());
  if (cameras.size() == 1) return cameras[0];
  U4D_CHECK(frame >= 0 && frame < static_cast<int>(cameras.size()),
            "view {}: no camera for frame {} (have {})", name, frame, cameras.size());
  return cameras[frame];
}

int Capture::ViewIndex(const std::string& view_name) const {
  for (int i = 0; i < NumViews(); ++i)
    if (views[i].name == view_name) return i;
  ThrowError(fmt::format("capture {}: no view named '{}'", name, view_name));
}

fs::path Capture::ImagePath(int view, int frame) const {
  const FrameSource& src = views.at(view).source;
  U4D_CHECK(src.kind == FrameSource::Kind::kImages, "view {} is a video, not images",
            views[view].name);
  U4D_CHECK(frame >= 0 && frame < num_frames, "frame {} out of range [0, {})", frame, num_frames);
  if (!src.files.empty()) return root / src.files.at(frame);
  return root / FormatPattern(src.path, frame + src.first_index, views[view].name);
}

void Capture::Check(const std::string& context) const {
  U4D_CHECK(!views.empty(), "{}: the capture has no views", context);
  U4D_CHECK(num_frames > 0, "{}: num_frames must be positive, found {}", context, num_frames);
  U4D_CHECK(fps > 0 && std::isfinite(fps), "{}: fps must be positive, found {}", context, fps);
  std::set<std::string> names;
  for (const CaptureView& v : views) {
    U4D_CHECK(!v.name.empty(), "{}: a view has an empty name", context);
    U4D_CHECK(names.insert(v.name).second, "{}: duplicate view name '{}'", context, v.name);
    U4D_CHECK(!v.cameras.empty(), "{}: view {} has no camera", context, v.name);
    U4D_CHECK(v.cameras.size() == 1 || static_cast<int>(v.cameras.size()) == num_frames,
              "{}: moving view {} has {} cameras but the capture has {} frames", context, v.name,
              v.cameras.size(), num_frames);
    for (size_t i = 0; i < v.cameras.size(); ++i)
      v.cameras[i].Check(fmt::format("{}: view {} camera {}", context, v.name, i));
    if (v.source.kind == FrameSource::Kind::kImages && !v.source.files.empty()) {
      U4D_CHECK(static_cast<int>(v.source.files.size()) == num_frames,
                "{}: view {} lists {} frame files but the capture has {} frames", context, v.name,
                v.source.files.size(), num_frames);
    }
  }
  if (source_frames.empty()) return;
  U4D_CHECK(static_cast<int>(source_frames.size()) == num_frames,
            "{}: source_frames lists {} frames but the capture has {}", context,
            source_frames.size(), num_frames);
  for (int f = 0; f < num_frames; ++f)
    U4D_CHECK(source_frames[f] >= 0 && (f == 0 || source_frames[f] > source_frames[f - 1]),
              "{}: source_frames must be increasing non-negative numbers ({} at frame {})", context,
              source_frames[f], f);
}

bool ContinuesFrom(const Capture& capture, int frame, double max_gap_s) {
  U4D_CHECK(frame >= 0 && frame < capture.num_frames, "frame {} out of range [0, {})", frame,
            capture.num_frames);
  if (frame == 0) return false;
  if (capture.source_frames.empty()) return true;
  const int64_t gap = capture.source_frames[frame] - capture.source_frames[frame - 1];
  return static_cast<double>(gap) / capture.fps <= max_gap_s;
}

namespace {

std::vector<double> FlatList(const nlohmann::json& j, size_t n, const std::string& context,
                             const std::string& key) {
  U4D_CHECK(j.contains(key), "{}: missing '{}'", context, key);
  const nlohmann::json& v = j.at(key);
  std::vector<double> out;
  auto push = [&](const nlohmann::json& x) {
    U4D_CHECK(x.is_number(), "{}: '{}' must hold numbers", context, key);
    out.push_back(x.get<double>());
  };
  U4D_CHECK(v.is_array(), "{}: '{}' must be an array", context, key);
  for (const auto& x : v) {
    if (x.is_array()) {
      for (const auto& y : x) push(y);
    } else {
      push(x);
    }
  }
  U4D_CHECK(out.size() == n, "{}: '{}' must have {} numbers, found {}", context, key, n,
            out.size());
  for (double d : out) U4D_CHECK(std::isfinite(d), "{}: '{}' has a non-finite value", context, key);
  return out;
}

}  // namespace

Camera CameraFromJson(const nlohmann::json& j, const std::string& context) {
  Camera cam;
  // The same plausibility bound as the binary image readers (io/image_io.h).
  cam.width = JsonRequiredInt(j, "width", 1, 99999, context);
  cam.height = JsonRequiredInt(j, "height", 1, 99999, context);
  const auto k = FlatList(j, 9, context, "K");
  for (int i = 0; i < 9; ++i) cam.K(i / 3, i % 3) = k[i];
  if (j.contains("dist")) {
    const auto d = FlatList(j, 5, context, "dist");
    for (int i = 0; i < 5; ++i) cam.dist[i] = d[i];
  }
  const auto r = FlatList(j, 9, context, "R");
  for (int i = 0; i < 9; ++i) cam.cam_from_world.rotation(i / 3, i % 3) = r[i];
  const auto t = FlatList(j, 3, context, "t");
  cam.cam_from_world.translation = {t[0], t[1], t[2]};
  cam.Check(context);
  return cam;
}

nlohmann::json CameraToJson(const Camera& cam) {
  nlohmann::json j;
  j["width"] = cam.width;
  j["height"] = cam.height;
  j["K"] = {{cam.K(0, 0), cam.K(0, 1), cam.K(0, 2)},
            {cam.K(1, 0), cam.K(1, 1), cam.K(1, 2)},
            {cam.K(2, 0), cam.K(2, 1), cam.K(2, 2)}};
  j["dist"] = cam.dist;
  const Eigen::Matrix3d& r = cam.cam_from_world.rotation;
  j["R"] = {{r(0, 0), r(0, 1), r(0, 2)}, {r(1, 0), r(1, 1), r(1, 2)}, {r(2, 0), r(2, 1), r(2, 2)}};
  const Eigen::Vector3d& t = cam.cam_from_world.translation;
  j["t"] = {t.x(), t.y(), t.z()};
  return j;
}

nlohmann::json CalibrationToJson(const Capture& capture) {
  nlohmann::json cams = nlohmann::json::array();
  for (const CaptureView& v : capture.views) {
    nlohmann::json c;
    c["view"] = v.name;
    if (v.IsMoving()) {
      c["per_frame"] = nlohmann::json::array();
      for (const Camera& cam : v.cameras) c["per_frame"].push_back(CameraToJson(cam));
    } else {
      c.update(CameraToJson(v.cameras[0]));
    }
    cams.push_back(c);
  }
  return {{"format", "u4d-calibration"},
          {"version", 1},
          {"units", "metres"},
          {"convention", "cam_from_world: x_cam = R x_world + t; OpenCV distortion k1 k2 p1 p2 k3"},
          {"cameras", cams}};
}

namespace {

// Formats an image path pattern ("images/cam00/{:06d}.png") for one index; a
// malformed pattern is a u4d::Error naming `context`, not fmt's format_error.
std::string FormatPattern(const std::string& pattern, int index, const std::string& context) {
  try {
    return fmt::format(fmt::runtime(pattern), index);
  } catch (const fmt::format_error& e) {
    ThrowError(
        fmt::format("{}: invalid path pattern '{}' ({}); expected one field such as {{:06d}}",
                    context, pattern, e.what()));
  }
}

FrameSource SourceFromJson(const nlohmann::json& vj, const std::string& view,
                           const std::string& mctx) {
  const std::string ctx = fmt::format("{}: view {}", mctx, view);
  FrameSource source;
  const std::string kind = JsonOptional<std::string>(vj, "source", "images", ctx);
  U4D_CHECK(kind == "images" || kind == "video", "{}: source must be images or video, found '{}'",
            ctx, kind);
  source.kind = kind == "images" ? FrameSource::Kind::kImages : FrameSource::Kind::kVideo;
  source.path = JsonOptional<std::string>(vj, "path", "", ctx);
  source.first_index = JsonOptional<int>(vj, "first_index", 0, ctx);
  U4D_CHECK(source.first_index >= 0, "{}: 'first_index' must be >= 0, found {}", ctx,
            source.first_index);
  source.files = JsonOptional<std::vector<std::string>>(vj, "files", {}, ctx);
  U4D_CHECK(!source.path.empty() || !source.files.empty(), "{}: neither 'path' nor 'files'", ctx);
  if (source.kind == FrameSource::Kind::kImages && source.files.empty())
    FormatPattern(source.path, source.first_index, ctx);
  return source;
}

// The cameras of `view` in calibration.json's 'cameras' array (one, or one
// per frame under 'per_frame'); empty when the view has none.
std::vector<Camera> CamerasOfView(const nlohmann::json& cameras, const std::string& view,
                                  const std::string& cctx) {
  std::vector<Camera> out;
  for (const auto& cj : cameras) {
    if (JsonRequired<std::string>(cj, "view", cctx) != view) continue;
    const std::string ctx = fmt::format("{}: view {}", cctx, view);
    U4D_CHECK(out.empty(), "{}: more than one camera record for the view", ctx);
    if (cj.contains("per_frame")) {
      const auto per_frame = JsonRequired<std::vector<nlohmann::json>>(cj, "per_frame", ctx);
      U4D_CHECK(!per_frame.empty(), "{}: 'per_frame' is empty", ctx);
      for (size_t i = 0; i < per_frame.size(); ++i)
        out.push_back(CameraFromJson(per_frame[i], fmt::format("{} frame {}", ctx, i)));
    } else {
      out.push_back(CameraFromJson(cj, ctx));
    }
  }
  return out;
}

}  // namespace

Capture ReadCapture(const fs::path& dir) {
  CheckDirExists(dir, "capture directory");
  const fs::path manifest_path = dir / "capture.json";
  const fs::path calib_path = dir / "calibration.json";
  const std::string mctx = manifest_path.string();
  const nlohmann::json m = JsonObject(ReadJsonFile(manifest_path), mctx);
  U4D_CHECK(JsonOptional<std::string>(m, "format", "", mctx) == "u4d-capture",
            "{}: 'format' must be 'u4d-capture'", mctx);

  Capture capture;
  capture.root = dir;
  capture.name = JsonOptional<std::string>(m, "name", dir.filename().string(), mctx);
  capture.scene = SceneTypeFromString(JsonOptional<std::string>(m, "scene", "indoor", mctx), mctx);
  capture.fps = JsonGet<double>(m, "fps", mctx);
  capture.num_frames = JsonGet<int>(m, "num_frames", mctx);
  capture.classes = JsonOptional<std::vector<std::string>>(m, "classes", capture.classes, mctx);
  capture.source_frames = JsonOptional<std::vector<int64_t>>(m, "source_frames", {}, mctx);
  const auto views = JsonRequired<std::vector<nlohmann::json>>(m, "views", mctx);

  const std::string cctx = calib_path.string();
  const nlohmann::json calib = JsonObject(ReadJsonFile(calib_path), cctx);
  const auto cameras = JsonRequired<std::vector<nlohmann::json>>(calib, "cameras", cctx);
  std::set<std::string> view_names;
  for (const auto& vj : views) {
    CaptureView view;
    view.name = JsonGet<std::string>(vj, "name", mctx);
    view_names.insert(view.name);
    view.source = SourceFromJson(vj, view.name, mctx);
    view.cameras = CamerasOfView(cameras, view.name, cctx);
    U4D_CHECK(!view.cameras.empty(), "{}: no camera for view '{}' listed in {}", cctx, view.name,
              mctx);
    capture.views.push_back(std::move(view));
  }
  // A camera for a view the manifest does not list is most likely a typo in
  // a view name; refuse rather than silently ignore it.
  for (const auto& cj : cameras) {
    const std::string name = JsonRequired<std::string>(cj, "view", cctx);
    U4D_CHECK(view_names.count(name), "{}: camera for view '{}', which {} does not list", cctx,
              name, mctx);
  }
  capture.Check(mctx);
  return capture;
}

void WriteCapture(const Capture& capture, const fs::path& dir) {
  capture.Check("WriteCapture(" + dir.string() + ")");
  nlohmann::json views = nlohmann::json::array();
  for (const CaptureView& v : capture.views) {
    nlohmann::json vj = {
        {"name", v.name},
        {"source", v.source.kind == FrameSource::Kind::kImages ? "images" : "video"},
        {"moving", v.IsMoving()}};
    if (!v.source.path.empty()) vj["path"] = v.source.path;
    if (!v.source.files.empty()) vj["files"] = v.source.files;
    if (v.source.first_index != 0) vj["first_index"] = v.source.first_index;
    views.push_back(vj);
  }
  nlohmann::json manifest = {{"format", "u4d-capture"},    {"version", 1},
                             {"name", capture.name},       {"scene", ToString(capture.scene)},
                             {"fps", capture.fps},         {"num_frames", capture.num_frames},
                             {"classes", capture.classes}, {"views", views}};
  if (!capture.source_frames.empty()) manifest["source_frames"] = capture.source_frames;
  WriteJsonFileAtomic(dir / "calibration.json", CalibrationToJson(capture));
  WriteJsonFileAtomic(dir / "capture.json", manifest);
}

}  // namespace u4d
