#include "u4d/features/temporal_tracks.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "u4d/io/frame_reader.h"
#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

namespace u4d {

const Eigen::Vector2d* TemporalTrack::At(int frame) const {
  const auto it = std::lower_bound(points.begin(), points.end(), frame,
                                   [](const auto& p, int f) { return p.first < f; });
  return it != points.end() && it->first == frame ? &it->second : nullptr;
}

void TemporalTrackOptions::Check() const {
  U4D_CHECK(window >= 1, "TemporalTrackOptions.window must be >= 1, got {}", window);
  U4D_CHECK(ratio > 0 && ratio <= 1, "TemporalTrackOptions.ratio must be in (0, 1], got {}", ratio);
  U4D_CHECK(max_features >= 0, "TemporalTrackOptions.max_features must be >= 0, got {}",
            max_features);
  U4D_CHECK(contrast_threshold > 0, "TemporalTrackOptions.contrast_threshold must be > 0, got {}",
            contrast_threshold);
  U4D_CHECK(mask_dilation_px >= 0, "TemporalTrackOptions.mask_dilation_px must be >= 0, got {}",
            mask_dilation_px);
  U4D_CHECK(min_joint_confidence >= 0 && min_joint_confidence <= 1,
            "TemporalTrackOptions.min_joint_confidence must be in [0, 1], got {}",
            min_joint_confidence);
}

namespace {

int IdAt(const cv::Mat& ids, const Eigen::Vector2d& p) {
  if (ids.empty()) return 0;
  const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
  if (x < 0 || y < 0 || x >= ids.cols || y >= ids.rows) return 0;
  return ids.at<uint16_t>(y, x);
}

// Best and second-best L2 distances of each row of `a` among rows of `b`.
std::vector<cv::DMatch> RatioMatches(const cv::Mat& a, const cv::Mat& b, double ratio) {
  std::vector<cv::DMatch> out;
  if (a.rows == 0 || b.rows < 2) return out;
  cv::BFMatcher matcher(cv::NORM_L2, false);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(a, b, knn, 2);
  for (const auto& m : knn) {
    if (m.size() == 2 && m[0].distance < ratio * m[1].distance) out.push_back(m[0]);
  }
  return out;
}

int Find(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

int MajorityInstance(const std::vector<int>& ids) {
  std::map<int, int> count;
  for (int id : ids) ++count[id];
  int best = 0, best_n = 0;
  for (const auto& [id, n] : count) {
    if (n > best_n) best = id, best_n = n;
  }
  return best;
}

}  // namespace

FrameFeatures DetectFrameFeatures(const cv::Mat& image, const cv::Mat& mask_ids,
                                  const TemporalTrackOptions& options) {
  options.Check();
  U4D_CHECK(!image.empty(), "DetectFrameFeatures: empty image");
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image;
  }
  cv::Mat detect_mask;
  if (!mask_ids.empty() && options.restrict_to_masks) {
    U4D_CHECK(mask_ids.size() == image.size() && mask_ids.type() == CV_16UC1,
              "DetectFrameFeatures: mask is {}x{} (type {}), expected a {}x{} CV_16UC1 image",
              mask_ids.cols, mask_ids.rows, mask_ids.type(), image.cols, image.rows);
    detect_mask = mask_ids > 0;
    if (options.mask_dilation_px > 0) {
      const int k = 2 * options.mask_dilation_px + 1;
      cv::dilate(detect_mask, detect_mask,
                 cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
    }
  }
  FrameFeatures f;
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(options.max_features, 3, options.contrast_threshold);
  sift->detectAndCompute(grey, detect_mask, f.keypoints, f.descriptors);
  if (f.descriptors.empty()) f.descriptors = cv::Mat(0, 128, CV_32F);
  f.instance.resize(f.keypoints.size());
  for (size_t k = 0; k < f.keypoints.size(); ++k) {
    f.instance[k] = IdAt(mask_ids, {f.keypoints[k].pt.x, f.keypoints[k].pt.y});
  }
  return f;
}

std::vector<cv::DMatch> MatchFrameFeatures(const FrameFeatures& a, const FrameFeatures& b,
                                           const TemporalTrackOptions& options,
                                           MatchCounts* counts) {
  std::vector<cv::DMatch> forward = RatioMatches(a.descriptors, b.descriptors, options.ratio);
  std::vector<cv::DMatch> kept;
  if (options.symmetry_test) {
    const std::vector<cv::DMatch> backward =
        RatioMatches(b.descriptors, a.descriptors, options.ratio);
    std::vector<int> back(b.keypoints.size(), -1);
    for (const cv::DMatch& m : backward) back[m.queryIdx] = m.trainIdx;
    for (const cv::DMatch& m : forward) {
      if (back[m.trainIdx] == m.queryIdx) kept.push_back(m);
    }
  } else {
    kept = forward;
  }
  if (counts) {
    counts->one_way = static_cast<int>(forward.size());
    counts->symmetric = static_cast<int>(kept.size());
  }
  return kept;
}

std::vector<TemporalTrack> LinkFeatureTracks(int view, int first_frame,
                                             const std::vector<FrameFeatures>& frames,
                                             const TemporalTrackOptions& options,
                                             TrackStats* stats) {
  options.Check();
  const int n = static_cast<int>(frames.size());
  std::vector<int> offset(n + 1, 0);
  for (int k = 0; k < n; ++k)
    offset[k + 1] = offset[k] + static_cast<int>(frames[k].keypoints.size());
  std::vector<int> parent(offset[n]);
  std::iota(parent.begin(), parent.end(), 0);
  Timer timer;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j <= std::min(n - 1, i + options.window); ++j) {
      MatchCounts counts;
      for (const cv::DMatch& m : MatchFrameFeatures(frames[i], frames[j], options, &counts)) {
        const int a = Find(parent, offset[i] + m.queryIdx),
                  b = Find(parent, offset[j] + m.trainIdx);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
      if (stats) {
        ++stats->frame_pairs;
        stats->one_way_matches += counts.one_way;
        stats->symmetric_matches += counts.symmetric;
      }
    }
  }
  if (stats) stats->seconds_match += timer.Seconds();
  // Group nodes by root; nodes are visited in frame order, so points come sorted.
  std::map<int, std::vector<std::pair<int, int>>> groups;  // root -> (frame k, keypoint)
  for (int k = 0; k < n; ++k) {
    for (int p = 0; p < offset[k + 1] - offset[k]; ++p) {
      groups[Find(parent, offset[k] + p)].push_back({k, p});
    }
  }
  std::vector<TemporalTrack> tracks;
  for (const auto& [root, nodes] : groups) {
    if (nodes.size() < 2) continue;
    bool conflict = false;
    for (size_t q = 1; q < nodes.size(); ++q) conflict |= nodes[q].first == nodes[q - 1].first;
    if (conflict) {
      if (stats) ++stats->dropped_components;
      continue;
    }
    TemporalTrack t;
    t.view = view;
    std::vector<int> ids;
    for (const auto& [k, p] : nodes) {
      const cv::KeyPoint& kp = frames[k].keypoints[p];
      t.points.push_back({first_frame + k, Eigen::Vector2d(kp.pt.x, kp.pt.y)});
      ids.push_back(frames[k].instance[p]);
    }
    t.instance = MajorityInstance(ids);
    tracks.push_back(std::move(t));
  }
  return tracks;
}

std::vector<TemporalTrack> JointTracks(const Capture& capture, int view, int first_frame,
                                       const std::vector<std::vector<Pose3d>>& poses,
                                       const std::vector<cv::Mat>& mask_ids,
                                       const TemporalTrackOptions& options) {
  options.Check();
  U4D_CHECK(view >= 0 && view < capture.NumViews(), "JointTracks: view {} out of range [0, {})",
            view, capture.NumViews());
  std::map<std::pair<int, int>, TemporalTrack> by_key;  // (person, joint)
  std::map<std::pair<int, int>, std::vector<int>> ids;
  for (size_t k = 0; k < poses.size(); ++k) {
    const int frame = first_frame + static_cast<int>(k);
    const Camera& cam = capture.views[view].CameraAt(frame);
    for (size_t person = 0; person < poses[k].size(); ++person) {
      const Pose3d& pose = poses[k][person];
      const int pid = pose.person_id >= 0 ? pose.person_id : static_cast<int>(person);
      for (int j = 0; j < h36m17::kNumJoints; ++j) {
        const Eigen::Vector4d& jt = pose.joints[j];
        if (jt.w() <= 0 || jt.w() < options.min_joint_confidence) continue;
        const Eigen::Vector2d px = cam.Project(jt.head<3>());
        if (!px.allFinite() || !cam.InImage(px)) continue;
        TemporalTrack& t = by_key[{pid, j}];
        t.view = view;
        t.from_joint = true;
        t.joint = j;
        t.person_id = pose.person_id;
        t.points.push_back({frame, px});
        ids[{pid, j}].push_back(k < mask_ids.size() ? IdAt(mask_ids[k], px) : 0);
      }
    }
  }
  std::vector<TemporalTrack> tracks;
  for (auto& [key, t] : by_key) {
    t.instance = MajorityInstance(ids[key]);
    tracks.push_back(std::move(t));
  }
  return tracks;
}

void WriteTemporalTracks(const fs::path& path, const std::string& view_name, int view,
                         const std::vector<TemporalTrack>& tracks) {
  nlohmann::json list = nlohmann::json::array();
  for (const TemporalTrack& t : tracks) {
    if (t.view != view) continue;
    nlohmann::json points = nlohmann::json::array();
    for (const auto& [frame, x] : t.points) points.push_back({frame, x.x(), x.y()});
    list.push_back({{"id", static_cast<int>(list.size())},
                    {"instance", t.instance},
                    {"from_joint", t.from_joint},
                    {"joint", t.joint},
                    {"person_id", t.person_id},
                    {"points", points}});
  }
  WriteJsonFileAtomic(path, {{"format", "u4d-tracks"}, {"view", view_name}, {"tracks", list}}, -1);
}

std::vector<TemporalTrack> ReadTemporalTracks(const fs::path& path, int view) {
  const nlohmann::json j = ReadJsonFile(path);
  const std::string ctx = path.string();
  U4D_CHECK(j.is_object() && j.value("format", "") == "u4d-tracks",
            "{}: not a u4d-tracks file (\"format\": \"u4d-tracks\" expected)", ctx);
  std::vector<TemporalTrack> tracks;
  for (const nlohmann::json& jt : JsonGet<nlohmann::json>(j, "tracks", ctx)) {
    TemporalTrack t;
    t.view = view;
    t.instance = static_cast<int>(
        JsonInteger(JsonGet<nlohmann::json>(jt, "instance", ctx), ctx, "instance"));
    t.from_joint = JsonGet<bool>(jt, "from_joint", ctx);
    t.joint =
        static_cast<int>(JsonInteger(JsonGet<nlohmann::json>(jt, "joint", ctx), ctx, "joint"));
    t.person_id = static_cast<int>(
        JsonInteger(JsonGet<nlohmann::json>(jt, "person_id", ctx), ctx, "person_id"));
    for (const nlohmann::json& p : JsonGet<nlohmann::json>(jt, "points", ctx)) {
      U4D_CHECK(p.is_array() && p.size() == 3, "{}: a track point must be [frame, x, y]", ctx);
      const int frame = static_cast<int>(JsonInteger(p[0], ctx, "point frame"));
      const Eigen::Vector2d x(JsonNumber(p[1], ctx, "point x"), JsonNumber(p[2], ctx, "point y"));
      U4D_CHECK(x.allFinite(), "{}: non-finite track point", ctx);
      U4D_CHECK(t.points.empty() || frame > t.points.back().first,
                "{}: track frames must be strictly increasing", ctx);
      t.points.emplace_back(frame, x);
    }
    tracks.push_back(std::move(t));
  }
  return tracks;
}

}  // namespace u4d
