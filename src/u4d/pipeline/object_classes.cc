#include "u4d/pipeline/object_classes.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d {

ClassVotes VoteObjectClasses(const std::vector<cv::Mat>& objects,
                             const std::vector<InstanceMask>& detections) {
  U4D_CHECK(objects.size() == detections.size(),
            "VoteObjectClasses: {} object masks but {} detection masks", objects.size(),
            detections.size());
  ClassVotes votes;
  for (size_t v = 0; v < objects.size(); ++v) {
    const cv::Mat& obj = objects[v];
    const InstanceMask& det = detections[v];
    if (obj.empty() || det.ids.empty()) continue;
    U4D_CHECK(obj.size() == det.ids.size() && obj.type() == CV_16U && det.ids.type() == CV_16U,
              "VoteObjectClasses: view {}: object ids ({}x{}) and detections ({}x{}) must be "
              "CV_16U images of one size",
              v, obj.cols, obj.rows, det.ids.cols, det.ids.rows);
    std::map<int, std::string> class_of;  // detector id -> class
    for (const InstanceInfo& info : det.instances) class_of[info.id] = info.label;
    std::map<int, std::map<std::string, int>> pixels;  // object -> class -> pixels
    for (int y = 0; y < obj.rows; ++y)
      for (int x = 0; x < obj.cols; ++x) {
        const int o = obj.at<uint16_t>(y, x);
        if (!o) continue;
        const auto it = class_of.find(det.ids.at<uint16_t>(y, x));
        if (it != class_of.end()) ++pixels[o][it->second];
      }
    for (const auto& [o, by_class] : pixels) {
      const auto best =
          std::max_element(by_class.begin(), by_class.end(), [](const auto& a, const auto& b) {
            return a.second < b.second;  // first of equals wins
          });
      ++votes[o][best->first];
    }
  }
  return votes;
}

std::vector<cv::Mat> IdImages(const std::vector<InstanceMask>& masks) {
  std::vector<cv::Mat> ids;
  ids.reserve(masks.size());
  for (const InstanceMask& m : masks) ids.push_back(m.ids);
  return ids;
}

InstanceClasses InstanceClassesOf(const std::vector<InstanceMask>& masks) {
  InstanceClasses out(masks.size());
  for (size_t v = 0; v < masks.size(); ++v)
    for (const InstanceInfo& info : masks[v].instances) out[v][info.id] = info.label;
  return out;
}

std::vector<InstanceMask> KeepInstances(const std::vector<InstanceMask>& masks, bool people) {
  std::vector<InstanceMask> out(masks.size());
  for (size_t v = 0; v < masks.size(); ++v) {
    if (masks[v].ids.empty()) continue;
    std::vector<uint8_t> keep(65536, 0);  // per id (CV_16U), 1 when kept
    for (const InstanceInfo& info : masks[v].instances)
      if (IsPersonClass(info.label) == people) {
        out[v].instances.push_back(info);
        keep[static_cast<uint16_t>(info.id)] = 1;
      }
    out[v].ids = masks[v].ids.clone();
    for (int y = 0; y < out[v].ids.rows; ++y) {
      uint16_t* row = out[v].ids.ptr<uint16_t>(y);
      for (int x = 0; x < out[v].ids.cols; ++x)
        if (!keep[row[x]]) row[x] = 0;
    }
  }
  return out;
}

void AddClassVotes(const ClassVotes& votes, ClassVotes* total) {
  for (const auto& [id, by_class] : votes)
    for (const auto& [name, n] : by_class) (*total)[id][name] += n;
}

std::map<int, std::string> MajorityClasses(const ClassVotes& votes) {
  std::map<int, std::string> classes;
  for (const auto& [id, by_class] : votes) {
    std::string best;
    int most = 0;
    for (const auto& [name, n] : by_class)  // alphabetical: the first of equals stays
      if (n > most) best = name, most = n;
    const auto person = by_class.find(kDefaultClass);
    if (person != by_class.end() && person->second == most) best = kDefaultClass;
    if (most > 0) classes[id] = best;
  }
  return classes;
}

std::string ObjectClass(const std::map<int, std::string>& classes, int id) {
  const auto it = classes.find(id);
  return it == classes.end() ? kDefaultClass : it->second;
}

bool IsPersonClass(const std::string& class_name) { return class_name == kDefaultClass; }

nlohmann::json ClassVotesToJson(const ClassVotes& votes) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [id, by_class] : votes) j[std::to_string(id)] = by_class;
  return j;
}

ClassVotes ClassVotesFromJson(const nlohmann::json& j, const std::string& context) {
  U4D_CHECK(j.is_object(), "{}: \"classes\" must be an object {{\"<id>\": {{\"<class>\": votes}}}}",
            context);
  ClassVotes votes;
  for (auto it = j.begin(); it != j.end(); ++it) {
    int id = 0;
    try {
      size_t used = 0;
      id = std::stoi(it.key(), &used);
      if (used != it.key().size()) id = 0;
    } catch (const std::exception&) {
      id = 0;
    }
    U4D_CHECK(id >= 1, "{}: \"classes\" has the key '{}', not an object id >= 1", context,
              it.key());
    U4D_CHECK(it.value().is_object(), "{}: \"classes\" of object {} must map class to votes",
              context, id);
    for (auto c = it.value().begin(); c != it.value().end(); ++c) {
      const int64_t n = JsonInteger(c.value(), context, "a class vote count");
      U4D_CHECK(n >= 1, "{}: object {} has {} votes for '{}' (must be >= 1)", context, id, n,
                c.key());
      votes[id][c.key()] = static_cast<int>(n);
    }
  }
  return votes;
}

std::map<int, std::string> ReadRunObjectClasses(const fs::path& scene, int first, int last) {
  ClassVotes total;
  for (int f = first; f < last; ++f) {
    const fs::path path = scene / layout::SceneInitialObjects(f);
    const nlohmann::json j = ReadJsonFile(path);
    if (j.contains("classes"))
      AddClassVotes(ClassVotesFromJson(j["classes"], path.string()), &total);
  }
  return MajorityClasses(total);
}

}  // namespace u4d
