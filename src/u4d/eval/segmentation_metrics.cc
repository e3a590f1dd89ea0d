#include "u4d/eval/segmentation_metrics.h"

#include <cmath>
#include <limits>
#include <set>

#include "u4d/eval/hungarian.h"
#include "u4d/util/check.h"

namespace u4d::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void CheckLabelImage(const cv::Mat& ids, const char* which, const std::string& context) {
  U4D_CHECK(!ids.empty(), "{}: the {} label image is empty", context, which);
  U4D_CHECK(ids.type() == CV_16UC1, "{}: the {} label image must be CV_16UC1", context, which);
}

std::string LabelOf(const InstanceMask& mask, int id, const char* which,
                    const std::string& context) {
  const InstanceInfo* info = mask.Find(id);
  U4D_CHECK(info != nullptr, "{}: id {} in the {} label image has no class (no instance entry)",
            context, id, which);
  return info->label;
}

// Pairs (a < b) of different non-zero ids of `ids` within `distance` pixels.
std::vector<std::pair<int, int>> TouchingPairs(const cv::Mat& ids, int distance) {
  std::set<std::pair<int, int>> pairs;
  for (int y = 0; y < ids.rows; ++y) {
    const uint16_t* row = ids.ptr<uint16_t>(y);
    for (int x = 0; x < ids.cols; ++x) {
      if (row[x] == 0) continue;
      for (int dy = 0; dy <= distance && y + dy < ids.rows; ++dy) {
        const uint16_t* other = ids.ptr<uint16_t>(y + dy);
        for (int dx = -distance; dx <= distance; ++dx) {
          if (x + dx < 0 || x + dx >= ids.cols || (dy == 0 && dx <= 0)) continue;
          const int a = row[x], b = other[x + dx];
          if (b != 0 && b != a) pairs.emplace(std::min(a, b), std::max(a, b));
        }
      }
    }
  }
  return {pairs.begin(), pairs.end()};
}

// Counts the visible GT objects (class other than "person") and those a
// predicted instance covers together with a GT person (segmentation_metrics.h).
// grid[i + 1][j + 1]: pixels of GT row i and predicted column j.
void CountObjectsMergedWithPeople(const std::vector<std::vector<int64_t>>& grid,
                                  const std::vector<std::string>& gt_label,
                                  const std::vector<int64_t>& gt_area, double coverage,
                                  InstanceSegResult* r) {
  const int ng = static_cast<int>(gt_label.size());
  auto covers = [&](int i, size_t j) {
    return static_cast<double>(grid[i + 1][j]) > coverage * static_cast<double>(gt_area[i]);
  };
  for (int i = 0; i < ng; ++i) {
    if (gt_label[i] == "person") continue;
    ++r->objects;
    bool merged = false;
    for (size_t j = 1; j < grid[i + 1].size() && !merged; ++j) {
      if (!covers(i, j)) continue;
      for (int k = 0; k < ng && !merged; ++k) merged = gt_label[k] == "person" && covers(k, j);
    }
    r->objects_merged_with_person += merged ? 1 : 0;
  }
}

}  // namespace

void InstanceSegOptions::Check() const {
  U4D_CHECK(match_iou > 0 && match_iou <= 1, "InstanceSegOptions: match_iou must be in (0, 1]");
  U4D_CHECK(coverage > 0 && coverage < 1, "InstanceSegOptions: coverage must be in (0, 1)");
  U4D_CHECK(touch_distance_px >= 0, "InstanceSegOptions: touch_distance_px must be >= 0");
}

double Overlap::IoU() const {
  return union_ > 0 ? static_cast<double>(intersection) / static_cast<double>(union_) : kNaN;
}

double MaskIoU(const cv::Mat& a, const cv::Mat& b, const std::string& context) {
  U4D_CHECK(a.type() == CV_8UC1 && b.type() == CV_8UC1, "{}: masks must be CV_8UC1", context);
  U4D_CHECK(a.size() == b.size(), "{}: mask sizes differ ({}x{} vs {}x{})", context, a.cols, a.rows,
            b.cols, b.rows);
  const int64_t inter = cv::countNonZero(a & b);
  const int64_t uni = cv::countNonZero(a | b);
  return uni > 0 ? static_cast<double>(inter) / static_cast<double>(uni) : kNaN;
}

InstanceSegResult EvaluateInstances(const InstanceMask& pred, const InstanceMask& gt,
                                    const InstanceSegOptions& options, const std::string& context) {
  options.Check();
  CheckLabelImage(pred.ids, "predicted", context);
  CheckLabelImage(gt.ids, "ground-truth", context);
  U4D_CHECK(pred.ids.size() == gt.ids.size(),
            "{}: image sizes differ: prediction {}x{}, ground truth {}x{}", context, pred.ids.cols,
            pred.ids.rows, gt.ids.cols, gt.ids.rows);

  // Joint histogram of (gt id, pred id) over the pixels, ids densely indexed
  // in order of first appearance; index 0 is the background.
  InstanceSegResult r;
  std::vector<int> gt_lut(65536, 0), pred_lut(65536, 0);
  for (int y = 0; y < gt.ids.rows; ++y) {
    const uint16_t* g = gt.ids.ptr<uint16_t>(y);
    const uint16_t* p = pred.ids.ptr<uint16_t>(y);
    for (int x = 0; x < gt.ids.cols; ++x) {
      if (g[x] && !gt_lut[g[x]]) {
        r.gt_ids.push_back(g[x]);
        gt_lut[g[x]] = static_cast<int>(r.gt_ids.size());
      }
      if (p[x] && !pred_lut[p[x]]) {
        r.pred_ids.push_back(p[x]);
        pred_lut[p[x]] = static_cast<int>(r.pred_ids.size());
      }
    }
  }
  std::vector<std::vector<int64_t>> grid(r.gt_ids.size() + 1,
                                         std::vector<int64_t>(r.pred_ids.size() + 1, 0));
  for (int y = 0; y < gt.ids.rows; ++y) {
    const uint16_t* g = gt.ids.ptr<uint16_t>(y);
    const uint16_t* p = pred.ids.ptr<uint16_t>(y);
    for (int x = 0; x < gt.ids.cols; ++x) ++grid[gt_lut[g[x]]][pred_lut[p[x]]];
  }
  const int ng = static_cast<int>(r.gt_ids.size());
  const int np = static_cast<int>(r.pred_ids.size());
  r.num_gt = ng;
  r.num_pred = np;

  std::vector<std::string> gt_label(ng), pred_label(np);
  for (int i = 0; i < ng; ++i) gt_label[i] = LabelOf(gt, r.gt_ids[i], "ground-truth", context);
  for (int j = 0; j < np; ++j) pred_label[j] = LabelOf(pred, r.pred_ids[j], "predicted", context);

  std::vector<int64_t> gt_area(ng, 0), pred_area(np, 0);
  for (int i = 0; i <= ng; ++i)
    for (int j = 0; j <= np; ++j) {
      if (i > 0) gt_area[i - 1] += grid[i][j];
      if (j > 0) pred_area[j - 1] += grid[i][j];
    }

  r.iou = Eigen::MatrixXd::Zero(ng, np);
  Eigen::MatrixXd score = Eigen::MatrixXd::Zero(ng, np);
  for (int i = 0; i < ng; ++i)
    for (int j = 0; j < np; ++j) {
      const int64_t inter = grid[i + 1][j + 1];
      r.iou(i, j) =
          static_cast<double>(inter) / static_cast<double>(gt_area[i] + pred_area[j] - inter);
      const bool allowed = !options.match_within_class || gt_label[i] == pred_label[j];
      score(i, j) = allowed ? r.iou(i, j) : 0.0;
    }
  const std::vector<int> gt_to_pred = MaxScoreAssignment(score);

  std::vector<char> pred_detected(np, 0);
  double sum_iou = 0;
  for (int i = 0; i < ng; ++i) {
    InstanceMatch m;
    m.gt_id = r.gt_ids[i];
    m.label = gt_label[i];
    m.gt_area = gt_area[i];
    const int j = gt_to_pred[i];
    if (j >= 0 && score(i, j) > 0) {
      m.pred_id = r.pred_ids[j];
      m.iou = score(i, j);
      if (m.iou >= options.match_iou)
        pred_detected[j] = 1;
      else
        ++r.missed;
    } else {
      ++r.missed;
    }
    sum_iou += m.iou;
    r.matches.push_back(m);
  }
  for (int j = 0; j < np; ++j)
    if (!pred_detected[j]) ++r.false_positives;
  r.mean_instance_iou = ng > 0 ? sum_iou / ng : kNaN;

  for (int j = 0; j < np; ++j) {
    int covered = 0;
    for (int i = 0; i < ng; ++i)
      if (static_cast<double>(grid[i + 1][j + 1]) > options.coverage * gt_area[i]) ++covered;
    if (covered >= 2) ++r.merged;
  }
  CountObjectsMergedWithPeople(grid, gt_label, gt_area, options.coverage, &r);
  for (int i = 0; i < ng; ++i) {
    int covering = 0;
    for (int j = 0; j < np; ++j)
      if (static_cast<double>(grid[i + 1][j + 1]) > options.coverage * pred_area[j]) ++covering;
    if (covering >= 2) ++r.split;
  }

  r.touching_pairs = TouchingPairs(gt.ids, options.touch_distance_px);
  r.touching = !r.touching_pairs.empty();

  // Class and foreground overlap: |union of class c in GT n union in pred|.
  for (int i = 0; i <= ng; ++i)
    for (int j = 0; j <= np; ++j) {
      const int64_t n = grid[i][j];
      if (n == 0) continue;
      const std::string* gl = i > 0 ? &gt_label[i - 1] : nullptr;
      const std::string* pl = j > 0 ? &pred_label[j - 1] : nullptr;
      if (gl && pl && *gl == *pl) {
        r.per_class[*gl].intersection += n;
        r.per_class[*gl].union_ += n;
      } else {
        if (gl) r.per_class[*gl].union_ += n;
        if (pl) r.per_class[*pl].union_ += n;
      }
      if (gl || pl) r.foreground.union_ += n;
      if (gl && pl) r.foreground.intersection += n;
    }
  return r;
}

void InstanceSegAccumulator::Add(const InstanceSegResult& r) {
  ++num_images;
  touching_images += r.touching ? 1 : 0;
  merged_touching_images += r.touching && r.merged > 0 ? 1 : 0;
  num_gt += r.num_gt;
  num_pred += r.num_pred;
  missed += r.missed;
  false_positives += r.false_positives;
  merged += r.merged;
  split += r.split;
  objects += r.objects;
  objects_merged_with_person += r.objects_merged_with_person;
  for (const InstanceMatch& m : r.matches) {
    sum_instance_iou += m.iou;
    ClassInstances& c = per_class_instances[m.label];
    ++c.gt_instances;
    c.sum_iou += m.iou;
  }
  for (const auto& [label, o] : r.per_class) per_class[label].Add(o);
  foreground.Add(r.foreground);
}

double ClassInstances::MeanIoU() const { return gt_instances > 0 ? sum_iou / gt_instances : kNaN; }

double InstanceSegAccumulator::MeanInstanceIoU() const {
  return num_gt > 0 ? sum_instance_iou / num_gt : kNaN;
}

double InstanceSegAccumulator::MergeRateWhereTouching() const {
  return touching_images > 0 ? static_cast<double>(merged_touching_images) / touching_images : kNaN;
}

double InstanceSegAccumulator::ObjectMergeRate() const {
  return objects > 0 ? static_cast<double>(objects_merged_with_person) / objects : kNaN;
}

double InstanceSegAccumulator::MeanClassIoU() const {
  double sum = 0;
  int n = 0;
  for (const auto& [label, o] : per_class)
    if (o.union_ > 0) {
      sum += o.IoU();
      ++n;
    }
  return n > 0 ? sum / n : kNaN;
}

nlohmann::json InstanceSegAccumulator::ToJson() const {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json classes = nlohmann::json::object();
  for (const auto& [label, o] : per_class) {
    const auto it = per_class_instances.find(label);
    const ClassInstances inst = it == per_class_instances.end() ? ClassInstances{} : it->second;
    classes[label] = {{"iou", num(o.IoU())},
                      {"intersection", o.intersection},
                      {"union", o.union_},
                      {"gt_instances", inst.gt_instances},
                      {"mean_instance_iou", num(inst.MeanIoU())}};
  }
  return {{"images", num_images},
          {"gt_instances", num_gt},
          {"pred_instances", num_pred},
          {"mean_instance_iou", num(MeanInstanceIoU())},
          {"mean_class_iou", num(MeanClassIoU())},
          {"foreground_iou", num(foreground.IoU())},
          {"per_class", classes},
          {"missed", missed},
          {"false_positives", false_positives},
          {"merged", merged},
          {"split", split},
          {"touching_images", touching_images},
          {"merged_touching_images", merged_touching_images},
          {"merge_rate_where_touching", num(MergeRateWhereTouching())},
          {"objects", objects},
          {"objects_merged_with_person", objects_merged_with_person},
          {"object_merge_rate", num(ObjectMergeRate())},
          {"touch_rule", touch_in_contact ? "3d_contact" : "image_adjacency"}};
}

}  // namespace u4d::eval
