#include "u4d/keyframes/keyframe_similarity.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "u4d/io/layout.h"
#include "u4d/util/check.h"
#include "u4d/util/stats.h"

namespace u4d {

void KeyframeObservations::Check() const {
  U4D_CHECK(num_frames >= 1, "KeyframeObservations: num_frames must be >= 1, got {}", num_frames);
  U4D_CHECK(!masks.empty(), "KeyframeObservations: no views (masks is empty)");
  for (size_t v = 0; v < masks.size(); ++v) {
    U4D_CHECK(static_cast<int>(masks[v].size()) == num_frames,
              "KeyframeObservations: view {} has {} masks, expected {}", v, masks[v].size(),
              num_frames);
    cv::Size size;
    for (size_t f = 0; f < masks[v].size(); ++f) {
      const cv::Mat& ids = masks[v][f].ids;
      if (ids.empty()) continue;
      U4D_CHECK(ids.type() == CV_16UC1,
                "KeyframeObservations: mask of view {} frame {} is not CV_16UC1", v, f);
      if (size.area() == 0) size = ids.size();
      U4D_CHECK(
          ids.size() == size,
          "KeyframeObservations: mask of view {} frame {} is {}x{}, the view's first is {}x{}", v,
          f, ids.cols, ids.rows, size.width, size.height);
    }
  }
  U4D_CHECK(poses.empty() || static_cast<int>(poses.size()) == num_frames,
            "KeyframeObservations: {} pose frames for {} frames", poses.size(), num_frames);
}

int KeyframeOptions::NumTerms() const {
  return use_correspondence + use_semantic + use_distance + use_pose + use_shape;
}

void KeyframeOptions::Check() const {
  U4D_CHECK(threshold >= 0 && threshold <= 1, "KeyframeOptions.threshold must be in [0, 1], got {}",
            threshold);
  U4D_CHECK(NumTerms() >= 1, "KeyframeOptions: at least one term must be switched on");
  U4D_CHECK(distance_scale > 0, "KeyframeOptions.distance_scale must be > 0, got {}",
            distance_scale);
  U4D_CHECK(pose_scale_m > 0, "KeyframeOptions.pose_scale_m must be > 0, got {}", pose_scale_m);
  U4D_CHECK(min_common_joints >= 1 && min_common_joints <= 17,
            "KeyframeOptions.min_common_joints must be in [1, 17], got {}", min_common_joints);
}

namespace {

// One instance of one mask, with what the terms need.
struct Object {
  int id = 0;
  std::string label;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  cv::Rect box;
  cv::Mat crop;  // CV_8U 0/1 over `box`
  long area = 0;
};

std::vector<Object> Objects(const InstanceMask& mask) {
  std::map<int, Object> by_id;
  const cv::Mat& ids = mask.ids;
  std::map<int, std::pair<cv::Point, cv::Point>> extent;
  for (int y = 0; y < ids.rows; ++y) {
    const uint16_t* row = ids.ptr<uint16_t>(y);
    for (int x = 0; x < ids.cols; ++x) {
      if (row[x] == 0) continue;
      Object& o = by_id[row[x]];
      o.centroid += Eigen::Vector2d(x, y);
      ++o.area;
      auto [it, fresh] = extent.try_emplace(row[x], cv::Point(x, y), cv::Point(x, y));
      if (!fresh) {
        it->second.first = {std::min(it->second.first.x, x), std::min(it->second.first.y, y)};
        it->second.second = {std::max(it->second.second.x, x), std::max(it->second.second.y, y)};
      }
    }
  }
  std::vector<Object> out;
  for (auto& [id, o] : by_id) {
    o.id = id;
    const InstanceInfo* info = mask.Find(id);
    o.label = info ? info->label : "unknown";
    o.centroid /= static_cast<double>(o.area);
    const auto& [lo, hi] = extent[id];
    o.box = cv::Rect(lo, cv::Point(hi.x + 1, hi.y + 1));
    o.crop = ids(o.box) == id;
    o.crop /= 255;
    out.push_back(std::move(o));
  }
  return out;
}

// IoU of two silhouettes with b translated so that the centroids coincide.
double AlignedIoU(const Object& a, const Object& b) {
  const Eigen::Vector2d shift = a.centroid - b.centroid;
  const int dx = static_cast<int>(std::lround(shift.x())),
            dy = static_cast<int>(std::lround(shift.y()));
  const cv::Rect bb(b.box.x + dx, b.box.y + dy, b.box.width, b.box.height);
  const cv::Rect u = a.box | bb;
  cv::Mat ca = cv::Mat::zeros(u.size(), CV_8U), cb = cv::Mat::zeros(u.size(), CV_8U);
  a.crop.copyTo(ca(cv::Rect(a.box.x - u.x, a.box.y - u.y, a.box.width, a.box.height)));
  b.crop.copyTo(cb(cv::Rect(bb.x - u.x, bb.y - u.y, bb.width, bb.height)));
  const double inter = cv::countNonZero(ca & cb), uni = cv::countNonZero(ca | cb);
  return uni > 0 ? inter / uni : 1.0;
}

// Greedy matching of same-class objects by increasing centroid distance.
std::vector<std::pair<int, int>> MatchObjects(const std::vector<Object>& a,
                                              const std::vector<Object>& b) {
  std::vector<std::tuple<double, int, int>> cand;
  for (size_t p = 0; p < a.size(); ++p) {
    for (size_t q = 0; q < b.size(); ++q) {
      if (a[p].label == b[q].label) {
        cand.emplace_back((a[p].centroid - b[q].centroid).norm(), p, q);
      }
    }
  }
  std::sort(cand.begin(), cand.end());
  std::vector<bool> used_a(a.size()), used_b(b.size());
  std::vector<std::pair<int, int>> out;
  for (const auto& [d, p, q] : cand) {
    if (used_a[p] || used_b[q]) continue;
    used_a[p] = used_b[q] = true;
    out.emplace_back(p, q);
  }
  return out;
}

double SemanticTerm(const std::vector<Object>& a, const std::vector<Object>& b) {
  std::map<std::string, std::pair<int, int>> counts;
  for (const Object& o : a) ++counts[o.label].first;
  for (const Object& o : b) ++counts[o.label].second;
  double mn = 0, mx = 0;
  for (const auto& [label, c] : counts) {
    mn += std::min(c.first, c.second);
    mx += std::max(c.first, c.second);
  }
  return mx > 0 ? 1.0 - mn / mx : 0.0;
}

// Root-relative MPJPE of two poses, or NaN with too few common joints.
double RootRelativeMpjpe(const Pose3d& a, const Pose3d& b, int min_common) {
  std::vector<int> common;
  for (int j = 0; j < h36m17::kNumJoints; ++j) {
    if (a.joints[j].w() > 0 && b.joints[j].w() > 0) common.push_back(j);
  }
  if (static_cast<int>(common.size()) < min_common) return std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d ra = Eigen::Vector3d::Zero(), rb = Eigen::Vector3d::Zero();
  if (a.joints[h36m17::kPelvis].w() > 0 && b.joints[h36m17::kPelvis].w() > 0) {
    ra = a.joints[h36m17::kPelvis].head<3>();
    rb = b.joints[h36m17::kPelvis].head<3>();
  } else {
    for (int j : common) ra += a.joints[j].head<3>(), rb += b.joints[j].head<3>();
    ra /= common.size();
    rb /= common.size();
  }
  double sum = 0;
  for (int j : common) sum += ((a.joints[j].head<3>() - ra) - (b.joints[j].head<3>() - rb)).norm();
  return sum / common.size();
}

Eigen::Vector3d PoseCentre(const Pose3d& p) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& j : p.joints) {
    if (j.w() > 0) c += j.head<3>(), ++n;
  }
  return n ? Eigen::Vector3d(c / n) : c;
}

double PoseTerm(const std::vector<Pose3d>& a, const std::vector<Pose3d>& b,
                const KeyframeOptions& options) {
  const size_t slots = std::max(a.size(), b.size());
  if (slots == 0) return 0.0;
  // Pairs: same person_id when both are known, else greedy by centre distance.
  std::vector<std::tuple<double, int, int>> cand;
  for (size_t p = 0; p < a.size(); ++p) {
    for (size_t q = 0; q < b.size(); ++q) {
      if (a[p].person_id >= 0 && b[q].person_id >= 0) {
        if (a[p].person_id == b[q].person_id) cand.emplace_back(-1.0, p, q);
      } else {
        cand.emplace_back((PoseCentre(a[p]) - PoseCentre(b[q])).norm(), p, q);
      }
    }
  }
  std::sort(cand.begin(), cand.end());
  std::vector<bool> used_a(a.size()), used_b(b.size());
  double sum = 0;
  size_t matched = 0;
  for (const auto& [d, p, q] : cand) {
    if (used_a[p] || used_b[q]) continue;
    used_a[p] = used_b[q] = true;
    ++matched;
    const double e = RootRelativeMpjpe(a[p], b[q], options.min_common_joints);
    sum += std::isfinite(e) ? std::min(1.0, e / options.pose_scale_m) : 1.0;
  }
  return (sum + static_cast<double>(slots - matched)) / slots;
}

// Per-view, per-frame precomputation shared by all pairs.
struct Prepared {
  std::vector<std::vector<std::vector<Object>>> objects;  // [view][frame]
  std::vector<std::vector<std::vector<int>>> tracks_at;   // [view][frame] -> track indices
  std::vector<double> diagonal;                           // [view]
};

Prepared Prepare(const KeyframeObservations& obs) {
  obs.Check();
  Prepared p;
  p.objects.resize(obs.NumViews());
  p.tracks_at.assign(obs.NumViews(), std::vector<std::vector<int>>(obs.num_frames));
  p.diagonal.assign(obs.NumViews(), 1.0);
  for (int v = 0; v < obs.NumViews(); ++v) {
    for (int f = 0; f < obs.num_frames; ++f) {
      const cv::Mat& ids = obs.masks[v][f].ids;
      p.objects[v].push_back(Objects(obs.masks[v][f]));
      if (!ids.empty()) p.diagonal[v] = std::hypot(ids.cols, ids.rows);
    }
  }
  for (size_t t = 0; t < obs.tracks.size(); ++t) {
    const TemporalTrack& tr = obs.tracks[t];
    if (tr.from_joint || tr.instance == 0) continue;
    U4D_CHECK(tr.view >= 0 && tr.view < obs.NumViews(),
              "KeyframeObservations: track {} has view {} outside [0, {})", t, tr.view,
              obs.NumViews());
    for (const auto& [frame, px] : tr.points) {
      if (frame >= 0 && frame < obs.num_frames) p.tracks_at[tr.view][frame].push_back(t);
    }
  }
  return p;
}

KeyframeTerms Terms(const KeyframeObservations& obs, const Prepared& prep, int view, int i, int j,
                    const KeyframeOptions& options) {
  KeyframeTerms t;
  if (i == j) return t;
  if (options.use_correspondence) {
    // M: Dice overlap of the tracks present at i and at j (index lists are sorted).
    const auto& ti = prep.tracks_at[view][i];
    const auto& tj = prep.tracks_at[view][j];
    std::vector<int> both;
    std::set_intersection(ti.begin(), ti.end(), tj.begin(), tj.end(), std::back_inserter(both));
    t.m = ti.size() + tj.size() > 0 ? 1.0 - 2.0 * both.size() / (ti.size() + tj.size()) : 1.0;
  }
  const auto& oi = prep.objects[view][i];
  const auto& oj = prep.objects[view][j];
  t.l = SemanticTerm(oi, oj);
  const size_t slots = std::max(oi.size(), oj.size());
  if (slots > 0) {
    double d = 0, s = 0;
    const auto pairs = MatchObjects(oi, oj);
    for (const auto& [p, q] : pairs) {
      d += std::min(1.0, (oi[p].centroid - oj[q].centroid).norm() /
                             (options.distance_scale * prep.diagonal[view]));
      if (options.use_shape) s += 1.0 - AlignedIoU(oi[p], oj[q]);
    }
    const double unmatched = static_cast<double>(slots - pairs.size());
    t.d = (d + unmatched) / slots;
    t.i = options.use_shape ? (s + unmatched) / slots : 0.0;
  }
  t.p =
      obs.poses.empty() || !options.use_pose ? 0.0 : PoseTerm(obs.poses[i], obs.poses[j], options);
  return t;
}

// One view's 1 - KS: the mean of the terms switched on.
double Dissimilarity(const KeyframeTerms& t, const KeyframeOptions& options) {
  const double sum = (options.use_correspondence ? t.m : 0) + (options.use_semantic ? t.l : 0) +
                     (options.use_distance ? t.d : 0) + (options.use_pose ? t.p : 0) +
                     (options.use_shape ? t.i : 0);
  return sum / options.NumTerms();
}

}  // namespace

KeyframeTerms KeyframeTermsAt(const KeyframeObservations& obs, int view, int i, int j,
                              const KeyframeOptions& options) {
  options.Check();
  U4D_CHECK(view >= 0 && view < obs.NumViews(), "KeyframeTermsAt: view {} outside [0, {})", view,
            obs.NumViews());
  U4D_CHECK(i >= 0 && j >= 0 && i < obs.num_frames && j < obs.num_frames,
            "KeyframeTermsAt: frames ({}, {}) outside [0, {})", i, j, obs.num_frames);
  return Terms(obs, Prepare(obs), view, i, j, options);
}

KeyframeTermMatrices ComputeKeyframeTermMatrices(const KeyframeObservations& obs,
                                                 const KeyframeOptions& options) {
  options.Check();
  const Prepared prep = Prepare(obs);
  const int n = obs.num_frames;
  KeyframeTermMatrices out;
  for (Eigen::MatrixXd* m : {&out.m, &out.l, &out.d, &out.p, &out.i}) m->setZero(n, n);
  const double w = 1.0 / obs.NumViews();
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      KeyframeTerms sum;
      for (int v = 0; v < obs.NumViews(); ++v) {
        const KeyframeTerms t = Terms(obs, prep, v, a, b, options);
        sum.m += t.m, sum.l += t.l, sum.d += t.d, sum.p += t.p, sum.i += t.i;
      }
      out.m(a, b) = out.m(b, a) = options.use_correspondence ? w * sum.m : 0;
      out.l(a, b) = out.l(b, a) = options.use_semantic ? w * sum.l : 0;
      out.d(a, b) = out.d(b, a) = options.use_distance ? w * sum.d : 0;
      out.p(a, b) = out.p(b, a) = options.use_pose ? w * sum.p : 0;
      out.i(a, b) = out.i(b, a) = options.use_shape ? w * sum.i : 0;
    }
  }
  return out;
}

Eigen::MatrixXd CombineKeyframeTerms(const KeyframeTermMatrices& t,
                                     const KeyframeOptions& options) {
  options.Check();
  const Eigen::Index n = t.m.rows();
  for (const Eigen::MatrixXd* m : {&t.m, &t.l, &t.d, &t.p, &t.i}) {
    U4D_CHECK(m->rows() == n && m->cols() == n,
              "CombineKeyframeTerms: term matrices must all be {}x{}, got {}x{}", n, n, m->rows(),
              m->cols());
  }
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(n, n);
  if (options.use_correspondence) sum += t.m;
  if (options.use_semantic) sum += t.l;
  if (options.use_distance) sum += t.d;
  if (options.use_pose) sum += t.p;
  if (options.use_shape) sum += t.i;
  Eigen::MatrixXd ks = Eigen::MatrixXd::Ones(n, n) - sum / options.NumTerms();
  ks.diagonal().setOnes();
  return ks;
}

Eigen::MatrixXd KeyframeSimilarityMatrix(const KeyframeObservations& obs,
                                         const KeyframeOptions& options) {
  if (!options.view_median)
    return CombineKeyframeTerms(ComputeKeyframeTermMatrices(obs, options), options);
  options.Check();
  U4D_CHECK(obs.NumViews() >= 1, "KeyframeSimilarityMatrix: no views");
  const Prepared prep = Prepare(obs);
  const int n = obs.num_frames;
  Eigen::MatrixXd ks = Eigen::MatrixXd::Ones(n, n);
  std::vector<double> per_view(obs.NumViews());
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      for (int v = 0; v < obs.NumViews(); ++v)
        per_view[v] = 1.0 - Dissimilarity(Terms(obs, prep, v, a, b, options), options);
      ks(a, b) = ks(b, a) = MedianOfMiddle(per_view);
    }
  return ks;
}

void KeyframeSelectOptions::Check() const {
  U4D_CHECK(threshold >= 0 && threshold <= 1,
            "KeyframeSelectOptions.threshold must be in [0, 1], got {}", threshold);
  U4D_CHECK(medoid_rounds >= 0, "KeyframeSelectOptions.medoid_rounds must be >= 0, got {}",
            medoid_rounds);
}

namespace {

// Per frame: the key-frame it is most similar to among those it is similar
// to (a key-frame is its own; ties: the nearest in time, then the earlier);
// -1 when it is similar to none.
std::vector<int> AssignFrames(const Eigen::MatrixXd& ks, double threshold,
                              const std::vector<int>& keyframes) {
  const int n = static_cast<int>(ks.rows());
  std::vector<int> own(n, -1);
  for (int t = 0; t < n; ++t) {
    double best = -1;
    for (int k : keyframes) {
      if (k != t && !(ks(k, t) > threshold)) continue;
      const double v = k == t ? 2.0 : ks(k, t);
      const int cur = own[t];
      if (v > best || (v == best && std::abs(k - t) < std::abs(cur - t))) best = v, own[t] = k;
    }
  }
  return own;
}

std::vector<int> GreedyCover(const Eigen::MatrixXd& ks, const KeyframeSelectOptions& o) {
  const int n = static_cast<int>(ks.rows());
  auto similar = [&](int a, int b) { return a == b || ks(a, b) > o.threshold; };
  auto value = [&](int a, int b) { return a == b ? 1.0 : ks(a, b); };
  std::vector<bool> covered(n, false);
  std::vector<double> best(n, o.threshold);  // a frame's similarity to its best key-frame
  std::vector<int> keyframes;
  int left = n;
  while (left > 0) {
    int pick = -1;
    double pick_gain = -1;
    for (int k = 0; k < n; ++k) {
      int fresh = 0;
      double gain = 0;
      for (int t = 0; t < n; ++t) {
        if (!similar(k, t)) continue;
        fresh += !covered[t];
        gain +=
            o.cover == KeyframeCover::kCount ? !covered[t] : std::max(0.0, value(k, t) - best[t]);
      }
      // Only a frame that covers a new frame may be picked, so the loop ends
      // after at most n picks and never adds a key-frame that covers nothing.
      if (fresh > 0 && gain > pick_gain) pick = k, pick_gain = gain;
    }
    U4D_ASSERT(pick >= 0);
    keyframes.push_back(pick);
    for (int t = 0; t < n; ++t) {
      if (!similar(pick, t)) continue;
      if (!covered[t]) covered[t] = true, --left;
      best[t] = std::max(best[t], value(pick, t));
    }
  }
  return keyframes;
}

// Moves each key-frame to the medoid of its members: the frame similar to
// every member with the largest summed similarity to them (the current
// key-frame wins ties, so the loop cannot cycle on ties), and drops
// key-frames left alone. Every frame stays covered: a member is similar to
// its cluster's new key-frame.
std::vector<int> MedoidRefinement(const Eigen::MatrixXd& ks, const KeyframeSelectOptions& o,
                                  std::vector<int> keyframes) {
  const int n = static_cast<int>(ks.rows());
  auto similar = [&](int a, int b) { return a == b || ks(a, b) > o.threshold; };
  auto value = [&](int a, int b) { return a == b ? 1.0 : ks(a, b); };
  for (int round = 0; round < o.medoid_rounds; ++round) {
    const std::vector<int> own = AssignFrames(ks, o.threshold, keyframes);
    bool changed = false;
    for (int& k : keyframes) {
      std::vector<int> members;
      for (int t = 0; t < n; ++t) {
        if (own[t] == k) members.push_back(t);
      }
      auto score = [&](int c) {
        double sum = 0;
        for (int m : members) {
          if (!similar(c, m)) return -1.0;
          sum += value(c, m);
        }
        return sum;
      };
      int pick = k;
      double pick_score = score(k);
      for (int c = 0; c < n; ++c) {
        if (std::find(keyframes.begin(), keyframes.end(), c) != keyframes.end()) continue;
        const double sc = score(c);
        if (sc > pick_score + 1e-12) pick = c, pick_score = sc;
      }
      if (pick != k) k = pick, changed = true;
    }
    // A key-frame left with no member but itself (the others taken by closer
    // key-frames) is dropped when it is similar to a key-frame that has other
    // members (never dropped, so the frame stays covered).
    const std::vector<int> after = AssignFrames(ks, o.threshold, keyframes);
    std::vector<int> count(n, 0);
    for (int t = 0; t < n; ++t) ++count[after[t]];
    std::vector<int> kept;
    for (int k : keyframes) {
      bool redundant = count[k] == 1;
      if (redundant) {
        redundant = false;
        for (int other : keyframes)
          redundant |= other != k && count[other] > 1 && similar(other, k);
      }
      if (!redundant) kept.push_back(k);
    }
    changed |= kept.size() != keyframes.size();
    keyframes = std::move(kept);
    if (!changed) break;
  }
  return keyframes;
}

}  // namespace

KeyframeSelection SelectKeyframes(const Eigen::MatrixXd& similarity,
                                  const KeyframeSelectOptions& options) {
  options.Check();
  const int n = static_cast<int>(similarity.rows());
  U4D_CHECK(n >= 1 && similarity.cols() == n,
            "SelectKeyframes: similarity must be square and non-empty, got {}x{}",
            similarity.rows(), similarity.cols());
  KeyframeSelection s;
  s.threshold = options.threshold;
  s.similarity = similarity;
  s.keyframes = MedoidRefinement(similarity, options, GreedyCover(similarity, options));
  std::sort(s.keyframes.begin(), s.keyframes.end());
  s.frame_keyframe = AssignFrames(similarity, options.threshold, s.keyframes);
  s.frame_segment.assign(n, 0);
  s.segment_lengths.assign(s.keyframes.size(), 0);
  for (int t = 0; t < n; ++t) {
    U4D_ASSERT(s.frame_keyframe[t] >= 0);
    int seg = 0;
    for (size_t q = 0; q < s.keyframes.size(); ++q) {
      if (s.keyframes[q] <= t) seg = static_cast<int>(q);
    }
    s.frame_segment[t] = seg;
    ++s.segment_lengths[seg];
  }
  return s;
}

KeyframeSelection SelectKeyframes(const Eigen::MatrixXd& similarity, double threshold) {
  KeyframeSelectOptions o;
  o.threshold = threshold;
  return SelectKeyframes(similarity, o);
}

KeyframeSelection SelectKeyframesInShots(Eigen::MatrixXd similarity,
                                         const std::vector<int>& shot_starts,
                                         const KeyframeSelectOptions& options) {
  const int n = static_cast<int>(similarity.rows());
  U4D_CHECK(!shot_starts.empty() && shot_starts[0] == 0,
            "SelectKeyframesInShots: the first shot must start at frame 0");
  std::vector<int> bounds = shot_starts;
  bounds.push_back(n);
  for (size_t i = 1; i < bounds.size(); ++i)
    U4D_CHECK(bounds[i] > bounds[i - 1],
              "SelectKeyframesInShots: shot starts {} and {} are not "
              "increasing within the {} frames",
              bounds[i - 1], bounds[i], n);
  KeyframeSelection all;
  all.threshold = options.threshold;
  for (size_t i = 0; i + 1 < bounds.size(); ++i) {
    const int first = bounds[i], len = bounds[i + 1] - first;
    similarity.block(first, 0, len, first).setZero();
    similarity.block(0, first, first, len).setZero();
    const KeyframeSelection shot =
        SelectKeyframes(similarity.block(first, first, len, len), options);
    const int segment_offset = static_cast<int>(all.keyframes.size());
    for (int k : shot.keyframes) all.keyframes.push_back(first + k);
    for (int k : shot.frame_keyframe) all.frame_keyframe.push_back(first + k);
    for (int s : shot.frame_segment) all.frame_segment.push_back(segment_offset + s);
    for (int l : shot.segment_lengths) all.segment_lengths.push_back(l);
  }
  all.similarity = std::move(similarity);
  return all;
}

void WriteKeyframes(const fs::path& path, const KeyframeSelection& s) {
  nlohmann::json j;
  j["format"] = "u4d-keyframes";
  j["threshold"] = s.threshold;
  j["num_frames"] = s.frame_segment.size();
  j["keyframes"] = s.keyframes;
  j["frame_keyframe"] = s.frame_keyframe;
  j["frame_segment"] = s.frame_segment;
  j["segment_lengths"] = s.segment_lengths;
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < s.similarity.rows(); ++r) {
    std::vector<double> row(s.similarity.cols());
    for (int c = 0; c < s.similarity.cols(); ++c) row[c] = s.similarity(r, c);
    rows.push_back(row);
  }
  j["similarity"] = rows;
  WriteJsonFileAtomic(path, j);
}

KeyframeSelection ReadKeyframes(const fs::path& path) {
  const nlohmann::json j = ReadJsonFile(path);
  const std::string ctx = path.string();
  U4D_CHECK(j.is_object() && j.value("format", "") == "u4d-keyframes",
            "{}: not a keyframes file (\"format\" must be \"u4d-keyframes\")", ctx);
  KeyframeSelection s;
  s.threshold = JsonNumber(j.at("threshold"), ctx, "threshold");
  const int n = static_cast<int>(JsonInteger(j.at("num_frames"), ctx, "num_frames"));
  U4D_CHECK(n >= 1, "{}: num_frames must be >= 1, got {}", ctx, n);
  auto ints = [&](const char* key, size_t expected, int lo, int hi) {
    U4D_CHECK(j.contains(key) && j[key].is_array(), "{}: \"{}\" must be an array", ctx, key);
    std::vector<int> out;
    for (const auto& v : j[key]) {
      const int x = static_cast<int>(JsonInteger(v, ctx, key));
      U4D_CHECK(x >= lo && x < hi, "{}: \"{}\" value {} outside [{}, {})", ctx, key, x, lo, hi);
      out.push_back(x);
    }
    U4D_CHECK(expected == 0 || out.size() == expected, "{}: \"{}\" has {} entries, expected {}",
              ctx, key, out.size(), expected);
    return out;
  };
  s.keyframes = ints("keyframes", 0, 0, n);
  U4D_CHECK(!s.keyframes.empty(), "{}: no key-frames", ctx);
  s.frame_keyframe = ints("frame_keyframe", n, 0, n);
  s.frame_segment = ints("frame_segment", n, 0, static_cast<int>(s.keyframes.size()));
  s.segment_lengths = ints("segment_lengths", s.keyframes.size(), 0, n + 1);
  U4D_CHECK(std::is_sorted(s.keyframes.begin(), s.keyframes.end()) &&
                std::adjacent_find(s.keyframes.begin(), s.keyframes.end()) == s.keyframes.end(),
            "{}: \"keyframes\" must be strictly increasing", ctx);
  for (int k : s.frame_keyframe) {
    U4D_CHECK(std::binary_search(s.keyframes.begin(), s.keyframes.end(), k),
              "{}: frame_keyframe {} is not a key-frame", ctx, k);
  }
  U4D_CHECK(j.contains("similarity") && j["similarity"].is_array() &&
                static_cast<int>(j["similarity"].size()) == n,
            "{}: \"similarity\" must be {} rows", ctx, n);
  s.similarity.resize(n, n);
  for (int r = 0; r < n; ++r) {
    const auto& row = j["similarity"][r];
    U4D_CHECK(row.is_array() && static_cast<int>(row.size()) == n,
              "{}: similarity row {} must have {} values", ctx, r, n);
    for (int c = 0; c < n; ++c) s.similarity(r, c) = JsonNumber(row[c], ctx, "similarity");
  }
  return s;
}

}  // namespace u4d
