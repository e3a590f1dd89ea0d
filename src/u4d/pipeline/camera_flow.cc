#include "u4d/pipeline/camera_flow.h"

#include <algorithm>
#include <set>
#include <vector>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "u4d/baselines/dense_flow.h"
#include "u4d/io/label_ids.h"
#include "u4d/util/check.h"

namespace u4d {

namespace {

// |I_t1(p + f(p)) − I_t(p)| summed over the channels, then over the window,
// for the pixels of `roi` (`flow` holds the roi's flow; `t_roi` is I_t in
// the roi and `t1` the whole I_t1, so a match leaving the roi is still
// measured; both CV_32FC3).
cv::Mat WindowError(const cv::Mat& t_roi, const cv::Mat& t1, const cv::Rect& roi,
                    const cv::Mat& flow, int window_px) {
  cv::Mat map(flow.size(), CV_32FC2);
  for (int y = 0; y < flow.rows; ++y)
    for (int x = 0; x < flow.cols; ++x) {
      const cv::Vec2f f = flow.at<cv::Vec2f>(y, x);
      map.at<cv::Vec2f>(y, x) = cv::Vec2f(roi.x + x + f[0], roi.y + y + f[1]);
    }
  cv::Mat warped, diff, summed, window;
  cv::remap(t1, warped, map, cv::Mat(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  cv::absdiff(warped, t_roi, diff);
  cv::transform(diff, summed, cv::Matx13f(1, 1, 1));
  cv::boxFilter(summed, window, CV_32F, cv::Size(window_px, window_px));
  return window;
}

// The objects' bounding box grown by `margin` on every side, inside the image.
cv::Rect ObjectBox(const cv::Mat& labels, int margin) {
  const cv::Rect box = cv::boundingRect(labels > 0);
  const cv::Rect grown(box.x - margin, box.y - margin, box.width + 2 * margin,
                       box.height + 2 * margin);
  return grown & cv::Rect(0, 0, labels.cols, labels.rows);
}

// OpenCV's DIS needs an image side of at least 12 pixels; the crop's
// margin is at least this, and a smaller image is not matched.
constexpr int kMinMatchSide = 16;

// `grey` with every pixel outside `keep` set to mid-grey.
cv::Mat OnlyObject(const cv::Mat& grey, const cv::Mat& keep) {
  cv::Mat out(grey.size(), CV_8U, cv::Scalar(128));
  grey.copyTo(out, keep);
  return out;
}

// Object `id`'s own pair of images (camera_flow.h): the crop around it at t
// and t+1, and the grey images there with every pixel outside it set to
// mid-grey.
struct ObjectPair {
  cv::Rect crop;
  cv::Mat grey_t, grey_t1;
};

// False where `id` is absent from `labels_t1`.
bool OwnPair(const cv::Mat& labels, const cv::Mat& labels_t1, const cv::Mat& grey_t,
             const cv::Mat& grey_t1, int id, ObjectPair* pair) {
  const cv::Mat grow = cv::getStructuringElement(
      cv::MORPH_ELLIPSE, cv::Size(2 * kObjectMatchMarginPx + 1, 2 * kObjectMatchMarginPx + 1));
  cv::Mat at_t, at_t1;
  cv::dilate(labels == id, at_t, grow);
  cv::dilate(labels_t1 == id, at_t1, grow);
  if (cv::countNonZero(at_t1) == 0) return false;
  const cv::Mat both_frames = at_t | at_t1;
  pair->crop = ObjectBox(both_frames, cv::boundingRect(both_frames).width / 5 + kMinMatchSide);
  pair->grey_t = OnlyObject(grey_t(pair->crop), at_t(pair->crop));
  pair->grey_t1 = OnlyObject(grey_t1(pair->crop), at_t1(pair->crop));
  return true;
}

cv::Mat Grey(const cv::Mat& bgr) {
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

// Each object's own dense match (see the header) at its pixels of the roi;
// elsewhere `solved`. `own` (CV_8U, the roi's size) marks the pixels that
// have one.
cv::Mat ObjectMatches(const cv::Mat& labels, const cv::Mat& labels_t1, const cv::Mat& grey_t,
                      const cv::Mat& grey_t1, const cv::Rect& roi, const cv::Mat& solved,
                      cv::Mat* own) {
  cv::Mat field = solved.clone();
  *own = cv::Mat::zeros(roi.size(), CV_8U);
  for (const int id : IdsIn(labels)) {
    ObjectPair pair;
    if (!OwnPair(labels, labels_t1, grey_t, grey_t1, id, &pair)) continue;
    const cv::Mat match =
        baselines::DenseFlow(baselines::DenseFlowMethod::kDisFine, pair.grey_t, pair.grey_t1);
    const cv::Rect both = pair.crop & roi;
    const cv::Mat mine = labels(both) == id;
    match(both - pair.crop.tl()).copyTo(field(both - roi.tl()), mine);
    (*own)(both - roi.tl()).setTo(255, mine);
  }
  return field;
}

// `flow` where `mine` (CV_8U) is set; elsewhere the flow of the nearest
// pixel of `mine`, which must not be empty.
cv::Mat ExtendedFlow(const cv::Mat& mine, const cv::Mat& flow) {
  cv::Mat distance, nearest;
  cv::distanceTransform(mine == 0, distance, nearest, cv::DIST_L2, cv::DIST_MASK_5,
                        cv::DIST_LABEL_PIXEL);
  std::vector<cv::Vec2f> by_label(mine.total() + 1);
  for (int y = 0; y < mine.rows; ++y)
    for (int x = 0; x < mine.cols; ++x)
      if (mine.at<uint8_t>(y, x)) by_label[nearest.at<int>(y, x)] = flow.at<cv::Vec2f>(y, x);
  cv::Mat extended(flow.size(), CV_32FC2);
  for (int y = 0; y < mine.rows; ++y)
    for (int x = 0; x < mine.cols; ++x)
      extended.at<cv::Vec2f>(y, x) = by_label[nearest.at<int>(y, x)];
  return extended;
}

// Throws unless the labels at t and t+1 (CV_16U), the BGR 8-bit images and
// the CV_32FC2 flow have one size; `what` names the caller.
void CheckTwoFrames(const char* what, const cv::Mat& labels, const cv::Mat& labels_t1,
                    const cv::Mat& image_t, const cv::Mat& image_t1, const cv::Mat& flow) {
  U4D_CHECK(labels.type() == CV_16U && labels_t1.type() == CV_16U && image_t.type() == CV_8UC3 &&
                image_t1.type() == CV_8UC3 && flow.type() == CV_32FC2,
            "{}: expected CV_16U labels, BGR images and a CV_32FC2 flow", what);
  U4D_CHECK(labels.size() == labels_t1.size() && labels.size() == image_t.size() &&
                labels.size() == image_t1.size() && labels.size() == flow.size(),
            "{}: the labels ({}x{}), images and flow must have one size", what, labels.cols,
            labels.rows);
}

// Whether pixel (x, y) moved by `motion` (rounded) lands inside the image on
// object `id`'s labels at t+1.
bool LandsOn(const cv::Mat& labels_t1, int x, int y, const cv::Vec2f& motion, uint16_t id) {
  const cv::Point q(cvRound(x + motion[0]), cvRound(y + motion[1]));
  return q.x >= 0 && q.y >= 0 && q.x < labels_t1.cols && q.y < labels_t1.rows &&
         labels_t1.at<uint16_t>(q) == id;
}

// The forward-backward check's verdict per object pixel (camera_flow.h).
enum Verdict : uint8_t { kNotJudged = 0, kConsistent = 1, kInconsistent = 2 };

// Sundaram, Brox and Keutzer's Eq. 5: the backward flow leads back.
bool LeadsBack(const cv::Vec2f& forward, const cv::Vec2f& backward) {
  const cv::Vec2f sum = forward + backward;
  return sum.dot(sum) <= 0.01f * (forward.dot(forward) + backward.dot(backward)) + 0.5f;
}

cv::Mat JudgeObjectFlow(const cv::Mat& labels, const cv::Mat& labels_t1, const cv::Mat& flow,
                        const cv::Mat& backward) {
  cv::Mat verdict(labels.size(), CV_8U, cv::Scalar(kNotJudged));
  tbb::parallel_for(0, labels.rows, [&](int y) {
    for (int x = 0; x < labels.cols; ++x) {
      const uint16_t id = labels.at<uint16_t>(y, x);
      if (id == 0) continue;
      const cv::Vec2f& f = flow.at<cv::Vec2f>(y, x);
      if (!LandsOn(labels_t1, x, y, f, id)) continue;
      const cv::Point q(cvRound(x + f[0]), cvRound(y + f[1]));
      verdict.at<uint8_t>(y, x) =
          LeadsBack(f, backward.at<cv::Vec2f>(q)) ? kConsistent : kInconsistent;
    }
  });
  return verdict;
}

// Fewest consistent pixels an affine fill is fitted to.
constexpr int kMinFillSupport = 20;

// The affine motion at p = (x, y) fitted to the consistent pixels of object
// `id` around it (camera_flow.h); false where too few are near.
bool AffineFill(const cv::Mat& labels, const cv::Mat& verdict, const cv::Mat& flow, int x, int y,
                int radius_px, cv::Vec2f* motion) {
  const uint16_t id = labels.at<uint16_t>(y, x);
  for (int r = radius_px; r <= 8 * radius_px; r *= 2) {
    cv::Matx33d normal = cv::Matx33d::zeros();
    cv::Vec3d rhs_x, rhs_y;
    int n = 0;
    for (int v = std::max(0, y - r); v <= std::min(labels.rows - 1, y + r); v += 2)
      for (int u = std::max(0, x - r); u <= std::min(labels.cols - 1, x + r); u += 2) {
        if (labels.at<uint16_t>(v, u) != id || verdict.at<uint8_t>(v, u) != kConsistent) continue;
        const cv::Vec3d row(1, u - x, v - y);
        const cv::Vec2f& m = flow.at<cv::Vec2f>(v, u);
        normal += row * row.t();
        rhs_x += row * m[0];
        rhs_y += row * m[1];
        ++n;
      }
    if (n < kMinFillSupport) continue;
    // Centred on p, the fit's value at p is its constant term.
    *motion = cv::Vec2f(static_cast<float>(normal.solve(rhs_x, cv::DECOMP_SVD)[0]),
                        static_cast<float>(normal.solve(rhs_y, cv::DECOMP_SVD)[0]));
    return true;
  }
  return false;
}

}  // namespace

void RefineFlowAtCameraSize(const cv::Mat& labels, const cv::Mat& image_t, const cv::Mat& image_t1,
                            int window_px, cv::Mat* flow, const cv::Mat& labels_t1,
                            const cv::Mat& carried) {
  U4D_CHECK(window_px > 0 && window_px % 2 == 1,
            "RefineFlowAtCameraSize: the window must be odd and positive, got {}", window_px);
  U4D_CHECK(labels.type() == CV_16U && image_t.type() == CV_8UC3 && image_t1.type() == CV_8UC3 &&
                flow->type() == CV_32FC2,
            "RefineFlowAtCameraSize: expected CV_16U labels, BGR images and a CV_32FC2 flow");
  U4D_CHECK(labels.size() == image_t.size() && labels.size() == image_t1.size() &&
                labels.size() == flow->size(),
            "RefineFlowAtCameraSize: the labels ({}x{}), images and flow must have one size",
            labels.cols, labels.rows);
  U4D_CHECK(labels_t1.empty() || (labels_t1.type() == CV_16U && labels_t1.size() == labels.size()),
            "RefineFlowAtCameraSize: the labels at t+1 must be CV_16U {}x{}", labels.cols,
            labels.rows);
  U4D_CHECK(carried.empty() || (carried.type() == CV_32FC2 && carried.size() == labels.size()),
            "RefineFlowAtCameraSize: the carried flow must be CV_32FC2 {}x{}", labels.cols,
            labels.rows);
  if (cv::countNonZero(labels) == 0) return;
  if (labels.cols < kMinMatchSide && labels.rows < kMinMatchSide) return;
  // The dense match is computed around the objects only: a margin of a
  // tenth of the width (at least the window) keeps the match's own border
  // effects and the objects' motion inside the crop.
  const cv::Rect roi = ObjectBox(labels, std::max({window_px, labels.cols / 10, kMinMatchSide}));
  const cv::Mat dense =
      baselines::DenseFlow(baselines::DenseFlowMethod::kDisFine, image_t(roi), image_t1(roi));
  cv::Mat t_roi, t1;
  image_t(roi).convertTo(t_roi, CV_32F);
  image_t1.convertTo(t1, CV_32F);
  cv::Mat solved = (*flow)(roi);
  cv::Mat best_error = WindowError(t_roi, t1, roi, solved, window_px);
  const cv::Mat objects = labels(roi) > 0;
  cv::Mat best = solved.clone();
  auto consider = [&](const cv::Mat& candidate, const cv::Mat& where) {
    const cv::Mat error = WindowError(t_roi, t1, roi, candidate, window_px);
    const cv::Mat take = (error < best_error) & where;
    candidate.copyTo(best, take);
    error.copyTo(best_error, take);
  };
  consider(dense, objects);
  if (!labels_t1.empty()) {
    cv::Mat own;
    const cv::Mat matches =
        ObjectMatches(labels, labels_t1, Grey(image_t), Grey(image_t1), roi, solved, &own);
    consider(matches, own & objects);
  }
  if (!carried.empty()) consider(carried(roi), objects);
  best.copyTo(solved, objects);
}

cv::Mat CarriedObjectFlow(const cv::Mat& labels_prev, const cv::Mat& flow_prev,
                          const cv::Mat& labels, const cv::Mat& flow) {
  U4D_CHECK(labels_prev.type() == CV_16U && labels.type() == CV_16U &&
                flow_prev.type() == CV_32FC2 && flow.type() == CV_32FC2,
            "CarriedObjectFlow: expected CV_16U labels and CV_32FC2 flows");
  U4D_CHECK(labels_prev.size() == labels.size() && flow_prev.size() == labels.size() &&
                flow.size() == labels.size(),
            "CarriedObjectFlow: the labels ({}x{}) and flows must have one size", labels.cols,
            labels.rows);
  cv::Mat sum = cv::Mat::zeros(labels.size(), CV_32FC2);
  cv::Mat count = cv::Mat::zeros(labels.size(), CV_32S);
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) {
      const uint16_t id = labels_prev.at<uint16_t>(y, x);
      const cv::Vec2f& f = flow_prev.at<cv::Vec2f>(y, x);
      if (id == 0 || !LandsOn(labels, x, y, f, id)) continue;
      const cv::Point q(cvRound(x + f[0]), cvRound(y + f[1]));
      sum.at<cv::Vec2f>(q) += f;
      ++count.at<int>(q);
    }
  cv::Mat carried = flow.clone();
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x)
      if (const int n = count.at<int>(y, x); n > 0)
        carried.at<cv::Vec2f>(y, x) = sum.at<cv::Vec2f>(y, x) / static_cast<float>(n);
  return carried;
}

void FillInconsistentObjectFlow(const cv::Mat& labels, const cv::Mat& labels_t1,
                                const cv::Mat& image_t, const cv::Mat& image_t1, int radius_px,
                                cv::Mat* flow) {
  U4D_CHECK(radius_px >= 1, "FillInconsistentObjectFlow: the radius must be >= 1, got {}",
            radius_px);
  if (labels_t1.empty()) return;
  CheckTwoFrames("FillInconsistentObjectFlow", labels, labels_t1, image_t, image_t1, *flow);
  if (cv::countNonZero(labels) == 0 || cv::countNonZero(labels_t1) == 0) return;
  if (labels.cols < kMinMatchSide && labels.rows < kMinMatchSide) return;
  const cv::Rect whole(0, 0, labels.cols, labels.rows);
  cv::Mat own;
  const cv::Mat backward = ObjectMatches(labels_t1, labels, Grey(image_t1), Grey(image_t), whole,
                                         cv::Mat::zeros(flow->size(), CV_32FC2), &own);
  const cv::Mat verdict = JudgeObjectFlow(labels, labels_t1, *flow, backward);
  const cv::Mat judged = flow->clone();
  tbb::parallel_for(0, labels.rows, [&](int y) {
    for (int x = 0; x < labels.cols; ++x) {
      cv::Vec2f fill;
      if (verdict.at<uint8_t>(y, x) != kInconsistent ||
          !AffineFill(labels, verdict, judged, x, y, radius_px, &fill))
        continue;
      if (LandsOn(labels_t1, x, y, fill, labels.at<uint16_t>(y, x)))
        flow->at<cv::Vec2f>(y, x) = fill;
    }
  });
}

void RefineObjectFlowVariationally(const cv::Mat& labels, const cv::Mat& labels_t1,
                                   const cv::Mat& image_t, const cv::Mat& image_t1, int iterations,
                                   cv::Mat* flow) {
  U4D_CHECK(iterations >= 1, "RefineObjectFlowVariationally: the iterations must be >= 1, got {}",
            iterations);
  if (labels_t1.empty()) return;
  CheckTwoFrames("RefineObjectFlowVariationally", labels, labels_t1, image_t, image_t1, *flow);
  const cv::Mat grey_t = Grey(image_t), grey_t1 = Grey(image_t1);
  for (const int id : IdsIn(labels)) {
    ObjectPair pair;
    if (!OwnPair(labels, labels_t1, grey_t, grey_t1, id, &pair)) continue;
    const cv::Mat mine = labels(pair.crop) == id;
    cv::Mat field = ExtendedFlow(mine, (*flow)(pair.crop));
    const cv::Ptr<cv::VariationalRefinement> refine = cv::VariationalRefinement::create();
    refine->setFixedPointIterations(iterations);
    refine->calc(pair.grey_t, pair.grey_t1, field);
    field.copyTo((*flow)(pair.crop), mine);
  }
}

void MedianFilterObjectFlow(const cv::Mat& labels, int window_px, cv::Mat* flow) {
  U4D_CHECK(window_px > 0 && window_px % 2 == 1,
            "MedianFilterObjectFlow: the window must be odd and positive, got {}", window_px);
  U4D_CHECK(labels.type() == CV_16U && flow->type() == CV_32FC2 && labels.size() == flow->size(),
            "MedianFilterObjectFlow: expected CV_16U labels and a CV_32FC2 flow of one size");
  const cv::Mat in = flow->clone();
  const int r = window_px / 2;
  tbb::parallel_for(0, labels.rows, [&](int y) {
    std::vector<float> xs, ys;
    for (int x = 0; x < labels.cols; ++x) {
      const uint16_t id = labels.at<uint16_t>(y, x);
      if (id == 0) continue;
      xs.clear();
      ys.clear();
      for (int v = std::max(0, y - r); v <= std::min(labels.rows - 1, y + r); ++v)
        for (int u = std::max(0, x - r); u <= std::min(labels.cols - 1, x + r); ++u) {
          if (labels.at<uint16_t>(v, u) != id) continue;
          const cv::Vec2f& f = in.at<cv::Vec2f>(v, u);
          xs.push_back(f[0]);
          ys.push_back(f[1]);
        }
      const auto mid = static_cast<std::ptrdiff_t>(xs.size() / 2);
      std::nth_element(xs.begin(), xs.begin() + mid, xs.end());
      std::nth_element(ys.begin(), ys.begin() + mid, ys.end());
      flow->at<cv::Vec2f>(y, x) = cv::Vec2f(xs[mid], ys[mid]);
    }
  });
}

}  // namespace u4d
