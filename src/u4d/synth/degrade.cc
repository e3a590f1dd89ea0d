#include "u4d/synth/degrade.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <tuple>

#include <opencv2/imgproc.hpp>

#include "u4d/synth/scene.h"
#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

// ------------------------------------------------------------ random numbers

uint64_t SplitMix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

uint64_t Mix(uint64_t a, uint64_t b) { return SplitMix(SplitMix(a) ^ (b * 0xd6e8feb86659fd93ULL)); }

constexpr double kPi = 3.14159265358979323846;

// Stream tags, so the sub-streams of one call never coincide.
constexpr uint64_t kFrameStream = 1;
constexpr uint64_t kFalsePositiveStream = 2;
constexpr uint64_t kRenumberStream = 3;
constexpr uint64_t kInstanceStream = 1000;
constexpr uint64_t kPairStream = 2000;
constexpr uint64_t kGroupStream = 3000;
constexpr uint64_t kPersonStream = 4000;

// A small deterministic generator (splitmix64 sequence) with our own
// distributions, identical on every platform and standard library.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  bool Bernoulli(double p) { return Uniform() < p; }
  int UniformInt(int n) { return static_cast<int>(Uniform() * n); }  // [0, n)
  double Normal() {
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
  int Poisson(double mean) {  // Knuth; mean is small (checked <= 50)
    const double limit = std::exp(-mean);
    int k = 0;
    double p = Uniform();
    while (p > limit) {
      ++k;
      p *= Uniform();
    }
    return k;
  }

 private:
  uint64_t state_;
};

void CheckProb(double p, const char* name) {
  U4D_CHECK(std::isfinite(p) && p >= 0 && p <= 1, "{}: expected a probability in [0, 1], got {}",
            name, p);
}
void CheckNonNeg(double v, const char* name) {
  U4D_CHECK(std::isfinite(v) && v >= 0, "{}: expected a finite value >= 0, got {}", name, v);
}

// P(event now | whether it happened at the previous frame) of a two-state
// Markov chain with long-run rate `rate` and P(event | event before) =
// `persistence`.
double MarkovProbability(double rate, double persistence, bool before) {
  if (before) return persistence;
  if (rate >= 1) return 1;
  return std::clamp(rate * (1 - persistence) / (1 - rate), 0.0, 1.0);
}

// Removes, from instance `label` of `work` inside `roi`, each thin piece (what
// an opening with a disc of diameter `width` takes away, at least width^2
// pixels) with probability `prob`. Returns the number of pieces removed.
int DropThinParts(cv::Mat work, int label, double width, double prob, Rng& rng) {
  const cv::Mat own = work == label;
  const int w = std::max(3, static_cast<int>(std::lround(width)) | 1);
  cv::Mat opened;
  cv::morphologyEx(own, opened, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(w, w)));
  const cv::Mat thin = own & ~opened;
  cv::Mat components, stats, centroids;
  const int count = cv::connectedComponentsWithStats(thin, components, stats, centroids, 8, CV_32S);
  int dropped = 0;
  for (int c = 1; c < count; ++c) {
    if (stats.at<int>(c, cv::CC_STAT_AREA) < w * w || !rng.Bernoulli(prob)) continue;
    work.setTo(0, components == c);
    ++dropped;
  }
  return dropped;
}

// ------------------------------------------------------------ mask helpers

// A smooth zero-mean random field of size `size` with standard deviation
// `amplitude` and correlation length `correlation` (grid spacing).
cv::Mat NoiseField(cv::Size size, double amplitude, double correlation, Rng& rng) {
  cv::Mat field(size, CV_32F, cv::Scalar(0));
  if (amplitude <= 0 || size.area() == 0) return field;
  const int step = std::max(1, static_cast<int>(std::lround(correlation)));
  const int gw = size.width / step + 4, gh = size.height / step + 4;
  cv::Mat grid(gh, gw, CV_32F);
  for (int y = 0; y < gh; ++y)
    for (int x = 0; x < gw; ++x) grid.at<float>(y, x) = static_cast<float>(rng.Normal());
  cv::Mat fine;
  cv::resize(grid, fine, cv::Size(gw * step, gh * step), 0, 0, cv::INTER_CUBIC);
  field = fine(cv::Rect(step, step, size.width, size.height)).clone();
  // Interpolation lowers the variance between grid nodes; rescale to the
  // requested standard deviation (about zero mean by construction).
  cv::Scalar mean, stddev;
  cv::meanStdDev(field, mean, stddev);
  if (stddev[0] > 1e-9) field *= amplitude / stddev[0];
  return field;
}

// Signed distance (pixels, > 0 inside) of a binary CV_8U mask: +-0.5 at the
// pixels on either side of the boundary.
cv::Mat SignedDistance(const cv::Mat& mask) {
  cv::Mat inside, outside, inverted;
  cv::distanceTransform(mask, inside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::bitwise_not(mask, inverted);
  cv::distanceTransform(inverted, outside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::Mat sd(mask.size(), CV_32F);
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y);
    const float* in = inside.ptr<float>(y);
    const float* out = outside.ptr<float>(y);
    float* d = sd.ptr<float>(y);
    for (int x = 0; x < mask.cols; ++x) d[x] = m[x] ? in[x] - 0.5f : 0.5f - out[x];
  }
  return sd;
}

// The degraded version of `mask` (CV_8U, 0/255, covering `roi` of the image)
// competes for pixels: a pixel goes to the candidate with the largest
// positive margin signed_distance + noise.
void Compete(const cv::Mat& mask, const cv::Rect& roi, const MaskDegradeOptions& options, int label,
             Rng& rng, cv::Mat& best_margin, cv::Mat& labels, const cv::Mat* allowed = nullptr) {
  cv::Mat m = mask;
  if (options.blur_sigma_px > 0) {
    cv::Mat f, blurred;
    mask.convertTo(f, CV_32F, 1.0 / 255);
    cv::GaussianBlur(f, blurred, cv::Size(0, 0), options.blur_sigma_px, options.blur_sigma_px,
                     cv::BORDER_REPLICATE);
    m = blurred >= 0.5f;
  }
  const cv::Mat sd = SignedDistance(m);
  const cv::Mat noise =
      NoiseField(roi.size(), options.boundary_amplitude_px, options.boundary_correlation_px, rng);
  for (int y = 0; y < roi.height; ++y) {
    const float* sd_row = sd.ptr<float>(y);
    const float* noise_row = noise.ptr<float>(y);
    float* best_row = best_margin.ptr<float>(y + roi.y) + roi.x;
    int* label_row = labels.ptr<int>(y + roi.y) + roi.x;
    const uint8_t* allowed_row = allowed ? allowed->ptr<uint8_t>(y + roi.y) + roi.x : nullptr;
    for (int x = 0; x < roi.width; ++x) {
      if (allowed_row && !allowed_row[x]) continue;
      const float margin = sd_row[x] + noise_row[x];
      if (margin > 0 && margin > best_row[x]) {
        best_row[x] = margin;
        label_row[x] = label;
      }
    }
  }
}

int Margin(const MaskDegradeOptions& o) {
  return static_cast<int>(
             std::ceil(4 * o.boundary_amplitude_px + 3 * o.blur_sigma_px + o.merge_distance_px)) +
         3;
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int Find(int i) { return parent[i] == i ? i : parent[i] = Find(parent[i]); }
  void Unite(int a, int b) { parent[Find(b)] = Find(a); }
};

double Clamp(double v, double lo, double hi) { return std::min(hi, std::max(lo, v)); }

// The class of the member (index into gt_list) with the most GT pixels;
// "person" without classes or for an id they do not name.
std::string MajorityClass(const cv::Mat& gt_ids, const std::map<int, cv::Rect>& boxes,
                          const std::vector<int>& gt_list, const std::vector<int>& members,
                          const std::map<int, std::string>* classes) {
  if (classes == nullptr) return "person";
  int best = gt_list[members[0]];
  int best_area = -1;
  for (int m : members) {
    const int id = gt_list[m];
    const int area = cv::countNonZero(gt_ids(boxes.at(id)) == id);
    if (area > best_area) std::tie(best, best_area) = std::pair(id, area);
  }
  const auto it = classes->find(best);
  return it == classes->end() ? "person" : it->second;
}

}  // namespace

uint64_t DegradeSeed(uint64_t base, int view, int frame) {
  return Mix(Mix(base, static_cast<uint64_t>(view) + 1), static_cast<uint64_t>(frame) + 1);
}

// ------------------------------------------------------------ mask options

void MaskDegradeOptions::Check() const {
  CheckProb(frame_drop_prob, "MaskDegradeOptions.frame_drop_prob");
  CheckProb(instance_miss_prob, "MaskDegradeOptions.instance_miss_prob");
  CheckNonNeg(boundary_amplitude_px, "MaskDegradeOptions.boundary_amplitude_px");
  U4D_CHECK(std::isfinite(boundary_correlation_px) && boundary_correlation_px >= 1,
            "MaskDegradeOptions.boundary_correlation_px: expected >= 1 pixel, got {}",
            boundary_correlation_px);
  CheckNonNeg(blur_sigma_px, "MaskDegradeOptions.blur_sigma_px");
  CheckProb(lower_arm_drop_prob, "MaskDegradeOptions.lower_arm_drop_prob");
  CheckProb(lower_leg_drop_prob, "MaskDegradeOptions.lower_leg_drop_prob");
  CheckProb(merge_prob, "MaskDegradeOptions.merge_prob");
  CheckNonNeg(merge_distance_px, "MaskDegradeOptions.merge_distance_px");
  U4D_CHECK(std::isfinite(apart_merge_prob) && apart_merge_prob <= 1,
            "MaskDegradeOptions.apart_merge_prob: expected < 0 (off) or a probability, got {}",
            apart_merge_prob);
  U4D_CHECK(std::isfinite(merge_persistence) && merge_persistence <= 1,
            "MaskDegradeOptions.merge_persistence: expected < 0 (off) or a probability, got {}",
            merge_persistence);
  U4D_CHECK(std::isfinite(miss_persistence) && miss_persistence <= 1,
            "MaskDegradeOptions.miss_persistence: expected < 0 (off) or a probability, got {}",
            miss_persistence);
  CheckProb(thin_part_drop_prob, "MaskDegradeOptions.thin_part_drop_prob");
  U4D_CHECK(std::isfinite(thin_part_width_px) && thin_part_width_px >= 3,
            "MaskDegradeOptions.thin_part_width_px: expected >= 3 pixels, got {}",
            thin_part_width_px);
  CheckNonNeg(false_positive_rate, "MaskDegradeOptions.false_positive_rate");
  U4D_CHECK(false_positive_rate <= 50,
            "MaskDegradeOptions.false_positive_rate: expected <= 50 per image, got {}",
            false_positive_rate);
  CheckNonNeg(false_positive_min_radius_px, "MaskDegradeOptions.false_positive_min_radius_px");
  CheckNonNeg(false_positive_max_radius_px, "MaskDegradeOptions.false_positive_max_radius_px");
  U4D_CHECK(false_positive_min_radius_px <= false_positive_max_radius_px,
            "MaskDegradeOptions: false_positive_min_radius_px {} > false_positive_max_radius_px {}",
            false_positive_min_radius_px, false_positive_max_radius_px);
  CheckProb(false_positive_score_min, "MaskDegradeOptions.false_positive_score_min");
  CheckProb(false_positive_score_max, "MaskDegradeOptions.false_positive_score_max");
  U4D_CHECK(false_positive_score_min <= false_positive_score_max,
            "MaskDegradeOptions: false_positive_score_min {} > false_positive_score_max {}",
            false_positive_score_min, false_positive_score_max);
  CheckProb(score_mean, "MaskDegradeOptions.score_mean");
  CheckNonNeg(score_std, "MaskDegradeOptions.score_std");
  CheckProb(score_min, "MaskDegradeOptions.score_min");
  CheckProb(merged_score_penalty, "MaskDegradeOptions.merged_score_penalty");
  U4D_CHECK(min_area_px >= 0, "MaskDegradeOptions.min_area_px: expected >= 0, got {}", min_area_px);
}

MaskDegradeOptions MaskDegradeOptions::None() {
  MaskDegradeOptions o;
  o.frame_drop_prob = 0;
  o.instance_miss_prob = 0;
  o.boundary_amplitude_px = 0;
  o.blur_sigma_px = 0;
  o.lower_arm_drop_prob = 0;
  o.lower_leg_drop_prob = 0;
  o.merge_prob = 0;
  o.false_positive_rate = 0;
  o.score_mean = 1;
  o.score_std = 0;
  o.min_area_px = 0;
  return o;
}

MaskDegradeOptions MaskDegradeOptions::Mild() {
  MaskDegradeOptions o;
  o.frame_drop_prob = 0;
  o.instance_miss_prob = 0.005;
  o.boundary_amplitude_px = 1.2;
  o.blur_sigma_px = 1.0;
  o.lower_arm_drop_prob = 0.05;
  o.lower_leg_drop_prob = 0.01;
  o.merge_prob = 0.1;
  o.false_positive_rate = 0.03;
  o.score_mean = 0.96;
  o.score_std = 0.02;
  return o;
}

MaskDegradeOptions MaskDegradeOptions::Default() { return MaskDegradeOptions(); }

MaskDegradeOptions MaskDegradeOptions::Realistic() {
  MaskDegradeOptions o;
  o.frame_drop_prob = 0;
  o.instance_miss_prob = 0.03;
  o.miss_persistence = 0.6;
  o.boundary_amplitude_px = 2.5;
  o.boundary_correlation_px = 32.0;
  o.blur_sigma_px = 2.0;
  o.lower_arm_drop_prob = 0;
  o.lower_leg_drop_prob = 0.1;
  o.thin_part_drop_prob = 0.35;
  o.thin_part_width_px = 13.0;
  o.merge_prob = 0.7;
  o.apart_merge_prob = 0.05;
  o.merge_persistence = 0.85;
  o.merge_distance_px = 4.0;
  o.false_positive_rate = 0.05;
  o.false_positive_max_radius_px = 40.0;
  return o;
}

MaskDegradeOptions MaskDegradeOptions::Harsh() {
  MaskDegradeOptions o;
  o.frame_drop_prob = 0.08;
  o.instance_miss_prob = 0.08;
  o.boundary_amplitude_px = 5.0;
  o.boundary_correlation_px = 32.0;
  o.blur_sigma_px = 3.0;
  o.lower_arm_drop_prob = 0.4;
  o.lower_leg_drop_prob = 0.15;
  o.merge_prob = 0.6;
  o.merge_distance_px = 6.0;
  o.false_positive_rate = 0.5;
  o.false_positive_max_radius_px = 50.0;
  o.false_positive_score_max = 0.7;
  o.score_mean = 0.85;
  o.score_std = 0.08;
  return o;
}

// ------------------------------------------------------------ masks

DegradedMask DegradeInstanceMask(const cv::Mat& gt_ids, const cv::Mat& parts,
                                 const MaskDegradeOptions& options, uint64_t seed,
                                 DetectorMemory* memory,
                                 const std::vector<std::pair<int, int>>* contacts,
                                 const std::map<int, std::string>* classes) {
  options.Check();
  U4D_CHECK(!gt_ids.empty(), "DegradeInstanceMask: gt_ids is empty");
  U4D_CHECK(gt_ids.type() == CV_16UC1, "DegradeInstanceMask: gt_ids must be CV_16UC1, got type {}",
            gt_ids.type());
  const bool have_parts = !parts.empty();
  if (have_parts) {
    U4D_CHECK(parts.type() == CV_8UC1, "DegradeInstanceMask: parts must be CV_8UC1, got type {}",
              parts.type());
    U4D_CHECK(parts.size() == gt_ids.size(),
              "DegradeInstanceMask: parts is {}x{} but gt_ids is {}x{}", parts.cols, parts.rows,
              gt_ids.cols, gt_ids.rows);
    double max_part = 0;
    cv::minMaxLoc(parts, nullptr, &max_part);
    U4D_CHECK(max_part <= static_cast<double>(BodyPart::kFoot),
              "DegradeInstanceMask: parts holds value {}, not a BodyPart (max {})", max_part,
              static_cast<int>(BodyPart::kFoot));
  }
  const uint64_t call_seed = Mix(options.seed, seed);
  const cv::Size size = gt_ids.size();

  // GT instances and their bounding boxes.
  std::map<int, cv::Rect> boxes;
  for (int y = 0; y < size.height; ++y) {
    const uint16_t* row = gt_ids.ptr<uint16_t>(y);
    for (int x = 0; x < size.width; ++x) {
      if (!row[x]) continue;
      auto [it, inserted] = boxes.try_emplace(row[x], x, y, 1, 1);
      if (!inserted) it->second |= cv::Rect(x, y, 1, 1);
    }
  }
  std::vector<int> gt_list;
  gt_list.reserve(boxes.size());
  for (const auto& [id, box] : boxes) gt_list.push_back(id);
  const int n = static_cast<int>(gt_list.size());

  DegradedMask out;
  out.mask.ids = cv::Mat(size, CV_16UC1, cv::Scalar(0));
  Rng frame_rng(Mix(call_seed, kFrameStream));
  if (frame_rng.Bernoulli(options.frame_drop_prob)) {
    out.dropped = true;
    out.missed_gt_ids = gt_list;
    return out;
  }
  const cv::Rect image_rect(0, 0, size.width, size.height);
  const int margin = Margin(options);
  auto expand = [&](const cv::Rect& r) {
    return cv::Rect(r.x - margin, r.y - margin, r.width + 2 * margin, r.height + 2 * margin) &
           image_rect;
  };

  // 1. Merging, decided on the GT masks: pairs within merge_distance_px.
  const bool merge_memory = memory != nullptr && options.merge_persistence >= 0;
  const bool miss_memory = memory != nullptr && options.miss_persistence >= 0;
  DetectorMemory now;
  now.present.insert(gt_list.begin(), gt_list.end());
  UnionFind groups(n);
  const int reach = static_cast<int>(std::ceil(options.merge_distance_px));
  for (int a = 0; a < n && options.merge_prob > 0; ++a) {
    const cv::Rect grown_a(boxes[gt_list[a]].x - reach - 1, boxes[gt_list[a]].y - reach - 1,
                           boxes[gt_list[a]].width + 2 * reach + 2,
                           boxes[gt_list[a]].height + 2 * reach + 2);
    const cv::Rect roi = grown_a & image_rect;
    cv::Mat mask_a = gt_ids(roi) == gt_list[a];
    cv::Mat dist;
    cv::Mat not_a;
    cv::bitwise_not(mask_a, not_a);
    cv::distanceTransform(not_a, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    for (int b = a + 1; b < n; ++b) {
      if ((boxes[gt_list[b]] & roi).empty()) continue;
      const cv::Mat mask_b = gt_ids(roi) == gt_list[b];
      if (cv::countNonZero(mask_b) == 0) continue;
      double min_dist = 0;
      cv::minMaxLoc(dist, &min_dist, nullptr, nullptr, nullptr, mask_b);
      // Adjacent pixels are at distance 1: a gap of g background pixels gives g + 1.
      if (min_dist - 1 > options.merge_distance_px) continue;
      Rng pair_rng(Mix(call_seed, kPairStream + static_cast<uint64_t>(gt_list[a]) * 65536 +
                                      static_cast<uint64_t>(gt_list[b])));
      const std::pair<int, int> pair(gt_list[a], gt_list[b]);
      double rate = options.merge_prob;
      if (contacts != nullptr && options.apart_merge_prob >= 0 &&
          std::find(contacts->begin(), contacts->end(), pair) == contacts->end())
        rate = options.apart_merge_prob;
      double prob = rate;
      if (merge_memory && memory->touching.count(pair))
        prob = MarkovProbability(rate, options.merge_persistence, memory->merged.count(pair) > 0);
      now.touching.insert(pair);
      if (pair_rng.Bernoulli(prob)) {
        groups.Unite(a, b);
        out.merged_gt_ids.push_back(pair);
        now.merged.insert(pair);
      }
    }
  }

  // 2. Working label image (index into gt_list + 1) with thin limbs removed.
  std::vector<int> index_of_id(65536, 0);
  for (int i = 0; i < n; ++i) index_of_id[gt_list[i]] = i + 1;
  cv::Mat work(size, CV_32S);
  for (int y = 0; y < size.height; ++y) {
    const uint16_t* in = gt_ids.ptr<uint16_t>(y);
    int* w = work.ptr<int>(y);
    for (int x = 0; x < size.width; ++x) w[x] = index_of_id[in[x]];
  }
  std::vector<Rng> instance_rngs;
  instance_rngs.reserve(n);
  for (int i = 0; i < n; ++i)
    instance_rngs.emplace_back(Mix(call_seed, kInstanceStream + static_cast<uint64_t>(gt_list[i])));
  if (have_parts) {
    for (int i = 0; i < n; ++i) {
      const cv::Rect roi = boxes[gt_list[i]];
      const cv::Mat own = gt_ids(roi) == gt_list[i];
      const cv::Mat p = parts(roi);
      const std::array<std::pair<cv::Mat, double>, 2> limbs = {
          std::pair{own & ((p == static_cast<int>(BodyPart::kForearm)) |
                           (p == static_cast<int>(BodyPart::kHand))),
                    options.lower_arm_drop_prob},
          std::pair{own & ((p == static_cast<int>(BodyPart::kShin)) |
                           (p == static_cast<int>(BodyPart::kFoot))),
                    options.lower_leg_drop_prob}};
      for (const auto& [limb, prob] : limbs) {
        cv::Mat components;
        const int count = cv::connectedComponents(limb, components, 8, CV_32S);
        for (int c = 1; c < count; ++c) {
          if (!instance_rngs[i].Bernoulli(prob)) continue;
          ++out.dropped_limbs;
          cv::Mat w = work(roi);
          w.setTo(0, components == c);
        }
      }
    }
  }
  if (options.thin_part_drop_prob > 0) {
    for (int i = 0; i < n; ++i)
      out.dropped_limbs += DropThinParts(work(boxes[gt_list[i]]), i + 1, options.thin_part_width_px,
                                         options.thin_part_drop_prob, instance_rngs[i]);
  }

  // 3. Candidates: one per group of merged GT instances.
  struct Candidate {
    std::vector<int> members;  // indices into gt_list
    bool merged = false;
  };
  std::map<int, Candidate> by_root;
  for (int i = 0; i < n; ++i) by_root[groups.Find(i)].members.push_back(i);

  cv::Mat best_margin(size, CV_32F, cv::Scalar(0));
  cv::Mat labels(size, CV_32S, cv::Scalar(0));
  std::vector<Candidate> candidates;
  std::vector<double> candidate_scores;
  for (auto& [root, cand] : by_root) {
    cand.merged = cand.members.size() > 1;
    uint64_t key = 0;
    for (int m : cand.members) key = Mix(key, static_cast<uint64_t>(gt_list[m]));
    Rng rng(Mix(call_seed, kGroupStream + key));
    double miss_prob = options.instance_miss_prob;
    const int single = cand.merged ? 0 : gt_list[cand.members[0]];
    if (miss_memory && single != 0 && memory->present.count(single))
      miss_prob = MarkovProbability(options.instance_miss_prob, options.miss_persistence,
                                    memory->missed.count(single) > 0);
    if (rng.Bernoulli(miss_prob)) {
      if (single != 0) now.missed.insert(single);
      continue;
    }
    cv::Rect box = boxes[gt_list[cand.members[0]]];
    for (int m : cand.members) box |= boxes[gt_list[m]];
    const cv::Rect roi = expand(box);
    cv::Mat mask(roi.size(), CV_8U, cv::Scalar(0));
    const cv::Mat w = work(roi);
    for (int m : cand.members) mask.setTo(255, w == m + 1);
    if (cv::countNonZero(mask) == 0) continue;
    if (cand.merged && reach > 0) {
      // Bridge the gap between the merged people, over background only.
      cv::Mat closed;
      const cv::Mat kernel =
          cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * reach + 3, 2 * reach + 3));
      cv::morphologyEx(mask, closed, cv::MORPH_CLOSE, kernel);
      mask.setTo(255, closed & (gt_ids(roi) == 0));
    }
    const int label = static_cast<int>(candidates.size()) + 1;
    Compete(mask, roi, options, label, rng, best_margin, labels);
    double score = options.score_mean + options.score_std * rng.Normal();
    if (cand.merged) score -= options.merged_score_penalty;
    candidate_scores.push_back(Clamp(score, options.score_min, 1.0));
    candidates.push_back(cand);
  }

  // 4. False positives on background.
  Rng fp_rng(Mix(call_seed, kFalsePositiveStream));
  const int num_fp = fp_rng.Poisson(options.false_positive_rate);
  std::vector<int> fp_labels;
  for (int f = 0; f < num_fp; ++f) {
    cv::Point center(-1, -1);
    for (int attempt = 0; attempt < 50; ++attempt) {
      const cv::Point c(fp_rng.UniformInt(size.width), fp_rng.UniformInt(size.height));
      if (labels.at<int>(c) == 0 && gt_ids.at<uint16_t>(c) == 0) {
        center = c;
        break;
      }
    }
    const double rx =
        fp_rng.Uniform(options.false_positive_min_radius_px, options.false_positive_max_radius_px);
    const double ry =
        fp_rng.Uniform(options.false_positive_min_radius_px, options.false_positive_max_radius_px);
    const double angle = fp_rng.Uniform(0, 180);
    const double score =
        fp_rng.Uniform(options.false_positive_score_min, options.false_positive_score_max);
    Rng blob_rng(fp_rng.Next());
    if (center.x < 0) continue;  // no background left
    const int r = static_cast<int>(std::ceil(std::max(rx, ry)));
    const cv::Rect roi = expand(cv::Rect(center.x - r, center.y - r, 2 * r + 1, 2 * r + 1));
    cv::Mat mask(roi.size(), CV_8U, cv::Scalar(0));
    cv::ellipse(
        mask,
        cv::RotatedRect(cv::Point2f(center - roi.tl()), cv::Size2f(2 * rx + 1, 2 * ry + 1), angle),
        cv::Scalar(255), cv::FILLED);
    const cv::Mat background = (labels == 0) & (gt_ids == 0);
    const int label = static_cast<int>(candidates.size() + fp_labels.size()) + 1;
    Compete(mask, roi, options, label, blob_rng, best_margin, labels, &background);
    if (labels.at<int>(center) == 0) labels.at<int>(center) = label;  // never empty
    fp_labels.push_back(label);
    candidate_scores.push_back(score);
  }

  // 5. Drop tiny detections, renumber in random order, write the output.
  const int total = static_cast<int>(candidate_scores.size());
  std::vector<int> area(total + 1, 0);
  for (int y = 0; y < size.height; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < size.width; ++x)
      if (l[x]) ++area[l[x]];
  }
  std::vector<int> kept;
  for (int l = 1; l <= total; ++l)
    if (area[l] > 0 && area[l] >= options.min_area_px) kept.push_back(l);
  std::vector<int> new_ids(kept.size());
  std::iota(new_ids.begin(), new_ids.end(), 1);
  Rng renumber_rng(Mix(call_seed, kRenumberStream));
  for (int i = static_cast<int>(new_ids.size()) - 1; i > 0; --i)
    std::swap(new_ids[i], new_ids[renumber_rng.UniformInt(i + 1)]);
  std::vector<int> id_of_label(total + 1, 0);
  for (size_t k = 0; k < kept.size(); ++k) id_of_label[kept[k]] = new_ids[k];
  for (int y = 0; y < size.height; ++y) {
    const int* l = labels.ptr<int>(y);
    uint16_t* o = out.mask.ids.ptr<uint16_t>(y);
    for (int x = 0; x < size.width; ++x) o[x] = static_cast<uint16_t>(id_of_label[l[x]]);
  }

  std::vector<std::pair<InstanceInfo, std::vector<int>>> instances;
  std::vector<bool> covered(n, false);
  for (int l : kept) {
    InstanceInfo info;
    info.id = id_of_label[l];
    info.label = "person";
    info.score = candidate_scores[l - 1];
    std::vector<int> gts;
    if (l <= static_cast<int>(candidates.size())) {
      const std::vector<int>& members = candidates[l - 1].members;
      info.label = MajorityClass(gt_ids, boxes, gt_list, members, classes);
      for (int m : members) {
        gts.push_back(gt_list[m]);
        covered[m] = true;
      }
      std::sort(gts.begin(), gts.end());
    } else {
      ++out.false_positives;
    }
    instances.emplace_back(info, gts);
  }
  std::sort(instances.begin(), instances.end(),
            [](const auto& a, const auto& b) { return a.first.id < b.first.id; });
  for (auto& [info, gts] : instances) {
    out.mask.instances.push_back(info);
    out.instance_gt_ids.push_back(std::move(gts));
  }
  for (int i = 0; i < n; ++i)
    if (!covered[i]) out.missed_gt_ids.push_back(gt_list[i]);
  if (memory != nullptr) *memory = std::move(now);
  return out;
}

// ------------------------------------------------------------ keypoints

void KeypointDegradeOptions::Check() const {
  CheckNonNeg(noise_sigma_px, "KeypointDegradeOptions.noise_sigma_px");
  CheckProb(outlier_prob, "KeypointDegradeOptions.outlier_prob");
  CheckNonNeg(outlier_radius_px, "KeypointDegradeOptions.outlier_radius_px");
  CheckProb(keypoint_miss_prob, "KeypointDegradeOptions.keypoint_miss_prob");
  CheckProb(person_miss_prob, "KeypointDegradeOptions.person_miss_prob");
  CheckProb(swap_prob, "KeypointDegradeOptions.swap_prob");
  CheckProb(swap_prob_from_behind, "KeypointDegradeOptions.swap_prob_from_behind");
  CheckProb(occluded_miss_prob, "KeypointDegradeOptions.occluded_miss_prob");
  CheckProb(occluded_confidence_scale, "KeypointDegradeOptions.occluded_confidence_scale");
  CheckNonNeg(occluded_noise_scale, "KeypointDegradeOptions.occluded_noise_scale");
  CheckProb(confidence_mean, "KeypointDegradeOptions.confidence_mean");
  CheckNonNeg(confidence_std, "KeypointDegradeOptions.confidence_std");
  U4D_CHECK(min_keypoints >= 0 && min_keypoints <= coco17::kNumKeypoints,
            "KeypointDegradeOptions.min_keypoints: expected in [0, 17], got {}", min_keypoints);
}

KeypointDegradeOptions KeypointDegradeOptions::None() {
  KeypointDegradeOptions o;
  o.noise_sigma_px = 0;
  o.outlier_prob = 0;
  o.keypoint_miss_prob = 0;
  o.person_miss_prob = 0;
  o.swap_prob = 0;
  o.swap_prob_from_behind = 0;
  o.occluded_miss_prob = 0;
  o.occluded_confidence_scale = 1;
  o.occluded_noise_scale = 1;
  o.confidence_mean = 1;
  o.confidence_std = 0;
  o.min_keypoints = 1;
  return o;
}

KeypointDegradeOptions KeypointDegradeOptions::Mild() {
  KeypointDegradeOptions o;
  o.noise_sigma_px = 1.0;
  o.outlier_prob = 0.002;
  o.keypoint_miss_prob = 0.02;
  o.person_miss_prob = 0.01;
  o.swap_prob = 0.005;
  o.swap_prob_from_behind = 0.05;
  o.occluded_miss_prob = 0.3;
  return o;
}

KeypointDegradeOptions KeypointDegradeOptions::Default() { return KeypointDegradeOptions(); }

KeypointDegradeOptions KeypointDegradeOptions::Harsh() {
  KeypointDegradeOptions o;
  o.noise_sigma_px = 5.0;
  o.outlier_prob = 0.05;
  o.outlier_radius_px = 60.0;
  o.keypoint_miss_prob = 0.15;
  o.person_miss_prob = 0.1;
  o.swap_prob = 0.08;
  o.swap_prob_from_behind = 0.35;
  o.occluded_miss_prob = 0.8;
  o.confidence_mean = 0.6;
  o.confidence_std = 0.15;
  return o;
}

std::vector<DetectedPose2d> DegradeKeypoints(
    const std::vector<std::array<Eigen::Vector3d, coco17::kNumKeypoints>>& coco_keypoints_3d,
    const Camera& camera, const cv::Mat& gt_ids, const KeypointDegradeOptions& options,
    uint64_t seed) {
  options.Check();
  camera.Check("DegradeKeypoints: camera");
  U4D_CHECK(gt_ids.type() == CV_16UC1, "DegradeKeypoints: gt_ids must be CV_16UC1, got type {}",
            gt_ids.type());
  U4D_CHECK(gt_ids.cols == camera.width && gt_ids.rows == camera.height,
            "DegradeKeypoints: gt_ids is {}x{} but the camera is {}x{}", gt_ids.cols, gt_ids.rows,
            camera.width, camera.height);
  for (size_t p = 0; p < coco_keypoints_3d.size(); ++p)
    for (int k = 0; k < coco17::kNumKeypoints; ++k)
      U4D_CHECK(coco_keypoints_3d[p][k].allFinite(),
                "DegradeKeypoints: person {} keypoint {} is not finite", p, k);
  const uint64_t call_seed = Mix(options.seed, seed);

  std::vector<DetectedPose2d> detections;
  for (size_t p = 0; p < coco_keypoints_3d.size(); ++p) {
    Rng rng(Mix(call_seed, kPersonStream + p));
    const int own_id = static_cast<int>(p) + 1;
    // Project; the stream draws a fixed number of values per keypoint so that
    // changing one probability does not shift the others' noise.
    std::array<Eigen::Vector2d, coco17::kNumKeypoints> projected;
    std::array<bool, coco17::kNumKeypoints> in_view;
    int num_in_view = 0;
    for (int k = 0; k < coco17::kNumKeypoints; ++k) {
      const Eigen::Vector3d& point = coco_keypoints_3d[p][k];
      in_view[k] = camera.Depth(point) > 0;
      if (in_view[k]) {
        projected[k] = camera.Project(point);
        in_view[k] = projected[k].allFinite() && camera.InImage(projected[k]);
      }
      num_in_view += in_view[k];
    }
    const bool person_missed = rng.Bernoulli(options.person_miss_prob);
    const bool from_behind =
        in_view[coco17::kLeftShoulder] && in_view[coco17::kRightShoulder] &&
        projected[coco17::kLeftShoulder].x() < projected[coco17::kRightShoulder].x();
    const bool swapped =
        rng.Bernoulli(from_behind ? options.swap_prob_from_behind : options.swap_prob);

    DetectedPose2d det;
    det.gt_person = static_cast<int>(p);
    det.swapped = swapped;
    int detected = 0;
    double confidence_sum = 0;
    for (int k = 0; k < coco17::kNumKeypoints; ++k) {
      // Fixed draws per keypoint.
      const double u_miss = rng.Uniform(), u_occ = rng.Uniform(), u_out = rng.Uniform();
      const double nx = rng.Normal(), ny = rng.Normal(), nc = rng.Normal();
      const double out_r = std::sqrt(rng.Uniform()), out_a = 2 * kPi * rng.Uniform();
      const int label = swapped ? Coco17Mirror(k) : k;  // where this physical keypoint is reported
      det.keypoints[label] = Eigen::Vector3d::Zero();
      if (!in_view[k] || u_miss < options.keypoint_miss_prob) continue;
      const cv::Point pixel(static_cast<int>(std::lround(projected[k].x())),
                            static_cast<int>(std::lround(projected[k].y())));
      const int at = gt_ids.at<uint16_t>(pixel);
      const bool occluded = at != 0 && at != own_id;
      if (occluded && u_occ < options.occluded_miss_prob) continue;
      double sigma = options.noise_sigma_px;
      double confidence = Clamp(options.confidence_mean + options.confidence_std * nc, 0.05, 1.0);
      if (occluded) {
        sigma *= options.occluded_noise_scale;
        confidence *= options.occluded_confidence_scale;
      }
      Eigen::Vector2d xy = projected[k] + sigma * Eigen::Vector2d(nx, ny);
      if (u_out < options.outlier_prob)
        xy = projected[k] +
             options.outlier_radius_px * out_r * Eigen::Vector2d(std::cos(out_a), std::sin(out_a));
      if (!camera.InImage(xy)) continue;
      det.keypoints[label] = Eigen::Vector3d(xy.x(), xy.y(), confidence);
      ++detected;
      confidence_sum += confidence;
    }
    if (person_missed || num_in_view == 0 || detected < std::max(1, options.min_keypoints))
      continue;
    det.score = confidence_sum / static_cast<double>(coco17::kNumKeypoints);
    detections.push_back(det);
  }
  std::stable_sort(
      detections.begin(), detections.end(),
      [](const DetectedPose2d& a, const DetectedPose2d& b) { return a.score > b.score; });
  return detections;
}

}  // namespace u4d::synth
