// People instances from a foreground mask (init.h, step 4).
#include <algorithm>
#include <cmath>
#include <map>

#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

#include "u4d/init/init.h"
#include "u4d/init/init_internal.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

// Splits the pixels of `part` (CV_8UC1 0/255, one component) at the deepest
// valley of its column profile, recursively up to `depth` times. Appends the
// resulting parts to `out`.
void SplitByProfile(const cv::Mat& part, const InitOptions& options, int depth,
                    std::vector<cv::Mat>& out) {
  const cv::Rect bb = cv::boundingRect(part);
  if (depth <= 0 || bb.width < 8 || bb.height < 8) {
    out.push_back(part);
    return;
  }
  const cv::Mat roi = part(bb);
  std::vector<double> prof(bb.width, 0.0);
  for (int y = 0; y < roi.rows; ++y)
    for (int x = 0; x < roi.cols; ++x) prof[x] += roi.at<uint8_t>(y, x) ? 1.0 : 0.0;
  // Smooth over ~1/20 of the height (a hand or a gap between fingers is no valley).
  const int h = std::max(1, bb.height / 40);
  std::vector<double> sm(bb.width, 0.0), cum(bb.width + 1, 0.0);
  for (int x = 0; x < bb.width; ++x) cum[x + 1] = cum[x] + prof[x];
  for (int x = 0; x < bb.width; ++x) {
    const int a = std::max(0, x - h), b = std::min(bb.width - 1, x + h);
    sm[x] = (cum[b + 1] - cum[a]) / (b - a + 1);
  }
  std::vector<double> left_max(bb.width), right_max(bb.width);
  for (int x = 0; x < bb.width; ++x) left_max[x] = std::max(sm[x], x ? left_max[x - 1] : 0.0);
  for (int x = bb.width - 1; x >= 0; --x)
    right_max[x] = std::max(sm[x], x + 1 < bb.width ? right_max[x + 1] : 0.0);
  const double total = cum[bb.width];
  int best = -1;
  double best_ratio = options.people.profile_valley_ratio;
  for (int x = 1; x + 1 < bb.width; ++x) {
    const double peak = std::min(left_max[x - 1], right_max[x + 1]);
    if (peak <= 0) continue;
    const double ratio = sm[x] / peak;
    if (ratio >= best_ratio) continue;
    // Both sides must look like a person: a good share of the mass and tall.
    const double left = cum[x], right = total - cum[x + 1];
    if (std::min(left, right) < 0.15 * total) continue;
    best = x;
    best_ratio = ratio;
  }
  if (best < 0) {
    out.push_back(part);
    return;
  }
  cv::Mat a = cv::Mat::zeros(part.size(), CV_8UC1), b = a.clone();
  roi(cv::Rect(0, 0, best, bb.height)).copyTo(a(cv::Rect(bb.x, bb.y, best, bb.height)));
  roi(cv::Rect(best, 0, bb.width - best, bb.height))
      .copyTo(b(cv::Rect(bb.x + best, bb.y, bb.width - best, bb.height)));
  for (const cv::Mat* side : {&a, &b}) {
    const cv::Rect sb = cv::boundingRect(*side);
    if (sb.height < 0.5 * bb.height) {  // an arm or a bag, not a person: no split
      out.push_back(part);
      return;
    }
  }
  SplitByProfile(a, options, depth - 1, out);
  SplitByProfile(b, options, depth - 1, out);
}

// Refines instance `id` of `ids` with GrabCut, seeded from the mask.
void RefineWithGrabCut(const cv::Mat& image, cv::Mat& ids, int id, const InitOptions& options) {
  const cv::Mat inst = ids == id;
  cv::Rect bb = cv::boundingRect(inst);
  if (bb.area() == 0) return;
  const int pad = std::max(4, static_cast<int>(0.15 * std::max(bb.width, bb.height)));
  bb = cv::Rect(bb.x - pad, bb.y - pad, bb.width + 2 * pad, bb.height + 2 * pad) &
       cv::Rect(0, 0, image.cols, image.rows);
  const double s = std::min(
      1.0, static_cast<double>(options.people.grabcut_max_side) / std::max(bb.width, bb.height));
  const cv::Size sz(std::max(1, static_cast<int>(std::lround(bb.width * s))),
                    std::max(1, static_cast<int>(std::lround(bb.height * s))));
  cv::Mat img, m, others;
  cv::resize(image(bb), img, sz, 0, 0, cv::INTER_AREA);
  cv::resize(inst(bb), m, sz, 0, 0, cv::INTER_NEAREST);
  cv::resize((ids(bb) != 0) & (ids(bb) != id), others, sz, 0, 0, cv::INTER_NEAREST);
  const int r = std::max(1, static_cast<int>(0.03 * std::max(sz.width, sz.height)));
  const cv::Mat k = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  // Probable foreground: the convex hull of the instance's pixels (fills a
  // body whose still parts are in the background model between moving limbs).
  cv::Mat hull = m.clone();
  {
    std::vector<cv::Point> pts;
    cv::findNonZero(m, pts);
    if (pts.size() >= 3) {
      std::vector<cv::Point> h;
      cv::convexHull(pts, h);
      cv::fillConvexPoly(hull, h, cv::Scalar(255));
    }
  }
  cv::Mat eroded, dilated;
  cv::erode(m, eroded, k);
  cv::dilate(hull, dilated, k, cv::Point(-1, -1), 2);
  cv::Mat gc(sz, CV_8UC1, cv::Scalar(cv::GC_BGD));
  gc.setTo(cv::GC_PR_BGD, dilated);
  gc.setTo(cv::GC_PR_FGD, hull);
  gc.setTo(cv::GC_FGD, eroded);
  gc.setTo(cv::GC_BGD, others);
  if (cv::countNonZero(gc == cv::GC_BGD) == 0 || cv::countNonZero(eroded) == 0) return;
  cv::Mat bgd, fgd;
  const FixedGrabCutSeed seed;
  cv::grabCut(img, gc, cv::Rect(), bgd, fgd, options.people.grabcut_iterations,
              cv::GC_INIT_WITH_MASK);
  cv::Mat fg = (gc == cv::GC_FGD) | (gc == cv::GC_PR_FGD), up;
  cv::resize(fg, up, bb.size(), 0, 0, cv::INTER_NEAREST);
  cv::Mat roi = ids(bb);
  for (int y = 0; y < roi.rows; ++y) {
    uint16_t* p = roi.ptr<uint16_t>(y);
    const uint8_t* f = up.ptr<uint8_t>(y);
    for (int x = 0; x < roi.cols; ++x) {
      if (f[x] && p[x] == 0) p[x] = static_cast<uint16_t>(id);
      if (!f[x] && p[x] == id) p[x] = 0;
    }
  }
}

}  // namespace

std::vector<PersonBox> DetectPeople(const cv::Mat& image_bgr, const InitOptions& options) {
  options.Check();
  U4D_CHECK(!image_bgr.empty() && image_bgr.type() == CV_8UC3,
            "DetectPeople: expected a non-empty BGR image (CV_8UC3)");
  const double s = std::min(
      128.0 / options.people.min_person_height_px,
      static_cast<double>(options.people.hog_max_side) / std::max(image_bgr.cols, image_bgr.rows));
  cv::Mat img;
  cv::resize(image_bgr, img, cv::Size(), s, s, s < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  if (img.cols < 64 || img.rows < 128) return {};
  cv::HOGDescriptor hog;
  hog.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
  std::vector<cv::Rect> found;
  std::vector<double> weights;
  hog.detectMultiScale(img, found, weights, options.people.hog_threshold, cv::Size(8, 8),
                       cv::Size(16, 16), 1.05, 2.0);
  std::vector<PersonBox> out;
  for (size_t i = 0; i < found.size(); ++i) {
    const cv::Rect& r = found[i];
    // HOG boxes are ~ 1/8 wider and taller than the person; keep them as they are.
    PersonBox b;
    b.box = cv::Rect(static_cast<int>(std::lround(r.x / s)), static_cast<int>(std::lround(r.y / s)),
                     static_cast<int>(std::lround(r.width / s)),
                     static_cast<int>(std::lround(r.height / s))) &
            cv::Rect(0, 0, image_bgr.cols, image_bgr.rows);
    b.score = i < weights.size() ? weights[i] : 0.0;
    if (b.box.area() > 0) out.push_back(b);
  }
  return out;
}

PeopleOptions::BoxFill BoxFillFromString(const std::string& name) {
  if (name == "never") return PeopleOptions::BoxFill::kNever;
  if (name == "empty-views") return PeopleOptions::BoxFill::kEmptyViews;
  U4D_CHECK(name == "always", "unknown box fill '{}' (known: never, empty-views, always)", name);
  return PeopleOptions::BoxFill::kAlways;
}

bool FillsBoxes(const cv::Mat& foreground, const InitOptions& options) {
  using BoxFill = PeopleOptions::BoxFill;
  if (options.people.box_fill != BoxFill::kEmptyViews)
    return options.people.box_fill == BoxFill::kAlways;
  return cv::countNonZero(foreground) < options.people.min_instance_fraction * foreground.total();
}

cv::Mat AddDetectedPeople(const cv::Mat& image_bgr, const cv::Mat& foreground,
                          const std::vector<PersonBox>& boxes, const InitOptions& options) {
  options.Check();
  CheckImageAndForeground("AddDetectedPeople", image_bgr, foreground);
  cv::Mat out = foreground.clone();
  if (!FillsBoxes(foreground, options)) return out;
  const cv::Rect image_rect(0, 0, image_bgr.cols, image_bgr.rows);
  for (const PersonBox& b : boxes) {
    const double coverage = static_cast<double>(cv::countNonZero(foreground(b.box))) / b.box.area();
    if (coverage >= options.people.box_min_coverage) continue;
    // GrabCut in the box (plus a margin of background), at most grabcut_max_side.
    const int pad = std::max(4, b.box.width / 4);
    const cv::Rect roi =
        cv::Rect(b.box.x - pad, b.box.y - pad / 2, b.box.width + 2 * pad, b.box.height + pad) &
        image_rect;
    const double s = std::min(1.0, static_cast<double>(options.people.grabcut_max_side) /
                                       std::max(roi.width, roi.height));
    const cv::Size sz(std::max(1, static_cast<int>(std::lround(roi.width * s))),
                      std::max(1, static_cast<int>(std::lround(roi.height * s))));
    cv::Mat img, fg;
    cv::resize(image_bgr(roi), img, sz, 0, 0, cv::INTER_AREA);
    cv::resize(foreground(roi), fg, sz, 0, 0, cv::INTER_NEAREST);
    cv::Mat gc(sz, CV_8UC1, cv::Scalar(cv::GC_BGD));
    // Inside the box: probable background at the sides, probable foreground
    // in the central half (a HOG box is about twice as wide as the torso),
    // the existing foreground as probable foreground too.
    const cv::Rect box_s(static_cast<int>((b.box.x - roi.x) * s),
                         static_cast<int>((b.box.y - roi.y) * s), static_cast<int>(b.box.width * s),
                         static_cast<int>(b.box.height * s));
    gc(box_s & cv::Rect(0, 0, sz.width, sz.height)).setTo(cv::GC_PR_BGD);
    const cv::Rect centre(box_s.x + box_s.width / 4, box_s.y + box_s.height / 16, box_s.width / 2,
                          box_s.height * 7 / 8);
    gc(centre & cv::Rect(0, 0, sz.width, sz.height)).setTo(cv::GC_PR_FGD);
    gc.setTo(cv::GC_PR_FGD, fg);
    cv::Mat bgd, fgd;
    const FixedGrabCutSeed seed;
    cv::grabCut(img, gc, cv::Rect(), bgd, fgd, options.people.grabcut_box_iterations,
                cv::GC_INIT_WITH_MASK);
    cv::Mat res = (gc == cv::GC_FGD) | (gc == cv::GC_PR_FGD), up;
    cv::resize(res, up, roi.size(), 0, 0, cv::INTER_NEAREST);
    // Only inside the detector's box.
    cv::Mat inside = cv::Mat::zeros(roi.size(), CV_8UC1);
    inside(cv::Rect(b.box.x - roi.x, b.box.y - roi.y, b.box.width, b.box.height) &
           cv::Rect(0, 0, roi.width, roi.height))
        .setTo(255);
    cv::Mat o = out(roi);
    o |= up & inside;
  }
  return CleanMask(out, options);
}

cv::Mat SplitInstances(const cv::Mat& image_bgr, const cv::Mat& foreground,
                       const std::vector<PersonBox>& boxes, const InitOptions& options) {
  options.Check();
  CheckImageAndForeground("SplitInstances", image_bgr, foreground);
  // Components of the foreground dilated by group_radius: fragments of one
  // person (split by a belt, a shadow-suppressed stripe) stay together.
  cv::Mat labels;
  int n = 0;
  {
    const int r = options.people.group_radius_px > 0 ? options.people.group_radius_px
                                                     : std::max(1, foreground.rows / 100);
    cv::Mat grown;
    cv::dilate(foreground, grown,
               cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)));
    n = cv::connectedComponents(grown, labels, 8, CV_32S);
    labels.setTo(0, foreground == 0);
  }
  std::vector<int> area(n, 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) ++area[l[x]];
  }
  const double min_area = options.people.min_instance_fraction * foreground.total();

  // Boxes per component: a box belongs to the component with most pixels in
  // it, when those cover at least 15% of the box.
  std::vector<std::vector<PersonBox>> comp_boxes(n);
  for (const PersonBox& b : boxes) {
    std::map<int, int> count;
    const cv::Mat l = labels(b.box);
    for (int y = 0; y < l.rows; ++y)
      for (int x = 0; x < l.cols; ++x)
        if (const int c = l.at<int>(y, x); c > 0) ++count[c];
    int best = 0, best_count = 0;
    for (const auto& [c, k] : count)
      if (k > best_count) best = c, best_count = k;
    if (best > 0 && best_count >= 0.15 * b.box.area()) comp_boxes[best].push_back(b);
  }

  std::vector<cv::Mat> parts;
  for (int c = 1; c < n; ++c) {
    if (area[c] < min_area) continue;
    std::vector<PersonBox>& cb = comp_boxes[c];
    if (options.people.require_detection && cb.empty()) continue;
    const cv::Mat comp = labels == c;
    // Non-maximum suppression along x: boxes whose centres are closer than
    // half a box width are one person.
    std::sort(cb.begin(), cb.end(),
              [](const PersonBox& a, const PersonBox& b) { return a.score > b.score; });
    std::vector<PersonBox> kept;
    for (const PersonBox& b : cb) {
      bool dup = false;
      for (const PersonBox& k : kept) {
        const double cx = b.box.x + 0.5 * b.box.width, kx = k.box.x + 0.5 * k.box.width;
        if (std::abs(cx - kx) < 0.5 * std::min(b.box.width, k.box.width)) dup = true;
      }
      if (!dup) kept.push_back(b);
    }
    if (kept.size() >= 2) {
      std::vector<cv::Mat> split(kept.size());
      for (auto& m : split) m = cv::Mat::zeros(comp.size(), CV_8UC1);
      for (int y = 0; y < comp.rows; ++y) {
        const uint8_t* p = comp.ptr<uint8_t>(y);
        for (int x = 0; x < comp.cols; ++x) {
          if (!p[x]) continue;
          int best = -1;
          double best_d = 1e18;
          bool best_inside = false;
          for (size_t k = 0; k < kept.size(); ++k) {
            const bool inside = kept[k].box.contains(cv::Point(x, y));
            const double d = std::abs(x - (kept[k].box.x + 0.5 * kept[k].box.width));
            if ((inside && !best_inside) || (inside == best_inside && d < best_d)) {
              best = static_cast<int>(k), best_d = d, best_inside = inside;
            }
          }
          split[best].at<uint8_t>(y, x) = 255;
        }
      }
      for (auto& m : split)
        if (cv::countNonZero(m) >= min_area) parts.push_back(m);
    } else if (options.people.split_by_profile) {
      SplitByProfile(comp, options, 3, parts);
    } else {
      parts.push_back(comp);
    }
  }
  // Ids left to right by centroid.
  std::vector<std::pair<double, int>> order;
  for (size_t i = 0; i < parts.size(); ++i) {
    const cv::Moments mo = cv::moments(parts[i], true);
    if (mo.m00 < min_area) continue;
    order.emplace_back(mo.m10 / mo.m00, static_cast<int>(i));
  }
  std::sort(order.begin(), order.end());
  cv::Mat ids = cv::Mat::zeros(foreground.size(), CV_16UC1);
  for (size_t k = 0; k < order.size(); ++k)
    ids.setTo(static_cast<int>(k + 1), parts[order[k].second]);
  if (options.people.grabcut_iterations > 0) {
    for (size_t k = 0; k < order.size(); ++k)
      RefineWithGrabCut(image_bgr, ids, static_cast<int>(k + 1), options);
  }
  return ids;
}

}  // namespace u4d
