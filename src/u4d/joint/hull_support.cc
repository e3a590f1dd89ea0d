#include "u4d/joint/hull_support.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {
namespace {

// Rays are cast only this far around the object's own pixels in the view,
// as a share of the height of their bounding box (a missing part is a limb
// or a head, not a second person).
constexpr double kSearchShareOfHeight = 0.3;

// One other view's vote material for one object.
struct Voter {
  const Camera* camera = nullptr;
  const cv::Mat* labels = nullptr;  // CV_16U
  cv::Mat object;                   // CV_8U, the object's labels dilated
};

enum class Vote { kOutside, kOnObject, kOnOther, kOnBackground };

Vote VoteOf(const Voter& u, const Eigen::Vector3d& X) {
  const std::optional<Eigen::Vector2i> q = NearestPixel(*u.camera, X);
  if (!q) return Vote::kOutside;
  if (u.object.at<uint8_t>(q->y(), q->x())) return Vote::kOnObject;
  return u.labels->at<uint16_t>(q->y(), q->x()) != 0 ? Vote::kOnOther : Vote::kOnBackground;
}

// True when X is on the object's leave-one-out hull (header contract), with
// at most `max_background` views putting it on the background.
bool Supported(const std::vector<Voter>& voters, const Eigen::Vector3d& X, int min_views,
               int max_background) {
  int on = 0, background = 0;
  for (const Voter& u : voters) {
    const Vote vote = VoteOf(u, X);
    if (vote == Vote::kOnBackground && ++background > max_background) return false;
    if (vote == Vote::kOnObject) ++on;
  }
  return on - background >= min_views;
}

// `tolerance` > 0 dilates each other view's object labels, < 0 erodes them.
std::vector<Voter> VotersOf(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& labels,
                            int ref, int id, int tolerance) {
  std::vector<Voter> voters;
  const int r = std::abs(tolerance);
  const cv::Mat kernel =
      cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  for (size_t u = 0; u < cameras.size(); ++u) {
    if (static_cast<int>(u) == ref || labels[u].empty()) continue;
    Voter voter{&cameras[u], &labels[u], labels[u] == id};
    if (cv::countNonZero(voter.object) == 0) continue;  // u does not hold the object
    if (tolerance > 0) cv::dilate(voter.object, voter.object, kernel);
    if (tolerance < 0) cv::erode(voter.object, voter.object, kernel);
    voters.push_back(std::move(voter));
  }
  return voters;
}

// The rectangle of `ref`'s pixels searched for object `id`: around its own
// pixels, and over the pixels of the labels it claims; the whole image when
// the view has none of its pixels (missed there, or merged into another
// object).
cv::Rect SearchBox(const cv::Mat& ref_labels, const HullObject& obj) {
  const cv::Rect image(0, 0, ref_labels.cols, ref_labels.rows);
  const cv::Mat own = ref_labels == obj.id;
  // Missed in this view: anywhere.
  if (cv::countNonZero(own) == 0) return image;
  const cv::Rect box = cv::boundingRect(own);
  const int grow = static_cast<int>(std::ceil(kSearchShareOfHeight * box.height));
  cv::Rect out(box.x - grow, box.y - grow, box.width + 2 * grow, box.height + 2 * grow);
  for (const int claim : obj.claims) {
    const cv::Mat claimed = ref_labels == claim;
    if (cv::countNonZero(claimed) > 0) out |= cv::boundingRect(claimed);
  }
  return out & image;
}

bool Claims(const HullObject& obj, int label) {
  return std::find(obj.claims.begin(), obj.claims.end(), label) != obj.claims.end();
}

}  // namespace

void HullSupportOptions::Check() const {
  U4D_CHECK(min_views >= 1, "HullSupportOptions.min_views must be >= 1, got {}", min_views);
  U4D_CHECK(max_background_views >= 0,
            "HullSupportOptions.max_background_views must be >= 0, got {}", max_background_views);
  U4D_CHECK(mask_tolerance_px >= 0, "HullSupportOptions.mask_tolerance_px must be >= 0, got {}",
            mask_tolerance_px);
  U4D_CHECK(depth_samples >= 2, "HullSupportOptions.depth_samples must be >= 2, got {}",
            depth_samples);
  U4D_CHECK(confirm_inset_px >= 0, "HullSupportOptions.confirm_inset_px must be >= 0, got {}",
            confirm_inset_px);
  U4D_CHECK(max_side >= 16, "HullSupportOptions.max_side must be >= 16, got {}", max_side);
}

namespace {

void CheckHullInput(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& labels, int ref,
                    const HullSupportOptions& options) {
  options.Check();
  U4D_CHECK(labels.size() == cameras.size(), "HullSupport: {} cameras but {} label maps",
            cameras.size(), labels.size());
  U4D_CHECK(ref >= 0 && ref < static_cast<int>(cameras.size()),
            "HullSupport: reference view {} out of range", ref);
  for (size_t u = 0; u < cameras.size(); ++u)
    U4D_CHECK(
        labels[u].empty() || (labels[u].type() == CV_16UC1 && labels[u].cols == cameras[u].width &&
                              labels[u].rows == cameras[u].height),
        "HullSupport: the labels of view {} must be CV_16U of the camera's size {}x{}", u,
        cameras[u].width, cameras[u].height);
  U4D_CHECK(!labels[ref].empty(), "HullSupport: the reference view {} has no labels", ref);
}

// The coarse grid the rays are cast on (options.max_side) and, per grid
// pixel, the object whose leave-one-out hull the ray meets first.
struct HullGrid {
  double f = 1;     // grid / camera
  cv::Mat support;  // CV_16U object id, 0 = none
  cv::Mat nearest;  // CV_64F depth of that meeting
  // With count_all, every object's rays run to its hull, and `met` (CV_8U)
  // counts the objects whose hulls a ray meets (else they stop at `nearest`).
  bool count_all = false;
  cv::Mat met;
};

HullGrid MakeGrid(const Camera& cam, const HullSupportOptions& options) {
  HullGrid g;
  g.f = std::min(1.0, static_cast<double>(options.max_side) / std::max(cam.width, cam.height));
  const int gw = std::max(1, static_cast<int>(std::lround(cam.width * g.f)));
  const int gh = std::max(1, static_cast<int>(std::lround(cam.height * g.f)));
  g.support = cv::Mat::zeros(gh, gw, CV_16U);
  g.nearest = cv::Mat(gh, gw, CV_64F, cv::Scalar(1e300));
  g.met = cv::Mat::zeros(gh, gw, CV_8U);
  return g;
}

// Casts the rays of the grid pixels in `box` whose own label passes `tested`
// and marks where they meet object `obj`'s hull (nearer than what is marked).
template <typename Tested>
void CastRays(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& labels, int ref,
              const HullObject& obj, const cv::Rect& box, int tolerance,
              const HullSupportOptions& options, Tested tested, HullGrid* grid) {
  U4D_CHECK(obj.id >= 1 && obj.id < 65536 && obj.depth_near > 0 && obj.depth_far > obj.depth_near &&
                std::isfinite(obj.depth_far),
            "HullSupport: object {} has a bad id or depth range [{}, {}]", obj.id, obj.depth_near,
            obj.depth_far);
  const Camera& cam = cameras[ref];
  const cv::Mat& own = labels[ref];
  const std::vector<Voter> voters = VotersOf(cameras, labels, ref, obj.id, tolerance);
  if (static_cast<int>(voters.size()) < options.min_views || box.empty()) return;
  const double f = grid->f;
  const int gw = grid->support.cols, gh = grid->support.rows;
  const int gx0 = static_cast<int>(box.x * f), gx1 = static_cast<int>(box.br().x * f);
  const int gy0 = static_cast<int>(box.y * f), gy1 = static_cast<int>(box.br().y * f);
  tbb::parallel_for(gy0, std::min(gy1 + 1, gh), [&](int gy) {
    for (int gx = gx0; gx <= std::min(gx1, gw - 1); ++gx) {
      const Eigen::Vector2d pixel((gx + 0.5) / f - 0.5, (gy + 0.5) / f - 0.5);
      const int x = std::clamp(static_cast<int>(std::lround(pixel.x())), 0, cam.width - 1);
      const int y = std::clamp(static_cast<int>(std::lround(pixel.y())), 0, cam.height - 1);
      const int own_label = own.at<uint16_t>(y, x);
      if (!tested(own_label)) continue;
      // Only a part the view puts on the background may have a dissenting
      // view (header): over another object's pixels, and to confirm a
      // label, every view must agree.
      const int max_background = own_label == 0 ? options.max_background_views : 0;
      // The ray's point at depth z is centre + z * step (undistorted once per ray).
      const Eigen::Vector3d centre = cam.Center();
      const Eigen::Vector3d step = cam.Unproject(pixel, 1.0) - centre;
      for (int k = 0; k < options.depth_samples; ++k) {
        const double z =
            obj.depth_near + (obj.depth_far - obj.depth_near) * k / (options.depth_samples - 1);
        double& nearest = grid->nearest.at<double>(gy, gx);
        if (!grid->count_all && z >= nearest) break;
        if (!Supported(voters, centre + z * step, options.min_views, max_background)) continue;
        if (grid->count_all) ++grid->met.at<uint8_t>(gy, gx);
        if (z < nearest) grid->support.at<uint16_t>(gy, gx) = static_cast<uint16_t>(obj.id);
        nearest = std::min(nearest, z);
        break;
      }
    }
  });
}

cv::Mat AtCameraSize(const HullGrid& grid, cv::Size size) {
  cv::Mat full = grid.support;
  if (full.size() != size) cv::resize(grid.support, full, size, 0, 0, cv::INTER_NEAREST);
  return full;
}

}  // namespace

cv::Mat HullSupport(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& labels, int ref,
                    const std::vector<HullObject>& objects, const HullSupportOptions& options) {
  CheckHullInput(cameras, labels, ref, options);
  const cv::Mat& own = labels[ref];
  HullGrid grid = MakeGrid(cameras[ref], options);
  for (const HullObject& obj : objects)
    // Only the view's background and the object's claims are tested.
    CastRays(
        cameras, labels, ref, obj, SearchBox(own, obj), options.mask_tolerance_px, options,
        [&](int label) { return label == 0 || Claims(obj, label); }, &grid);
  cv::Mat full = AtCameraSize(grid, own.size());
  // The view's own labels stand, but where claimed.
  std::map<int, const HullObject*> by_id;
  for (const HullObject& obj : objects) by_id[obj.id] = &obj;
  for (int y = 0; y < full.rows; ++y)
    for (int x = 0; x < full.cols; ++x) {
      uint16_t& o = full.at<uint16_t>(y, x);
      const int label = own.at<uint16_t>(y, x);
      if (o != 0 && label != 0 && !Claims(*by_id.at(o), label)) o = 0;
    }
  return full;
}

cv::Mat HullConfirmation(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& labels,
                         int ref, const std::vector<HullObject>& objects,
                         const HullSupportOptions& options, cv::Mat* seen, cv::Mat* alone) {
  CheckHullInput(cameras, labels, ref, options);
  const cv::Mat& own = labels[ref];
  HullGrid grid = MakeGrid(cameras[ref], options);
  grid.count_all = true;
  // Every object's rays over every object's pixels: the nearest hull a ray
  // meets is the object seen there (a person behind the one seen meets the
  // ray too, and the view may give one object's pixels to another).
  cv::Rect box;
  for (const HullObject& obj : objects) box |= SearchBox(own, obj);
  for (const HullObject& obj : objects) {
    CastRays(
        cameras, labels, ref, obj, box, -options.confirm_inset_px, options,
        [](int label) { return label != 0; }, &grid);
  }
  cv::Mat full = AtCameraSize(grid, own.size());
  full.setTo(0, own == 0);
  if (seen != nullptr) *seen = full.clone();
  full.setTo(0, full != own);
  if (alone != nullptr) {
    cv::Mat met = grid.met;
    if (met.size() != own.size()) cv::resize(grid.met, met, own.size(), 0, 0, cv::INTER_NEAREST);
    *alone = (full != 0) & (met == 1);
  }
  return full;
}

}  // namespace u4d
