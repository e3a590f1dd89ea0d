#include "u4d/io/instance_mask.h"

#include <set>

#include "u4d/io/image_io.h"
#include "u4d/io/label_ids.h"
#include "u4d/util/check.h"
#include "u4d/util/json_checked.h"

namespace u4d {

const InstanceInfo* InstanceMask::Find(int id) const {
  for (const InstanceInfo& info : instances)
    if (info.id == id) return &info;
  return nullptr;
}

std::vector<InstanceInfo> ReadInstanceInfo(const fs::path& json) {
  std::vector<InstanceInfo> instances;
  const std::string ctx = json.string();
  const nlohmann::json j = JsonObject(ReadJsonFile(json), ctx);
  std::set<int> listed;
  for (const auto& ij : JsonRequired<std::vector<nlohmann::json>>(j, "instances", ctx)) {
    InstanceInfo info;
    info.id = JsonGet<int>(ij, "id", ctx);
    info.label = JsonOptional<std::string>(ij, "class", "person", ctx);
    info.score = JsonOptional<double>(ij, "score", 1.0, ctx);
    U4D_CHECK(info.id >= 1 && info.id < 65536, "{}: instance id {} out of range [1, 65535]", ctx,
              info.id);
    U4D_CHECK(std::isfinite(info.score) && info.score >= 0 && info.score <= 1,
              "{}: instance {} has score {} outside [0, 1]", ctx, info.id, info.score);
    U4D_CHECK(listed.insert(info.id).second, "{}: instance id {} listed twice", ctx, info.id);
    instances.push_back(info);
  }
  return instances;
}

InstanceMask ReadInstanceMask(const fs::path& png, const fs::path& json) {
  InstanceMask mask;
  mask.ids = ReadLabelImage(png);
  mask.instances = ReadInstanceInfo(json);
  for (int id : IdsIn(mask.ids))
    U4D_CHECK(mask.Find(id) != nullptr, "{}: id {} appears in {} but is not listed", json.string(),
              id, png.filename().string());
  return mask;
}

void WriteInstanceMask(const fs::path& png, const fs::path& json, const InstanceMask& mask) {
  U4D_CHECK(mask.ids.type() == CV_16UC1, "WriteInstanceMask({}): ids must be CV_16UC1",
            png.string());
  nlohmann::json inst = nlohmann::json::array();
  for (const InstanceInfo& info : mask.instances)
    inst.push_back({{"id", info.id}, {"class", info.label}, {"score", info.score}});
  WriteImage(png, mask.ids);
  WriteJsonFileAtomic(json, {{"instances", inst}});
}

cv::Mat ScoreImage(const InstanceMask& mask) {
  if (mask.ids.empty()) return {};
  cv::Mat scores(mask.ids.size(), CV_32F, cv::Scalar(1));
  for (const InstanceInfo& info : mask.instances) scores.setTo(info.score, mask.ids == info.id);
  return scores;
}

}  // namespace u4d
