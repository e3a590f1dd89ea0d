#include "u4d/pipeline/run_log.h"

#include <algorithm>

#include <fmt/format.h>

#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d {

bool RunLog::StageDone(const std::string& name) const {
  return std::find(stages_done.begin(), stages_done.end(), name) != stages_done.end();
}

void RunLog::MarkStage(const std::string& name) {
  if (!StageDone(name)) stages_done.push_back(name);
}

void RunLog::AddReport(const StageReport& report) {
  for (StageReport& s : stages)
    if (s.name == report.name) {
      s.seconds += report.seconds;
      s.peak_rss_bytes = std::max(s.peak_rss_bytes, report.peak_rss_bytes);
      s.items += report.items;
      return;
    }
  stages.push_back(report);
}

void RunLog::AddSegmentPart(const std::string& name, double seconds) {
  for (PartTime& part : segment_parts)
    if (part.name == name) {
      part.seconds += seconds;
      return;
    }
  segment_parts.push_back({name, seconds});
}

std::string RunLog::FormatTable() const {
  std::string out =
      fmt::format("{:<16} {:>10} {:>14} {:>7}\n", "stage", "seconds", "peak memory", "items");
  double total = 0;
  int64_t peak = 0;
  for (const StageReport& s : stages) {
    out += fmt::format("{:<16} {:>10.1f} {:>11.0f} MB {:>7}\n", s.name, s.seconds,
                       s.peak_rss_bytes / 1048576.0, s.items);
    total += s.seconds;
    peak = std::max(peak, s.peak_rss_bytes);
    if (s.name == "segments")
      for (const PartTime& part : segment_parts)
        out += fmt::format("  {:<14} {:>10.1f}\n", part.name, part.seconds);
  }
  out += fmt::format("{:<16} {:>10.1f} {:>11.0f} MB\n", "total", total, peak / 1048576.0);
  return out;
}

void WriteRunLog(const fs::path& scene_dir, const RunLog& log) {
  nlohmann::json stages = nlohmann::json::array();
  for (const StageReport& s : log.stages)
    stages.push_back({{"name", s.name},
                      {"seconds", s.seconds},
                      {"peak_rss_mb", s.peak_rss_bytes / 1048576.0},
                      {"items", s.items}});
  nlohmann::json parts = nlohmann::json::array();
  for (const PartTime& part : log.segment_parts)
    parts.push_back({{"name", part.name}, {"seconds", part.seconds}});
  WriteJsonFileAtomic(scene_dir / layout::SceneRunLog(), {{"format", "u4d-run"},
                                                          {"capture", log.capture},
                                                          {"masks", log.masks},
                                                          {"poses", log.poses},
                                                          {"stages_done", log.stages_done},
                                                          {"segments_done", log.segments_done},
                                                          {"stages", stages},
                                                          {"segment_parts", parts},
                                                          {"empty_frames", log.empty_frames}});
}

RunLog ReadRunLog(const fs::path& scene_dir) {
  const fs::path path = scene_dir / layout::SceneRunLog();
  const nlohmann::json j = ReadJsonFile(path);
  const std::string ctx = path.string();
  U4D_CHECK(j.is_object() && j.value("format", "") == "u4d-run",
            "{}: not a u4d-run file (\"format\": \"u4d-run\" expected)", ctx);
  RunLog log;
  log.capture = JsonGet<std::string>(j, "capture", ctx);
  log.masks = JsonGet<std::string>(j, "masks", ctx);
  log.poses = JsonGet<std::string>(j, "poses", ctx);
  log.stages_done = JsonGet<std::vector<std::string>>(j, "stages_done", ctx);
  for (int s : JsonGet<std::vector<int>>(j, "segments_done", ctx)) log.segments_done.insert(s);
  for (const nlohmann::json& s : JsonGet<nlohmann::json>(j, "stages", ctx))
    log.stages.push_back(
        {JsonGet<std::string>(s, "name", ctx),
         JsonNumber(JsonGet<nlohmann::json>(s, "seconds", ctx), ctx, "seconds"),
         static_cast<int64_t>(
             JsonNumber(JsonGet<nlohmann::json>(s, "peak_rss_mb", ctx), ctx, "peak_rss_mb") *
             1048576.0),
         static_cast<int>(JsonInteger(JsonGet<nlohmann::json>(s, "items", ctx), ctx, "items"))});
  if (j.contains("segment_parts"))
    for (const nlohmann::json& part : JsonGet<nlohmann::json>(j, "segment_parts", ctx))
      log.segment_parts.push_back(
          {JsonGet<std::string>(part, "name", ctx),
           JsonNumber(JsonGet<nlohmann::json>(part, "seconds", ctx), ctx, "seconds")});
  if (j.contains("empty_frames"))
    log.empty_frames = JsonGet<std::vector<int>>(j, "empty_frames", ctx);
  return log;
}

}  // namespace u4d
