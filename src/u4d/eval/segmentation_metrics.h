// Instance-segmentation metrics (paper Section 4, "IoU" tables).
//
// Inputs are label images (CV_16UC1, 0 = background) with the class of every
// id (io/instance_mask.h). Per image:
//  - the IoU matrix between visible GT instances (rows) and visible predicted
//    instances (columns); an instance listed but with no pixel is ignored;
//  - an optimal one-to-one matching maximising the total IoU (Hungarian),
//    restricted to pairs of the same class and with IoU > 0;
//  - per-GT-instance IoU (an unmatched GT instance scores 0);
//  - per-class pixel overlap: intersection and union of the union of all
//    instances of a class (instance identity ignored), and of the foreground;
//  - counts: missed GT (no match with IoU >= match_iou), false positives
//    (predicted with no match with IoU >= match_iou), merges (a predicted
//    instance covering > coverage of each of >= 2 GT instances, coverage =
//    |P n G| / |G|) and splits (a GT instance covering > coverage of each of
//    >= 2 predicted instances, coverage = |P n G| / |P|);
//  - objects merged with a person: GT instances of a class other than
//    "person" covered > coverage by a predicted instance that also covers
//    > coverage of a GT person (a person and the box they hold as one);
//  - the pairs of GT instances that touch in the image (come within
//    touch_distance_px); an image where people touch and one prediction
//    covers two of them counts towards the merge rate where people touch.
// Averages over many images (InstanceSegAccumulator) are instance-weighted for
// the mean instance IoU and pixel-pooled (sum of intersections over sum of
// unions) for the class IoU; docs/metrics.md gives the formulas.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "u4d/io/instance_mask.h"

namespace u4d::eval {

struct InstanceSegOptions {
  // A matched pair with IoU below this does not count as a detection when
  // counting missed and false-positive instances (its IoU still counts).
  double match_iou = 0.5;
  // Share of an instance that another must cover to count a merge or a split.
  double coverage = 0.5;
  // Match only instances of the same class.
  bool match_within_class = true;
  // Two GT instances touch when a pixel of one lies within this many pixels
  // (Chebyshev distance) of a pixel of the other.
  int touch_distance_px = 3;
  void Check() const;
};

// Pixel counts of an overlap, summable over images.
struct Overlap {
  int64_t intersection = 0;
  int64_t union_ = 0;
  double IoU() const;  // NaN when the union is empty
  void Add(const Overlap& o) {
    intersection += o.intersection;
    union_ += o.union_;
  }
};

struct InstanceMatch {
  int gt_id = 0;
  int pred_id = 0;  // 0 when unmatched
  std::string label;
  int64_t gt_area = 0;
  double iou = 0;  // 0 when unmatched
};

struct InstanceSegResult {
  std::vector<int> gt_ids;             // visible GT instances, rows of `iou`
  std::vector<int> pred_ids;           // visible predicted instances, columns of `iou`
  Eigen::MatrixXd iou;                 // gt x pred
  std::vector<InstanceMatch> matches;  // one per visible GT instance, in gt_ids order
  double mean_instance_iou = 0;        // NaN when no GT instance is visible
  int num_gt = 0, num_pred = 0;
  int missed = 0, false_positives = 0, merged = 0, split = 0;
  int objects = 0, objects_merged_with_person = 0;  // visible GT instances not of class person
  std::vector<std::pair<int, int>> touching_pairs;  // GT ids (a < b) that touch in the image
  // Whether people touch here: any touching pair, unless the caller restricts
  // it to the pairs in 3D contact (EvaluateCapture with gt/contacts.json).
  bool touching = false;
  std::map<std::string, Overlap> per_class;  // classes present in GT or prediction
  Overlap foreground;                        // any instance vs any instance
};

// IoU of two binary masks (CV_8UC1, non-zero = set); NaN when both are empty.
// Throws naming `context` when the sizes or types differ.
double MaskIoU(const cv::Mat& a, const cv::Mat& b, const std::string& context = "MaskIoU");

// Evaluates one image. Throws u4d::Error naming `context` (usually the files)
// when the images differ in size or type, or an id in an image has no class.
InstanceSegResult EvaluateInstances(const InstanceMask& pred, const InstanceMask& gt,
                                    const InstanceSegOptions& options, const std::string& context);

// The GT instances of one class and the sum of their per-instance IoU (matched
// within the class when match_within_class).
struct ClassInstances {
  int gt_instances = 0;
  double sum_iou = 0;
  double MeanIoU() const;  // NaN when the class has no GT instance
};

// Sums over images. Mean instance IoU = sum of per-GT-instance IoU / number of
// GT instances (instance-weighted); class IoU = sum_i |P_c n G_c| / sum_i |P_c u G_c|;
// per class also the mean instance IoU of the GT instances of that class.
struct InstanceSegAccumulator {
  int num_images = 0;
  int num_gt = 0, num_pred = 0;
  int missed = 0, false_positives = 0, merged = 0, split = 0;
  int objects = 0, objects_merged_with_person = 0;
  // Images where GT instances touch, and those of them with a merge;
  // touch_in_contact: touching was restricted to pairs in 3D contact.
  int touching_images = 0, merged_touching_images = 0;
  bool touch_in_contact = false;
  double sum_instance_iou = 0;
  std::map<std::string, Overlap> per_class;
  std::map<std::string, ClassInstances> per_class_instances;  // by the GT instance's class
  Overlap foreground;

  void Add(const InstanceSegResult& r);
  double MeanInstanceIoU() const;  // NaN when no GT instance was seen
  // Mean over classes of the class IoU (classes with a non-empty union).
  double MeanClassIoU() const;
  // merged_touching_images / touching_images; NaN when nobody touched.
  double MergeRateWhereTouching() const;
  // objects_merged_with_person / objects; NaN without objects.
  double ObjectMergeRate() const;
  nlohmann::json ToJson() const;
};

}  // namespace u4d::eval
