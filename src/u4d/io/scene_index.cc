#include "u4d/io/scene_index.h"

#include <algorithm>
#include <set>

#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

constexpr const char* kFormat = "u4d-scene";

// Templates of the layout.h paths; {frame} is six digits, {object} two,
// {view} and {kind} verbatim. scene_index_test checks them against layout.h.
nlohmann::json FileTemplates() {
  return {{"calibration", "calibration.json"},
          {"keyframes", "keyframes.json"},
          {"eval", "eval.json"},
          {"picture", "pictures/{kind}/{view}/{frame}.png"},
          {"instances", "instances/{view}/{frame}.png"},
          {"depth", "depth/{view}/{frame}.pfm"},
          {"flow", "flow/{view}/{frame}.flo"},
          {"poses3d", "poses3d/{frame}.json"},
          {"tracks", "tracks/{view}.json"},
          {"mesh", "meshes/{object}/{frame}.ply"}};
}

int Int(const nlohmann::json& j, const std::string& key, const std::string& context) {
  U4D_CHECK(j.is_object() && j.contains(key), "{}: missing field '{}'", context, key);
  return static_cast<int>(JsonInteger(j.at(key), context, key));
}

std::vector<int> IntArray(const nlohmann::json& j, const std::string& key,
                          const std::string& context) {
  U4D_CHECK(j.is_object() && j.contains(key), "{}: missing field '{}'", context, key);
  const nlohmann::json& a = j.at(key);
  U4D_CHECK(a.is_array(), "{}: field '{}' must be an array, found {}", context, key, a.type_name());
  std::vector<int> out;
  for (size_t i = 0; i < a.size(); ++i)
    out.push_back(static_cast<int>(JsonInteger(a[i], context, fmt::format("{}[{}]", key, i))));
  return out;
}

bool OptionalBool(const nlohmann::json& j, const std::string& key, const std::string& context) {
  if (!j.contains(key)) return false;
  U4D_CHECK(j.at(key).is_boolean(), "{}: field '{}' must be true or false", context, key);
  return j.at(key).get<bool>();
}

}  // namespace

void SceneIndex::Check(const std::string& context) const {
  U4D_CHECK(fps > 0, "{}: 'fps' must be positive, found {}", context, fps);
  for (size_t i = 1; i < frames.size(); ++i)
    U4D_CHECK(frames[i] > frames[i - 1],
              "{}: 'frames' must be strictly increasing, found {} after {}", context, frames[i],
              frames[i - 1]);
  for (int f : frames) U4D_CHECK(f >= 0, "{}: 'frames' holds a negative frame {}", context, f);
  const std::set<int> frame_set(frames.begin(), frames.end());
  std::set<std::string> view_names;
  for (const SceneViewInfo& v : views) {
    U4D_CHECK(!v.name.empty(), "{}: 'views' holds a view without a name", context);
    U4D_CHECK(view_names.insert(v.name).second, "{}: 'views' names '{}' twice", context, v.name);
    U4D_CHECK(v.width > 0 && v.height > 0, "{}: view '{}' has size {}x{}, expected positive",
              context, v.name, v.width, v.height);
  }
  std::set<int> ids;
  for (const SceneObjectInfo& o : objects) {
    U4D_CHECK(o.id >= 1, "{}: 'objects' holds id {}, expected >= 1", context, o.id);
    U4D_CHECK(ids.insert(o.id).second, "{}: 'objects' lists id {} twice", context, o.id);
  }
  for (const SceneKeyframeInfo& k : keyframes) {
    U4D_CHECK(frame_set.count(k.frame), "{}: key-frame {} is not among 'frames'", context, k.frame);
    for (int m : k.members)
      U4D_CHECK(frame_set.count(m), "{}: key-frame {} has member {} not among 'frames'", context,
                k.frame, m);
  }
  for (const SceneSegmentInfo& s : segments) {
    U4D_CHECK(s.first <= s.last, "{}: segment {} has first {} > last {}", context, s.index, s.first,
              s.last);
    U4D_CHECK(frame_set.count(s.keyframe) && frame_set.count(s.first) && frame_set.count(s.last),
              "{}: segment {} refers to a frame not among 'frames' (key-frame {}, {}..{})", context,
              s.index, s.keyframe, s.first, s.last);
    for (const auto& [id, path] : s.glb)
      U4D_CHECK(ids.count(id), "{}: segment {} has a glb for unknown object {}", context, s.index,
                id);
  }
}

nlohmann::json SceneIndexToJson(const SceneIndex& index) {
  nlohmann::json j;
  j["format"] = kFormat;
  j["version"] = 1;
  j["name"] = index.name;
  j["fps"] = index.fps;
  j["frames"] = index.frames;
  j["views"] = nlohmann::json::array();
  for (const SceneViewInfo& v : index.views)
    j["views"].push_back({{"name", v.name}, {"width", v.width}, {"height", v.height}});
  j["objects"] = nlohmann::json::array();
  for (const SceneObjectInfo& o : index.objects)
    j["objects"].push_back(
        {{"id", o.id}, {"class", o.class_name}, {"color", {o.rgb[0], o.rgb[1], o.rgb[2]}}});
  j["keyframes"] = nlohmann::json::array();
  for (const SceneKeyframeInfo& k : index.keyframes)
    j["keyframes"].push_back({{"frame", k.frame}, {"members", k.members}});
  j["segments"] = nlohmann::json::array();
  for (const SceneSegmentInfo& s : index.segments) {
    nlohmann::json glb = nlohmann::json::object();
    for (const auto& [id, path] : s.glb) glb[std::to_string(id)] = path;
    j["segments"].push_back({{"index", s.index},
                             {"keyframe", s.keyframe},
                             {"first", s.first},
                             {"last", s.last},
                             {"dir", s.dir},
                             {"glb", glb}});
  }
  j["pictures"] = index.pictures;
  j["has_meshes"] = index.has_meshes;
  j["has_poses3d"] = index.has_poses3d;
  j["has_tracks"] = index.has_tracks;
  j["has_eval"] = index.has_eval;
  j["stages_done"] = index.stages_done;
  nlohmann::json bones = nlohmann::json::array();
  for (const auto& [a, b] : H36m17Bones()) bones.push_back({a, b});
  j["skeleton"] = {{"name", "h36m17"}, {"bones", bones}};
  j["files"] = FileTemplates();
  return j;
}

SceneIndex SceneIndexFromJson(const nlohmann::json& j, const std::string& context) {
  U4D_CHECK(j.is_object(), "{}: expected a JSON object", context);
  const std::string format = JsonGet<std::string>(j, "format", context);
  U4D_CHECK(format == kFormat, "{}: field 'format' is '{}', expected '{}'", context, format,
            kFormat);
  SceneIndex s;
  s.name = JsonGet<std::string>(j, "name", context);
  U4D_CHECK(j.contains("fps"), "{}: missing field 'fps'", context);
  s.fps = JsonNumber(j.at("fps"), context, "fps");
  s.frames = IntArray(j, "frames", context);
  for (const nlohmann::json& v : JsonGet<nlohmann::json>(j, "views", context)) {
    const std::string c = context + " 'views'";
    s.views.push_back(
        {JsonGet<std::string>(v, "name", c), Int(v, "width", c), Int(v, "height", c)});
  }
  for (const nlohmann::json& o : JsonGet<nlohmann::json>(j, "objects", context)) {
    const std::string c = context + " 'objects'";
    SceneObjectInfo info;
    info.id = Int(o, "id", c);
    info.class_name = JsonGet<std::string>(o, "class", c);
    const std::vector<int> rgb = IntArray(o, "color", c);
    U4D_CHECK(rgb.size() == 3, "{}: object {} field 'color' has {} values, expected 3", c, info.id,
              rgb.size());
    for (int k = 0; k < 3; ++k) {
      U4D_CHECK(rgb[k] >= 0 && rgb[k] <= 255,
                "{}: object {} field 'color' holds {}, expected 0..255", c, info.id, rgb[k]);
      info.rgb[k] = static_cast<uint8_t>(rgb[k]);
    }
    s.objects.push_back(info);
  }
  if (j.contains("keyframes"))
    for (const nlohmann::json& k : j.at("keyframes")) {
      const std::string c = context + " 'keyframes'";
      s.keyframes.push_back({Int(k, "frame", c), IntArray(k, "members", c)});
    }
  if (j.contains("segments"))
    for (const nlohmann::json& g : j.at("segments")) {
      const std::string c = context + " 'segments'";
      SceneSegmentInfo seg;
      seg.index = Int(g, "index", c);
      seg.keyframe = Int(g, "keyframe", c);
      seg.first = Int(g, "first", c);
      seg.last = Int(g, "last", c);
      seg.dir = JsonGet<std::string>(g, "dir", c);
      if (g.contains("glb")) {
        U4D_CHECK(g.at("glb").is_object(), "{}: segment {} field 'glb' must be an object", c,
                  seg.index);
        for (const auto& [key, path] : g.at("glb").items()) {
          int id = 0;
          try {
            id = std::stoi(key);
          } catch (const std::exception&) {
            ThrowError(fmt::format("{}: segment {} field 'glb' has key '{}', expected an object id",
                                   c, seg.index, key));
          }
          U4D_CHECK(path.is_string(), "{}: segment {} field 'glb.{}' must be a path", c, seg.index,
                    key);
          seg.glb[id] = path.get<std::string>();
        }
      }
      s.segments.push_back(seg);
    }
  if (j.contains("pictures"))
    s.pictures = JsonGet<std::vector<std::string>>(j, "pictures", context);
  s.has_meshes = OptionalBool(j, "has_meshes", context);
  s.has_poses3d = OptionalBool(j, "has_poses3d", context);
  s.has_tracks = OptionalBool(j, "has_tracks", context);
  s.has_eval = OptionalBool(j, "has_eval", context);
  if (j.contains("stages_done"))
    s.stages_done = JsonGet<std::vector<std::string>>(j, "stages_done", context);
  s.Check(context);
  return s;
}

void WriteSceneIndex(const fs::path& dir, const SceneIndex& index) {
  const fs::path path = dir / layout::SceneIndex();
  index.Check(path.string());
  WriteJsonFileAtomic(path, SceneIndexToJson(index));
}

SceneIndex ReadSceneIndex(const fs::path& dir) {
  const fs::path path = dir / layout::SceneIndex();
  return SceneIndexFromJson(ReadJsonFile(path), path.string());
}

}  // namespace u4d
