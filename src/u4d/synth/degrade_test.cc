#include "u4d/synth/degrade.h"

#include <cmath>
#include <limits>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "u4d/synth/scene.h"
#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

// ------------------------------------------------------------ GT builders

struct GtImages {
  cv::Mat ids;    // CV_16UC1
  cv::Mat parts;  // CV_8UC1
};

GtImages Blank(int width, int height) {
  return {cv::Mat(height, width, CV_16UC1, cv::Scalar(0)),
          cv::Mat(height, width, CV_8UC1, cv::Scalar(0))};
}

void Line(GtImages& gt, int id, BodyPart part, cv::Point a, cv::Point b, int thickness) {
  cv::line(gt.ids, a, b, cv::Scalar(id), thickness);
  cv::line(gt.parts, a, b, cv::Scalar(static_cast<int>(part)), thickness);
}

// A stick-figure person about 250 px tall centred at column cx, torso centre
// row cy. Lower arms (forearm + hand) reach about 52 px either side of cx.
void DrawPerson(GtImages& gt, int id, int cx, int cy) {
  cv::ellipse(gt.ids, cv::Point(cx, cy), cv::Size(26, 55), 0, 0, 360, cv::Scalar(id), cv::FILLED);
  cv::ellipse(gt.parts, cv::Point(cx, cy), cv::Size(26, 55), 0, 0, 360,
              cv::Scalar(static_cast<int>(BodyPart::kTorso)), cv::FILLED);
  cv::circle(gt.ids, cv::Point(cx, cy - 72), 17, cv::Scalar(id), cv::FILLED);
  cv::circle(gt.parts, cv::Point(cx, cy - 72), 17, cv::Scalar(static_cast<int>(BodyPart::kHead)),
             cv::FILLED);
  for (int s : {-1, 1}) {
    Line(gt, id, BodyPart::kUpperArm, {cx + s * 24, cy - 42}, {cx + s * 40, cy}, 12);
    Line(gt, id, BodyPart::kForearm, {cx + s * 43, cy + 4}, {cx + s * 47, cy + 38}, 10);
    Line(gt, id, BodyPart::kHand, {cx + s * 47, cy + 44}, {cx + s * 48, cy + 52}, 9);
    Line(gt, id, BodyPart::kThigh, {cx + s * 12, cy + 50}, {cx + s * 15, cy + 95}, 15);
    Line(gt, id, BodyPart::kShin, {cx + s * 15, cy + 103}, {cx + s * 16, cy + 140}, 11);
    Line(gt, id, BodyPart::kFoot, {cx + s * 16, cy + 148}, {cx + s * 26, cy + 150}, 7);
  }
}

// Three people in 480x360: 1 and 2 touch (hands overlap), 3 is far from both.
GtImages ThreePeople() {
  GtImages gt = Blank(480, 360);
  DrawPerson(gt, 1, 110, 160);
  DrawPerson(gt, 2, 217, 160);
  DrawPerson(gt, 3, 400, 160);
  return gt;
}

// ------------------------------------------------------------ metrics

double IoU(const cv::Mat& a, const cv::Mat& b) {
  const double inter = cv::countNonZero(a & b);
  const double uni = cv::countNonZero(a | b);
  return uni > 0 ? inter / uni : 1.0;
}

// Output id of the unmerged instance that came from GT id `gt`, or 0.
int OutputIdOf(const DegradedMask& d, int gt) {
  for (size_t i = 0; i < d.mask.instances.size(); ++i)
    if (d.instance_gt_ids[i] == std::vector<int>{gt}) return d.mask.instances[i].id;
  return 0;
}

// Pixels (x, y) on the inner boundary of a binary mask (4-neighbourhood).
cv::Mat InnerBoundary(const cv::Mat& mask) {
  cv::Mat eroded;
  cv::erode(mask, eroded, cv::getStructuringElement(cv::MORPH_CROSS, cv::Size(3, 3)));
  return mask & ~eroded;
}

bool SameMask(const DegradedMask& a, const DegradedMask& b) {
  if (cv::countNonZero(a.mask.ids != b.mask.ids) != 0) return false;
  if (a.mask.instances.size() != b.mask.instances.size()) return false;
  for (size_t i = 0; i < a.mask.instances.size(); ++i)
    if (a.mask.instances[i].id != b.mask.instances[i].id ||
        a.mask.instances[i].score != b.mask.instances[i].score)
      return false;
  return a.instance_gt_ids == b.instance_gt_ids && a.dropped == b.dropped;
}

// |observed - expected| within 4 binomial standard deviations.
void ExpectBinomial(int successes, int trials, double p, const char* what) {
  const double expected = trials * p;
  const double sd = std::sqrt(trials * p * (1 - p));
  EXPECT_NEAR(successes, expected, 4 * sd + 1)
      << what << ": " << successes << " of " << trials << ", p = " << p;
}

// ------------------------------------------------------------ mask tests

TEST(DegradeMaskTest, DeterministicPerSeed) {
  const GtImages gt = ThreePeople();
  MaskDegradeOptions o = MaskDegradeOptions::Harsh();
  o.frame_drop_prob = 0;
  const DegradedMask a = DegradeInstanceMask(gt.ids, gt.parts, o, 7);
  const DegradedMask b = DegradeInstanceMask(gt.ids, gt.parts, o, 7);
  const DegradedMask c = DegradeInstanceMask(gt.ids, gt.parts, o, 8);
  EXPECT_TRUE(SameMask(a, b));
  EXPECT_FALSE(SameMask(a, c));
  o.seed = 1;  // the options' seed also changes the realisation
  EXPECT_FALSE(SameMask(a, DegradeInstanceMask(gt.ids, gt.parts, o, 7)));
  EXPECT_NE(DegradeSeed(0, 1, 2), DegradeSeed(0, 2, 1));
  EXPECT_NE(DegradeSeed(0, 0, 0), DegradeSeed(1, 0, 0));
}

TEST(DegradeMaskTest, NoneReproducesGroundTruthUpToRenumbering) {
  const GtImages gt = ThreePeople();
  std::set<std::vector<int>> orders;
  for (uint64_t seed = 0; seed < 8; ++seed) {
    const DegradedMask d = DegradeInstanceMask(gt.ids, gt.parts, MaskDegradeOptions::None(), seed);
    ASSERT_FALSE(d.dropped);
    ASSERT_EQ(d.mask.instances.size(), 3u);
    EXPECT_EQ(d.false_positives, 0);
    EXPECT_TRUE(d.merged_gt_ids.empty());
    EXPECT_TRUE(d.missed_gt_ids.empty());
    std::vector<int> order;
    for (int g = 1; g <= 3; ++g) {
      const int id = OutputIdOf(d, g);
      ASSERT_GT(id, 0);
      EXPECT_EQ(IoU(gt.ids == g, d.mask.ids == id), 1.0);
      EXPECT_EQ(d.mask.Find(id)->label, "person");
      EXPECT_EQ(d.mask.Find(id)->score, 1.0);
      order.push_back(id);
    }
    EXPECT_EQ(cv::countNonZero(d.mask.ids), cv::countNonZero(gt.ids));
    orders.insert(order);
  }
  EXPECT_GT(orders.size(), 1u) << "ids are never renumbered";
}

// Boundary noise only: the mean distance from the degraded boundary to the GT
// boundary is E|n| = sqrt(2/pi) * amplitude (plus < 0.5 px discretisation),
// and IoU follows from the perimeter: a band of width E|n| along a perimeter
// P on a blob of area A gives IoU ~ (A - P E|n| / 2) / (A + P E|n| / 2).
TEST(DegradeMaskTest, BoundaryErrorMatchesAmplitude) {
  GtImages gt = Blank(400, 300);
  cv::ellipse(gt.ids, cv::Point(200, 150), cv::Size(110, 80), 20, 0, 360, cv::Scalar(1),
              cv::FILLED);
  const cv::Mat gt_mask = gt.ids == 1;
  const double area = cv::countNonZero(gt_mask);
  const double perimeter = cv::countNonZero(InnerBoundary(gt_mask));
  cv::Mat not_boundary = ~InnerBoundary(gt_mask), dist_to_gt;
  cv::distanceTransform(not_boundary, dist_to_gt, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  for (double amplitude : {2.0, 5.0}) {
    MaskDegradeOptions o = MaskDegradeOptions::None();
    o.boundary_amplitude_px = amplitude;
    double sum_dist = 0, sum_iou = 0;
    int count = 0;
    const int trials = 20;
    for (int seed = 0; seed < trials; ++seed) {
      const DegradedMask d = DegradeInstanceMask(gt.ids, gt.parts, o, seed);
      ASSERT_EQ(d.mask.instances.size(), 1u);
      const cv::Mat mask = d.mask.ids == d.mask.instances[0].id;
      sum_iou += IoU(mask, gt_mask);
      const cv::Mat boundary = InnerBoundary(mask);
      for (int y = 0; y < boundary.rows; ++y)
        for (int x = 0; x < boundary.cols; ++x)
          if (boundary.at<uint8_t>(y, x)) {
            sum_dist += dist_to_gt.at<float>(y, x);
            ++count;
          }
    }
    const double mean_abs = std::sqrt(2 / M_PI) * amplitude;
    const double mean_dist = sum_dist / count;
    EXPECT_GT(mean_dist, 0.7 * mean_abs) << "amplitude " << amplitude;
    EXPECT_LT(mean_dist, 1.3 * mean_abs + 0.5) << "amplitude " << amplitude;
    const double band = perimeter * mean_abs / 2;
    const double predicted_iou = (area - band) / (area + band);
    EXPECT_NEAR(sum_iou / trials, predicted_iou, 0.03) << "amplitude " << amplitude;
    RecordProperty(amplitude < 3 ? "mean_boundary_dist_a2" : "mean_boundary_dist_a5",
                   std::to_string(mean_dist));
    std::printf(
        "amplitude %.1f: mean boundary distance %.2f px (E|n| %.2f), IoU %.3f (pred %.3f)\n",
        amplitude, mean_dist, mean_abs, sum_iou / trials, predicted_iou);
  }
}

// Mean over GT instances of the best IoU with any output instance (a missed
// instance or a dropped frame counts 0).
double MeanBestIoU(const GtImages& gt, const MaskDegradeOptions& o, int trials) {
  double sum = 0;
  int count = 0;
  for (int seed = 0; seed < trials; ++seed) {
    const DegradedMask d = DegradeInstanceMask(gt.ids, gt.parts, o, seed);
    for (int g = 1; g <= 3; ++g) {
      const cv::Mat gt_mask = gt.ids == g;
      double best = 0;
      for (const InstanceInfo& info : d.mask.instances)
        best = std::max(best, IoU(gt_mask, d.mask.ids == info.id));
      sum += best;
      ++count;
    }
  }
  return sum / count;
}

// Default options on the stick figures (area ~11100 px, perimeter ~1110 px,
// limbs 10-15 px thick). Expected: boundary noise alone (amplitude 2, E|n| 1.6)
// gives a band of 1110 * 1.6 / 2 = 890 px, IoU ~ (11100 - 890) / (11100 + 890)
// = 0.85; blur ~0.99; dropped limbs ~0.97; merging the touching pair (p 0.15,
// IoU ~0.5 for 2 of 3 people) ~0.95; misses ~0.96 -> about 0.75 together.
// Presets are ordered Mild > Default > Harsh.
TEST(DegradeMaskTest, DefaultIoUBelowOneAboveFloor) {
  const GtImages gt = ThreePeople();
  const double mild = MeanBestIoU(gt, MaskDegradeOptions::Mild(), 20);
  const double def = MeanBestIoU(gt, MaskDegradeOptions::Default(), 30);
  const double harsh = MeanBestIoU(gt, MaskDegradeOptions::Harsh(), 20);
  std::printf("mean per-instance IoU: mild %.3f, default %.3f, harsh %.3f\n", mild, def, harsh);
  EXPECT_GT(def, 0.65);
  EXPECT_LT(def, 0.85);
  EXPECT_GT(mild, def);
  EXPECT_GT(def, harsh);
  EXPECT_GT(harsh, 0.3);
}

TEST(DegradeMaskTest, DropsWholeLowerArmsAndNothingElse) {
  const GtImages gt = ThreePeople();
  MaskDegradeOptions o = MaskDegradeOptions::None();
  o.lower_arm_drop_prob = 1;
  const DegradedMask d = DegradeInstanceMask(gt.ids, gt.parts, o, 3);
  EXPECT_EQ(d.dropped_limbs, 6);
  const cv::Mat lower_arm = (gt.parts == static_cast<int>(BodyPart::kForearm)) |
                            (gt.parts == static_cast<int>(BodyPart::kHand));
  EXPECT_GT(cv::countNonZero(lower_arm), 1000);
  EXPECT_EQ(cv::countNonZero((d.mask.ids != 0) & lower_arm), 0) << "a lower-arm pixel survived";
  for (int g = 1; g <= 3; ++g) {
    const cv::Mat kept = (gt.ids == g) & ~lower_arm;
    EXPECT_EQ(IoU(kept, d.mask.ids == OutputIdOf(d, g)), 1.0) << "GT " << g;
  }

  // Rate: each lower arm / leg independently, all-or-nothing.
  o = MaskDegradeOptions::None();
  o.lower_arm_drop_prob = 0.3;
  o.lower_leg_drop_prob = 0.1;
  const cv::Mat lower_leg = (gt.parts == static_cast<int>(BodyPart::kShin)) |
                            (gt.parts == static_cast<int>(BodyPart::kFoot));
  int arms = 0, legs = 0;
  const int trials = 60;
  for (int seed = 0; seed < trials; ++seed) {
    const DegradedMask r = DegradeInstanceMask(gt.ids, gt.parts, o, seed);
    const cv::Mat present = r.mask.ids != 0;
    int dropped_here = 0;
    for (int g = 1; g <= 3; ++g) {
      for (const cv::Mat* limb : {&lower_arm, &lower_leg}) {
        cv::Mat comps;
        const int n = cv::connectedComponents(*limb & (gt.ids == g), comps, 8, CV_32S);
        for (int c = 1; c < n; ++c) {
          const cv::Mat comp = comps == c;
          const int kept = cv::countNonZero(comp & present);
          ASSERT_TRUE(kept == 0 || kept == cv::countNonZero(comp)) << "partially dropped limb";
          if (kept == 0) {
            (limb == &lower_arm ? arms : legs) += 1;
            ++dropped_here;
          }
        }
      }
    }
    EXPECT_EQ(dropped_here, r.dropped_limbs);
  }
  ExpectBinomial(arms, 6 * trials, 0.3, "lower arms dropped");
  ExpectBinomial(legs, 6 * trials, 0.1, "lower legs dropped");
}

TEST(DegradeMaskTest, MergesTouchingPeopleAtConfiguredRateOnly) {
  const GtImages gt = ThreePeople();
  MaskDegradeOptions o = MaskDegradeOptions::None();
  o.merge_prob = 0.3;
  int merged = 0;
  const int trials = 200;
  for (int seed = 0; seed < trials; ++seed) {
    const DegradedMask d = DegradeInstanceMask(gt.ids, gt.parts, o, seed);
    for (const auto& [a, b] : d.merged_gt_ids)
      ASSERT_TRUE(a == 1 && b == 2) << "merged far-apart people " << a << ", " << b;
    if (d.merged_gt_ids.empty()) {
      ASSERT_EQ(d.mask.instances.size(), 3u);
      continue;
    }
    ++merged;
    ASSERT_EQ(d.mask.instances.size(), 2u);
    for (size_t i = 0; i < d.mask.instances.size(); ++i) {
      if (d.instance_gt_ids[i] != std::vector<int>{1, 2}) continue;
      const cv::Mat m = d.mask.ids == d.mask.instances[i].id;
      const cv::Mat both = (gt.ids == 1) | (gt.ids == 2);
      EXPECT_EQ(cv::countNonZero(both & ~m), 0);  // covers both people
      EXPECT_EQ(cv::countNonZero(m & (gt.ids == 3)), 0);
      EXPECT_NEAR(d.mask.instances[i].score, 1.0 - o.merged_score_penalty, 1e-12);
    }
  }
  ExpectBinomial(merged, trials, 0.3, "merges of the touching pair");
}

// A person (1) touching a small box (2), and a ball (3) apart: each instance
// gets its GT class, a merged one the class of its larger member.
TEST(DegradeMaskTest, InstancesCarryTheirClass) {
  GtImages gt = Blank(480, 360);
  DrawPerson(gt, 1, 110, 160);
  cv::rectangle(gt.ids, cv::Rect(140, 200, 30, 25), cv::Scalar(2), cv::FILLED);
  cv::circle(gt.ids, cv::Point(400, 300), 15, cv::Scalar(3), cv::FILLED);
  const std::map<int, std::string> classes = {{1, "person"}, {2, "box"}, {3, "ball"}};
  MaskDegradeOptions o = MaskDegradeOptions::None();
  o.merge_distance_px = 40;  // the box is beside the person's hip
  for (const double merge : {0.0, 1.0}) {
    o.merge_prob = merge;
    const DegradedMask d = DegradeInstanceMask(gt.ids, gt.parts, o, 1, nullptr, nullptr, &classes);
    std::map<std::vector<int>, std::string> label_of;
    for (size_t i = 0; i < d.mask.instances.size(); ++i)
      label_of[d.instance_gt_ids[i]] = d.mask.instances[i].label;
    const std::map<std::vector<int>, std::string> expected =
        merge > 0
            ? std::map<std::vector<int>, std::string>{{{1, 2}, "person"}, {{3}, "ball"}}
            : std::map<std::vector<int>, std::string>{{{1}, "person"}, {{2}, "box"}, {{3}, "ball"}};
    EXPECT_EQ(label_of, expected) << "merge probability " << merge;
  }
  // Without classes every instance is a person.
  for (const InstanceInfo& i : DegradeInstanceMask(gt.ids, gt.parts, o, 1).mask.instances)
    EXPECT_EQ(i.label, "person");
}

TEST(DegradeMaskTest, MergesPersistInTimeAtTheLongRunRate) {
  // Persons 1 and 2 touch in every frame. With a memory, a merge stays with
  // probability merge_persistence, and the long-run rate stays merge_prob.
  const GtImages gt = ThreePeople();
  MaskDegradeOptions o = MaskDegradeOptions::None();
  o.merge_prob = 0.6;
  o.merge_persistence = 0.9;
  const int sequences = 150, frames = 12;
  int merged = 0, kept = 0, was_merged = 0;
  for (int s = 0; s < sequences; ++s) {
    DetectorMemory memory;
    bool before = false;
    for (int f = 0; f < frames; ++f) {
      const bool now = !DegradeInstanceMask(gt.ids, gt.parts, o, DegradeSeed(s, 0, f), &memory)
                            .merged_gt_ids.empty();
      merged += now;
      if (f > 0 && before) {
        ++was_merged;
        kept += now;
      }
      before = now;
    }
  }
  ExpectBinomial(merged, sequences * frames, 0.6, "merged view-frames");
  ExpectBinomial(kept, was_merged, 0.9, "merges kept at the next frame");
}

TEST(DegradeMaskTest, ApartPairsMergeAtTheirOwnRateWhenContactsAreKnown) {
  // 1 and 2 are close in the image; told that they are not in contact in 3D,
  // they merge at apart_merge_prob; told that they are, at merge_prob.
  const GtImages gt = ThreePeople();
  MaskDegradeOptions o = MaskDegradeOptions::None();
  o.merge_prob = 0.8;
  o.apart_merge_prob = 0.1;
  const std::vector<std::pair<int, int>> none, touching = {{1, 2}};
  int apart = 0, in_contact = 0;
  const int trials = 300;
  for (int seed = 0; seed < trials; ++seed) {
    apart += !DegradeInstanceMask(gt.ids, gt.parts, o, seed, nullptr, &none).merged_gt_ids.empty();
    in_contact +=
        !DegradeInstanceMask(gt.ids, gt.parts, o, seed, nullptr, &touching).merged_gt_ids.empty();
  }
  ExpectBinomial(apart, trials, 0.1, "merges of a pair not in contact");
  ExpectBinomial(in_contact, trials, 0.8, "merges of a pair in contact");
}

TEST(DegradeMaskTest, ThinPartsAreDroppedFromTheMaskAlone) {
  // A 60x100 block with a 6 px wide, 50 px long arm; no part map.
  GtImages gt = Blank(200, 160);
  gt.ids(cv::Rect(40, 30, 60, 100)).setTo(4);
  gt.ids(cv::Rect(100, 50, 50, 6)).setTo(4);
  const cv::Mat arm = cv::Mat::zeros(gt.ids.size(), CV_8U);
  arm(cv::Rect(100, 50, 50, 6)).setTo(255);
  MaskDegradeOptions o = MaskDegradeOptions::None();
  o.thin_part_width_px = 13;
  o.thin_part_drop_prob = 1.0;
  const DegradedMask all = DegradeInstanceMask(gt.ids, cv::Mat(), o, 7);
  const cv::Mat kept = all.mask.ids != 0;
  EXPECT_LT(cv::countNonZero(kept & arm), 6 * 3);  // at most the arm's root stays
  EXPECT_EQ(cv::countNonZero(gt.ids(cv::Rect(40, 30, 60, 100)) != 0) -
                cv::countNonZero(kept(cv::Rect(40, 30, 60, 100))),
            0);  // the block is whole
  EXPECT_EQ(all.dropped_limbs, 1);
  o.thin_part_drop_prob = 0.0;
  const DegradedMask none = DegradeInstanceMask(gt.ids, cv::Mat(), o, 7);
  EXPECT_EQ(cv::countNonZero((none.mask.ids != 0) != (gt.ids != 0)), 0);
}

TEST(DegradeMaskTest, DroppedFramesAndFalsePositivesAtConfiguredRates) {
  GtImages gt = Blank(160, 120);
  cv::circle(gt.ids, cv::Point(40, 60), 20, cv::Scalar(5), cv::FILLED);
  MaskDegradeOptions o = MaskDegradeOptions::None();
  o.frame_drop_prob = 0.2;
  o.false_positive_rate = 0.5;
  o.false_positive_min_radius_px = 3;
  o.false_positive_max_radius_px = 8;
  o.boundary_amplitude_px = 1.0;
  const int trials = 1000;
  int dropped = 0, fps = 0, kept_frames = 0;
  for (int seed = 0; seed < trials; ++seed) {
    const DegradedMask d = DegradeInstanceMask(gt.ids, cv::Mat(), o, seed);
    if (d.dropped) {
      ++dropped;
      ASSERT_EQ(cv::countNonZero(d.mask.ids), 0);
      ASSERT_TRUE(d.mask.instances.empty());
      ASSERT_EQ(d.missed_gt_ids, std::vector<int>{5});
      continue;
    }
    ++kept_frames;
    fps += d.false_positives;
    int fp_instances = 0;
    for (size_t i = 0; i < d.mask.instances.size(); ++i) {
      if (!d.instance_gt_ids[i].empty()) continue;
      ++fp_instances;
      const InstanceInfo& info = d.mask.instances[i];
      EXPECT_EQ(info.label, "person");
      EXPECT_GE(info.score, o.false_positive_score_min);
      EXPECT_LE(info.score, o.false_positive_score_max);
      EXPECT_EQ(cv::countNonZero((d.mask.ids == info.id) & (gt.ids != 0)), 0)
          << "false positive on a person";
    }
    EXPECT_EQ(fp_instances, d.false_positives);
  }
  ExpectBinomial(dropped, trials, 0.2, "dropped frames");
  // Poisson: mean within 4 standard errors.
  EXPECT_NEAR(static_cast<double>(fps) / kept_frames, 0.5, 4 * std::sqrt(0.5 / kept_frames));
}

TEST(DegradeMaskTest, RejectsBadInput) {
  const GtImages gt = ThreePeople();
  const MaskDegradeOptions o;
  cv::Mat ids8;
  gt.ids.convertTo(ids8, CV_8U);
  EXPECT_THROW(DegradeInstanceMask(ids8, gt.parts, o, 0), Error);
  EXPECT_THROW(DegradeInstanceMask(cv::Mat(), gt.parts, o, 0), Error);
  EXPECT_THROW(DegradeInstanceMask(gt.ids, gt.parts(cv::Rect(0, 0, 100, 100)), o, 0), Error);
  cv::Mat parts16;
  gt.parts.convertTo(parts16, CV_16U);
  EXPECT_THROW(DegradeInstanceMask(gt.ids, parts16, o, 0), Error);
  cv::Mat bad_parts = gt.parts.clone();
  bad_parts.at<uint8_t>(0, 0) = 200;
  EXPECT_THROW(DegradeInstanceMask(gt.ids, bad_parts, o, 0), Error);
  MaskDegradeOptions bad = o;
  bad.boundary_amplitude_px = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(DegradeInstanceMask(gt.ids, gt.parts, bad, 0), Error);
  bad = o;
  bad.merge_prob = 1.5;
  EXPECT_THROW(bad.Check(), Error);
  bad = o;
  bad.false_positive_min_radius_px = 40;
  EXPECT_THROW(bad.Check(), Error);
  for (const MaskDegradeOptions& preset :
       {MaskDegradeOptions::None(), MaskDegradeOptions::Mild(), MaskDegradeOptions::Default(),
        MaskDegradeOptions::Harsh()})
    EXPECT_NO_THROW(preset.Check());
}

// ------------------------------------------------------------ keypoints

Camera TestCamera() {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.K << 500, 0, 319.5, 0, 500, 239.5, 0, 0, 1;
  return c;  // world = camera frame
}

// A person facing the camera (its left on the image right) at depth z, with
// horizontal offset x0 (metres). `from_behind` mirrors it left/right.
std::array<Eigen::Vector3d, 17> Person(double x0, double z, bool from_behind = false) {
  const double s = from_behind ? -1 : 1;
  auto p = [&](double x, double y) { return Eigen::Vector3d(x0 + s * x, y, z); };
  return {p(0, -0.75),     p(0.04, -0.79), p(-0.04, -0.79), p(0.08, -0.77),  p(-0.08, -0.77),
          p(0.2, -0.55),   p(-0.2, -0.55), p(0.28, -0.28),  p(-0.28, -0.28), p(0.33, -0.02),
          p(-0.33, -0.02), p(0.12, 0.0),   p(-0.12, 0.0),   p(0.13, 0.42),   p(-0.13, 0.42),
          p(0.14, 0.82),   p(-0.14, 0.82)};
}

TEST(DegradeKeypointsTest, NoneGivesExactProjections) {
  const Camera cam = TestCamera();
  const cv::Mat ids(480, 640, CV_16UC1, cv::Scalar(0));
  const auto front = Person(0, 4);
  auto behind_camera = Person(0, -3);
  auto half_out = Person(2.4, 4);  // right of the image: some keypoints outside
  const auto dets = DegradeKeypoints({front, behind_camera, half_out}, cam, ids,
                                     KeypointDegradeOptions::None(), 1);
  ASSERT_EQ(dets.size(), 2u);
  for (const DetectedPose2d& d : dets) {
    EXPECT_FALSE(d.swapped);
    ASSERT_NE(d.gt_person, 1);
    const auto& truth = d.gt_person == 0 ? front : half_out;
    for (int k = 0; k < 17; ++k) {
      const Eigen::Vector2d px = cam.Project(truth[k]);
      if (cam.InImage(px)) {
        EXPECT_NEAR((d.keypoints[k].head<2>() - px).norm(), 0, 1e-9);
        EXPECT_EQ(d.keypoints[k].z(), 1.0);
      } else {
        EXPECT_EQ(d.keypoints[k], Eigen::Vector3d::Zero());
      }
    }
  }
  EXPECT_EQ(dets[0].gt_person, 0);  // sorted by score: the complete person first
  EXPECT_EQ(dets[0].score, 1.0);
  EXPECT_LT(dets[1].score, 1.0);
}

TEST(DegradeKeypointsTest, NoiseMissAndSwapRates) {
  const Camera cam = TestCamera();
  const cv::Mat ids(480, 640, CV_16UC1, cv::Scalar(0));
  const auto person = Person(0, 4);
  KeypointDegradeOptions o = KeypointDegradeOptions::None();
  o.noise_sigma_px = 2.0;
  o.keypoint_miss_prob = 0.1;
  o.swap_prob = 0.25;
  o.person_miss_prob = 0.1;
  const int trials = 1000;
  int people = 0, swaps = 0, missed = 0, detected = 0;
  double sum = 0, sum2 = 0;
  for (int seed = 0; seed < trials; ++seed) {
    const auto dets = DegradeKeypoints({person}, cam, ids, o, seed);
    if (dets.empty()) continue;
    ++people;
    swaps += dets[0].swapped;
    for (int k = 0; k < 17; ++k) {
      const Eigen::Vector3d& kp = dets[0].keypoints[k];
      if (kp.z() == 0) {
        ++missed;
        continue;
      }
      ++detected;
      // Swapped: label k holds the mirror keypoint.
      const int source = dets[0].swapped ? Coco17Mirror(k) : k;
      const Eigen::Vector2d err = kp.head<2>() - cam.Project(person[source]);
      sum += err.x() + err.y();
      sum2 += err.squaredNorm();
    }
  }
  ExpectBinomial(trials - people, trials, 0.1, "missed people");
  ExpectBinomial(swaps, people, 0.25, "left/right swaps");
  ExpectBinomial(missed, 17 * people, 0.1, "missed keypoints");
  const int n = 2 * detected;
  const double stddev = std::sqrt(sum2 / n - (sum / n) * (sum / n));
  std::printf("keypoint noise: empirical std %.3f px (sigma 2), %d samples\n", stddev, n);
  EXPECT_NEAR(stddev, 2.0, 0.2);
  EXPECT_NEAR(sum / n, 0.0, 0.05);
}

TEST(DegradeKeypointsTest, SwapsMoreOftenFromBehind) {
  const Camera cam = TestCamera();
  const cv::Mat ids(480, 640, CV_16UC1, cv::Scalar(0));
  KeypointDegradeOptions o = KeypointDegradeOptions::None();
  o.swap_prob = 0.0;
  o.swap_prob_from_behind = 0.4;
  int front_swaps = 0, back_swaps = 0;
  const int trials = 500;
  for (int seed = 0; seed < trials; ++seed) {
    const auto dets =
        DegradeKeypoints({Person(-1, 5), Person(1, 5, /*from_behind=*/true)}, cam, ids, o, seed);
    ASSERT_EQ(dets.size(), 2u);
    for (const DetectedPose2d& d : dets) (d.gt_person == 0 ? front_swaps : back_swaps) += d.swapped;
  }
  EXPECT_EQ(front_swaps, 0);
  ExpectBinomial(back_swaps, trials, 0.4, "swaps seen from behind");
}

TEST(DegradeKeypointsTest, OccludedKeypointsMissedOrLowConfidence) {
  const Camera cam = TestCamera();
  const auto person = Person(0, 4);
  // Person 1's silhouette: its bounding box; person 2 stands in front of its
  // image-right half below the shoulders (its left elbow, wrist, hip, knee, ankle).
  cv::Mat ids(480, 640, CV_16UC1, cv::Scalar(0));
  cv::rectangle(ids, cv::Rect(230, 40, 180, 410), cv::Scalar(1), cv::FILLED);
  cv::rectangle(ids, cv::Rect(322, 190, 100, 270), cv::Scalar(2), cv::FILLED);
  std::set<int> occluded;
  for (int k = 0; k < 17; ++k) {
    const Eigen::Vector2d px = cam.Project(person[k]);
    if (ids.at<uint16_t>(static_cast<int>(std::lround(px.y())),
                         static_cast<int>(std::lround(px.x()))) == 2)
      occluded.insert(k);
  }
  ASSERT_EQ(occluded, (std::set<int>{coco17::kLeftElbow, coco17::kLeftWrist, coco17::kLeftHip,
                                     coco17::kLeftKnee, coco17::kLeftAnkle}));
  KeypointDegradeOptions o = KeypointDegradeOptions::None();
  o.occluded_miss_prob = 1;
  for (int seed = 0; seed < 5; ++seed) {
    const auto dets = DegradeKeypoints({person}, cam, ids, o, seed);
    ASSERT_EQ(dets.size(), 1u);
    for (int k = 0; k < 17; ++k)
      EXPECT_EQ(dets[0].keypoints[k].z() == 0, occluded.count(k) == 1) << "keypoint " << k;
  }
  o = KeypointDegradeOptions::Default();
  o.keypoint_miss_prob = 0;
  o.person_miss_prob = 0;
  o.outlier_prob = 0;
  o.swap_prob = 0;
  o.occluded_miss_prob = 0.5;
  double occ_conf = 0, vis_conf = 0;
  int occ_n = 0, vis_n = 0, occ_missed = 0;
  for (int seed = 0; seed < 200; ++seed) {
    const auto dets = DegradeKeypoints({person}, cam, ids, o, seed);
    ASSERT_EQ(dets.size(), 1u);
    for (int k = 0; k < 17; ++k) {
      const double c = dets[0].keypoints[k].z();
      if (occluded.count(k)) {
        if (c == 0)
          ++occ_missed;
        else
          occ_conf += c, ++occ_n;
      } else {
        ASSERT_GT(c, 0);
        vis_conf += c, ++vis_n;
      }
    }
  }
  ExpectBinomial(occ_missed, 200 * 5, 0.5, "occluded keypoints missed");
  EXPECT_NEAR(occ_conf / occ_n, o.occluded_confidence_scale * vis_conf / vis_n, 0.03);
}

TEST(DegradeKeypointsTest, DeterministicPerSeed) {
  const Camera cam = TestCamera();
  const cv::Mat ids(480, 640, CV_16UC1, cv::Scalar(0));
  const std::vector<std::array<Eigen::Vector3d, 17>> people = {Person(-0.8, 4), Person(0.8, 5)};
  const KeypointDegradeOptions o = KeypointDegradeOptions::Harsh();
  auto same = [](const std::vector<DetectedPose2d>& a, const std::vector<DetectedPose2d>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i) {
      if (a[i].gt_person != b[i].gt_person || a[i].swapped != b[i].swapped) return false;
      for (int k = 0; k < 17; ++k)
        if (a[i].keypoints[k] != b[i].keypoints[k]) return false;
    }
    return true;
  };
  EXPECT_TRUE(
      same(DegradeKeypoints(people, cam, ids, o, 3), DegradeKeypoints(people, cam, ids, o, 3)));
  EXPECT_FALSE(
      same(DegradeKeypoints(people, cam, ids, o, 3), DegradeKeypoints(people, cam, ids, o, 4)));
}

TEST(DegradeKeypointsTest, RejectsBadInput) {
  const Camera cam = TestCamera();
  const cv::Mat ids(480, 640, CV_16UC1, cv::Scalar(0));
  const KeypointDegradeOptions o;
  EXPECT_THROW(DegradeKeypoints({Person(0, 4)}, cam, cv::Mat(480, 639, CV_16UC1), o, 0), Error);
  EXPECT_THROW(DegradeKeypoints({Person(0, 4)}, cam, cv::Mat(480, 640, CV_8UC1), o, 0), Error);
  auto nan_person = Person(0, 4);
  nan_person[3].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(DegradeKeypoints({nan_person}, cam, ids, o, 0), Error);
  KeypointDegradeOptions bad = o;
  bad.noise_sigma_px = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(DegradeKeypoints({Person(0, 4)}, cam, ids, bad, 0), Error);
  bad = o;
  bad.swap_prob = -0.1;
  EXPECT_THROW(bad.Check(), Error);
  Camera bad_cam = cam;
  bad_cam.K(0, 0) = -1;
  EXPECT_THROW(DegradeKeypoints({Person(0, 4)}, bad_cam, ids, o, 0), Error);
  EXPECT_EQ(Coco17Mirror(coco17::kLeftAnkle), coco17::kRightAnkle);
  EXPECT_EQ(Coco17Mirror(coco17::kRightEye), coco17::kLeftEye);
  EXPECT_EQ(Coco17Mirror(coco17::kNose), coco17::kNose);
}

}  // namespace
}  // namespace u4d::synth
