#include "u4d/eval/segmentation_metrics.h"

#include <gtest/gtest.h>

#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

// A label image with rectangles [x0, x1) x [y0, y1) set to ids.
struct Rect {
  int id, x0, y0, x1, y1;
};
InstanceMask Labels(int w, int h, const std::vector<Rect>& rects,
                    const std::vector<InstanceInfo>& infos) {
  InstanceMask m{cv::Mat::zeros(h, w, CV_16UC1), infos};
  for (const Rect& r : rects) m.ids(cv::Rect(r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0)).setTo(r.id);
  return m;
}

TEST(Segmentation, IoUOfTwoRectangles) {
  // 10x10 vs the same shifted by 5 in x: intersection 50, union 150.
  const InstanceMask gt = Labels(20, 10, {{1, 0, 0, 10, 10}}, {{1, "person", 1}});
  const InstanceMask pred = Labels(20, 10, {{7, 5, 0, 15, 10}}, {{7, "person", 1}});
  const InstanceSegResult r = EvaluateInstances(pred, gt, {}, "test");
  ASSERT_EQ(r.iou.rows(), 1);
  ASSERT_EQ(r.iou.cols(), 1);
  EXPECT_NEAR(r.iou(0, 0), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.mean_instance_iou, 1.0 / 3.0, 1e-12);
  EXPECT_EQ(r.matches[0].pred_id, 7);
  EXPECT_EQ(r.missed, 1);  // IoU below 0.5
  EXPECT_EQ(r.false_positives, 1);
  EXPECT_NEAR(MaskIoU(gt.ids > 0, pred.ids > 0), 1.0 / 3.0, 1e-12);
}

TEST(Segmentation, MatchingIsOptimalWhereGreedyFails) {
  // One row: GT A = [0,10), B = [10,11); pred Q = [0,4), P = [5,11).
  // IoU(A,Q) = 4/10, IoU(A,P) = 5/11, IoU(B,P) = 1/6, IoU(B,Q) = 0.
  // Greedy takes A-P (0.4545) and leaves B unmatched; the optimum is
  // A-Q + B-P = 0.4 + 0.1667.
  const InstanceMask gt =
      Labels(12, 1, {{1, 0, 0, 10, 1}, {2, 10, 0, 11, 1}}, {{1, "person", 1}, {2, "person", 1}});
  const InstanceMask pred =
      Labels(12, 1, {{3, 0, 0, 4, 1}, {4, 5, 0, 11, 1}}, {{3, "person", 1}, {4, "person", 1}});
  const InstanceSegResult r = EvaluateInstances(pred, gt, {}, "test");
  ASSERT_EQ(r.matches.size(), 2u);
  EXPECT_EQ(r.matches[0].gt_id, 1);
  EXPECT_EQ(r.matches[0].pred_id, 3);
  EXPECT_NEAR(r.matches[0].iou, 0.4, 1e-12);
  EXPECT_EQ(r.matches[1].pred_id, 4);
  EXPECT_NEAR(r.matches[1].iou, 1.0 / 6.0, 1e-12);
  EXPECT_NEAR(r.mean_instance_iou, (0.4 + 1.0 / 6.0) / 2, 1e-12);
}

TEST(Segmentation, TouchingPeopleAndTheMergeRateWhereTheyTouch) {
  // A = [0,10) x [0,5); B starts 3 px (touching at distance 3) or 5 px (not)
  // to the right of A's last column; diagonal neighbours count (Chebyshev).
  const std::vector<InstanceInfo> infos = {{1, "person", 1}, {2, "person", 1}};
  const InstanceMask near = Labels(30, 10, {{1, 0, 0, 10, 5}, {2, 12, 5, 20, 10}}, infos);
  const InstanceMask far = Labels(30, 10, {{1, 0, 0, 10, 5}, {2, 14, 0, 20, 5}}, infos);
  EXPECT_TRUE(EvaluateInstances(near, near, {}, "test").touching);
  EXPECT_FALSE(EvaluateInstances(far, far, {}, "test").touching);
  InstanceSegOptions tight;
  tight.touch_distance_px = 2;
  EXPECT_FALSE(EvaluateInstances(near, near, tight, "test").touching);

  // One prediction covering both touching people: a merge where they touch.
  const InstanceMask merged = Labels(30, 10, {{9, 0, 0, 20, 10}}, {{9, "person", 1}});
  InstanceSegAccumulator acc;
  acc.Add(EvaluateInstances(merged, near, {}, "test"));  // touching, merged
  acc.Add(EvaluateInstances(near, near, {}, "test"));    // touching, kept apart
  acc.Add(EvaluateInstances(merged, far, {}, "test"));   // merged but not touching
  EXPECT_EQ(acc.touching_images, 2);
  EXPECT_EQ(acc.merged_touching_images, 1);
  EXPECT_DOUBLE_EQ(acc.MergeRateWhereTouching(), 0.5);
}

TEST(Segmentation, MergeCounting) {
  // P = [2,18) covers 8/10 of A = [0,10) and of B = [10,20): a merge.
  const InstanceMask gt =
      Labels(20, 5, {{1, 0, 0, 10, 5}, {2, 10, 0, 20, 5}}, {{1, "person", 1}, {2, "person", 1}});
  const InstanceMask pred = Labels(20, 5, {{5, 2, 0, 18, 5}}, {{5, "person", 1}});
  InstanceSegResult r = EvaluateInstances(pred, gt, {}, "test");
  EXPECT_EQ(r.merged, 1);
  EXPECT_EQ(r.split, 0);
  EXPECT_EQ(r.missed, 2);  // the match has IoU 8/18 < 0.5; the other GT is unmatched
  EXPECT_EQ(r.false_positives, 1);
  EXPECT_NEAR(r.mean_instance_iou, (8.0 / 18.0) / 2, 1e-12);
  // P = [6,14) covers 4/10 of each: no merge.
  r = EvaluateInstances(Labels(20, 5, {{5, 6, 0, 14, 5}}, {{5, "person", 1}}), gt, {}, "test");
  EXPECT_EQ(r.merged, 0);
  // The converse: two predictions inside one GT instance is a split.
  r = EvaluateInstances(gt, Labels(20, 5, {{9, 0, 0, 20, 5}}, {{9, "person", 1}}), {}, "test");
  EXPECT_EQ(r.split, 1);
}

// A person [0,10) holding a box [10,14), and a ball [16,20) alone.
TEST(Segmentation, ObjectsMergedWithAPerson) {
  const InstanceMask gt = Labels(20, 5, {{1, 0, 0, 10, 5}, {2, 10, 0, 14, 5}, {3, 16, 0, 20, 5}},
                                 {{1, "person", 1}, {2, "box", 1}, {3, "ball", 1}});
  // One prediction over person and box (whatever its class): the box is merged.
  InstanceSegResult r = EvaluateInstances(
      Labels(20, 5, {{7, 1, 0, 14, 5}, {8, 16, 0, 20, 5}}, {{7, "person", 1}, {8, "ball", 1}}), gt,
      {}, "test");
  EXPECT_EQ(r.objects, 2);
  EXPECT_EQ(r.objects_merged_with_person, 1);
  // Separate predictions: nothing merged, though the box's is a little large.
  r = EvaluateInstances(
      Labels(20, 5, {{7, 0, 0, 9, 5}, {8, 9, 0, 15, 5}}, {{7, "person", 1}, {8, "box", 1}}), gt, {},
      "test");
  EXPECT_EQ(r.objects, 2);
  EXPECT_EQ(r.objects_merged_with_person, 0);
  // The prediction covers the box and only 4/10 of the person: not merged.
  r = EvaluateInstances(Labels(20, 5, {{7, 6, 0, 14, 5}}, {{7, "box", 1}}), gt, {}, "test");
  EXPECT_EQ(r.objects_merged_with_person, 0);
  InstanceSegAccumulator acc;
  acc.Add(EvaluateInstances(gt, gt, {}, "test"));
  acc.Add(EvaluateInstances(Labels(20, 5, {{7, 0, 0, 20, 5}}, {{7, "person", 1}}), gt, {}, "test"));
  EXPECT_EQ(acc.objects, 4);
  EXPECT_EQ(acc.objects_merged_with_person, 2);  // the second image merges both
  EXPECT_DOUBLE_EQ(acc.ObjectMergeRate(), 0.5);
  EXPECT_EQ(acc.ToJson()["objects_merged_with_person"], 2);
}

TEST(Segmentation, PerClassIoUAndClassConstraint) {
  // GT: person [0,10), car [10,20); pred: person [0,15), car [15,20).
  // person: inter 10, union 15; car: inter 5, union 10; foreground 20 / 20.
  const InstanceMask gt =
      Labels(20, 2, {{1, 0, 0, 10, 2}, {2, 10, 0, 20, 2}}, {{1, "person", 1}, {2, "car", 1}});
  const InstanceMask pred =
      Labels(20, 2, {{3, 0, 0, 15, 2}, {4, 15, 0, 20, 2}}, {{3, "person", 1}, {4, "car", 1}});
  const InstanceSegResult r = EvaluateInstances(pred, gt, {}, "test");
  EXPECT_NEAR(r.per_class.at("person").IoU(), 10.0 / 15.0, 1e-12);
  EXPECT_NEAR(r.per_class.at("car").IoU(), 0.5, 1e-12);
  EXPECT_NEAR(r.foreground.IoU(), 1.0, 1e-12);
  InstanceSegAccumulator acc;
  acc.Add(r);
  acc.Add(r);
  EXPECT_NEAR(acc.per_class.at("car").IoU(), 0.5, 1e-12);
  EXPECT_NEAR(acc.MeanClassIoU(), (10.0 / 15.0 + 0.5) / 2, 1e-12);
  EXPECT_EQ(acc.num_gt, 4);
  // With the class constraint the car prediction is never matched to the person.
  const InstanceMask car_only = Labels(20, 2, {{4, 0, 0, 10, 2}}, {{4, "car", 1}});
  const InstanceSegResult c = EvaluateInstances(car_only, gt, {}, "test");
  EXPECT_EQ(c.matches[0].pred_id, 0);
  EXPECT_EQ(c.matches[0].iou, 0.0);
}

// Per-class instance IoU on hand-made masks: two people and a box, in two
// images; in the second the box is predicted exactly but called a person, so
// it has no match within its class (IoU 0) while the people keep theirs.
TEST(Segmentation, PerClassInstanceIoUMatchesWithinTheClass) {
  const InstanceMask gt = Labels(20, 2, {{1, 0, 0, 6, 2}, {2, 6, 0, 12, 2}, {3, 12, 0, 20, 2}},
                                 {{1, "person", 1}, {2, "person", 1}, {3, "box", 1}});
  // Image A: person 1 exact (IoU 1), person 2 two thirds (4/6), box 12/16.
  const InstanceMask a = Labels(20, 2, {{5, 0, 0, 6, 2}, {6, 6, 0, 10, 2}, {7, 14, 0, 20, 2}},
                                {{5, "person", 1}, {6, "person", 1}, {7, "box", 1}});
  // Image B: both people exact, the box exact but labelled "person".
  const InstanceMask b = Labels(20, 2, {{5, 0, 0, 6, 2}, {6, 6, 0, 12, 2}, {7, 12, 0, 20, 2}},
                                {{5, "person", 1}, {6, "person", 1}, {7, "person", 1}});
  InstanceSegAccumulator acc;
  acc.Add(EvaluateInstances(a, gt, {}, "A"));
  acc.Add(EvaluateInstances(b, gt, {}, "B"));
  ASSERT_EQ(acc.per_class_instances.size(), 2u);
  EXPECT_EQ(acc.per_class_instances.at("person").gt_instances, 4);
  EXPECT_NEAR(acc.per_class_instances.at("person").MeanIoU(), (1 + 4.0 / 6 + 1 + 1) / 4, 1e-12);
  EXPECT_EQ(acc.per_class_instances.at("box").gt_instances, 2);
  EXPECT_NEAR(acc.per_class_instances.at("box").MeanIoU(), (12.0 / 16 + 0) / 2, 1e-12);
  EXPECT_NEAR(acc.MeanInstanceIoU(), (1 + 4.0 / 6 + 1 + 1 + 12.0 / 16 + 0) / 6, 1e-12);
  // eval.json keeps the pixel-pooled keys and adds the instance figures.
  const nlohmann::json box = acc.ToJson()["per_class"]["box"];
  EXPECT_NEAR(box["iou"].get<double>(), (12.0 + 0) / (16 + 16), 1e-12);
  EXPECT_EQ(box["intersection"].get<int64_t>(), 12);
  EXPECT_EQ(box["gt_instances"].get<int>(), 2);
  EXPECT_NEAR(box["mean_instance_iou"].get<double>(), 0.375, 1e-12);
  // Without the class constraint the mislabelled box in B matches exactly.
  InstanceSegOptions any_class;
  any_class.match_within_class = false;
  InstanceSegAccumulator loose;
  loose.Add(EvaluateInstances(b, gt, any_class, "B"));
  EXPECT_NEAR(loose.per_class_instances.at("box").MeanIoU(), 1.0, 1e-12);
}

TEST(Segmentation, BadInputsThrowNamingTheContext) {
  const InstanceMask a = Labels(20, 2, {{1, 0, 0, 10, 2}}, {{1, "person", 1}});
  const InstanceMask b = Labels(21, 2, {{1, 0, 0, 10, 2}}, {{1, "person", 1}});
  try {
    EvaluateInstances(a, b, {}, "pred.png vs gt.png");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("pred.png vs gt.png"), std::string::npos);
  }
  const InstanceMask no_class = Labels(20, 2, {{1, 0, 0, 10, 2}}, {});
  EXPECT_THROW(EvaluateInstances(no_class, a, {}, "x"), Error);
}

}  // namespace
}  // namespace u4d::eval
