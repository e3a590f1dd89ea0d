#include "u4d/joint/hull_support.h"

#include <algorithm>
#include <cmath>
#include <map>

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
  if (!(u.camera->Depth(X) > 0)) return Vote::kOutside;
  const Eigen::Vector2d q = u.camera->Project(X);
  if (!q.allFinite() || !u.camera->InImage(q)) return Vote::kOutside;
  const int x = std::clamp(static_cast<int>(std::lround(q.x())), 0, u.camera->width - 1);
  const int y = std::clamp(static_cast<int>(std::lround(q.y())), 0, u.camera->height - 1);
  if (u.object.at<uint8_t>(y, x)) return Vote::kOnObject;
  return u.labels->at<uint16_t>(y, x) != 0 ? Vote::kOnOther : Vote::kOnBackground;
}

// True when X is on the object's leave-one-out hull (header contract).
bool Supported(const std::vector<Voter>& voters, const Eigen::Vector3d& X, int min_views) {
  int on = 0;
  for (const Voter& u : voters) {
    const Vote vote = VoteOf(u, X);
    if (vote == Vote::kOnBackground) return false;
    if (vote == Vote::kOnObject) ++on;
  }
  return on >= min_views;
}

std::vector<Voter> VotersOf(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& labels,
                            int ref, int id, int tolerance) {
  std::vector<Voter> voters;
  const cv::Mat kernel =
      cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * tolerance + 1, 2 * tolerance + 1));
  for (size_t u = 0; u < cameras.size(); ++u) {
    if (static_cast<int>(u) == ref || labels[u].empty()) continue;
    Voter voter{&cameras[u], &labels[u], labels[u] == id};
    if (cv::countNonZero(voter.object) == 0) continue;  // u does not hold the object
    if (tolerance > 0) cv::dilate(voter.object, voter.object, kernel);
    voters.push_back(std::move(voter));
  }
  return voters;
}

// The rectangle of `ref`'s pixels searched for object `id`: around its own
// pixels, and over the pixels of the labels it claims (empty when the view
// has none of either).
cv::Rect SearchBox(const cv::Mat& ref_labels, const HullObject& obj) {
  cv::Rect out;
  const cv::Mat own = ref_labels == obj.id;
  if (cv::countNonZero(own) > 0) {
    const cv::Rect box = cv::boundingRect(own);
    const int grow = static_cast<int>(std::ceil(kSearchShareOfHeight * box.height));
    out = cv::Rect(box.x - grow, box.y - grow, box.width + 2 * grow, box.height + 2 * grow);
  }
  for (const int claim : obj.claims) {
    const cv::Mat claimed = ref_labels == claim;
    if (cv::countNonZero(claimed) > 0) out |= cv::boundingRect(claimed);
  }
  return out & cv::Rect(0, 0, ref_labels.cols, ref_labels.rows);
}

bool Claims(const HullObject& obj, int label) {
  return std::find(obj.claims.begin(), obj.claims.end(), label) != obj.claims.end();
}

}  // namespace

void HullSupportOptions::Check() const {
  U4D_CHECK(min_views >= 1, "HullSupportOptions.min_views must be >= 1, got {}", min_views);
  U4D_CHECK(mask_tolerance_px >= 0, "HullSupportOptions.mask_tolerance_px must be >= 0, got {}",
            mask_tolerance_px);
  U4D_CHECK(depth_samples >= 2, "HullSupportOptions.depth_samples must be >= 2, got {}",
            depth_samples);
  U4D_CHECK(max_side >= 16, "HullSupportOptions.max_side must be >= 16, got {}", max_side);
}

cv::Mat HullSupport(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& labels, int ref,
                    const std::vector<HullObject>& objects, const HullSupportOptions& options) {
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
  const Camera& cam = cameras[ref];
  const cv::Mat& own = labels[ref];
  U4D_CHECK(!own.empty(), "HullSupport: the reference view {} has no labels", ref);
  const double f =
      std::min(1.0, static_cast<double>(options.max_side) / std::max(cam.width, cam.height));
  const int gw = std::max(1, static_cast<int>(std::lround(cam.width * f)));
  const int gh = std::max(1, static_cast<int>(std::lround(cam.height * f)));
  cv::Mat support = cv::Mat::zeros(gh, gw, CV_16U);
  cv::Mat nearest(gh, gw, CV_64F, cv::Scalar(1e300));
  for (const HullObject& obj : objects) {
    U4D_CHECK(obj.id >= 1 && obj.id < 65536 && obj.depth_near > 0 &&
                  obj.depth_far > obj.depth_near && std::isfinite(obj.depth_far),
              "HullSupport: object {} has a bad id or depth range [{}, {}]", obj.id, obj.depth_near,
              obj.depth_far);
    const std::vector<Voter> voters =
        VotersOf(cameras, labels, ref, obj.id, options.mask_tolerance_px);
    const cv::Rect box = SearchBox(own, obj);
    if (static_cast<int>(voters.size()) < options.min_views || box.empty()) continue;
    const int gx0 = static_cast<int>(box.x * f), gx1 = static_cast<int>(box.br().x * f);
    const int gy0 = static_cast<int>(box.y * f), gy1 = static_cast<int>(box.br().y * f);
    tbb::parallel_for(gy0, std::min(gy1 + 1, gh), [&](int gy) {
      for (int gx = gx0; gx <= std::min(gx1, gw - 1); ++gx) {
        const Eigen::Vector2d pixel((gx + 0.5) / f - 0.5, (gy + 0.5) / f - 0.5);
        const int x = std::clamp(static_cast<int>(std::lround(pixel.x())), 0, cam.width - 1);
        const int y = std::clamp(static_cast<int>(std::lround(pixel.y())), 0, cam.height - 1);
        // Only the view's background and the object's claims are tested.
        if (const int label = own.at<uint16_t>(y, x); label != 0 && !Claims(obj, label)) continue;
        // The ray's point at depth z is centre + z * step (undistorted once per ray).
        const Eigen::Vector3d centre = cam.Center();
        const Eigen::Vector3d step = cam.Unproject(pixel, 1.0) - centre;
        for (int k = 0; k < options.depth_samples; ++k) {
          const double z =
              obj.depth_near + (obj.depth_far - obj.depth_near) * k / (options.depth_samples - 1);
          if (z >= nearest.at<double>(gy, gx)) break;
          if (!Supported(voters, centre + z * step, options.min_views)) continue;
          support.at<uint16_t>(gy, gx) = static_cast<uint16_t>(obj.id);
          nearest.at<double>(gy, gx) = z;
          break;
        }
      }
    });
  }
  cv::Mat full = support;
  if (support.size() != own.size()) cv::resize(support, full, own.size(), 0, 0, cv::INTER_NEAREST);
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

}  // namespace u4d
