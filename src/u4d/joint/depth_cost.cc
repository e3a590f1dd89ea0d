#include "u4d/joint/depth_cost.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <tbb/parallel_for.h>
#include <Eigen/Core>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {

void DepthCostOptions::Check() const {
  U4D_CHECK(num_depths >= 2, "DepthCostOptions.num_depths must be >= 2, got {}", num_depths);
  U4D_CHECK(patch_radius >= 0 && patch_radius <= 50,
            "DepthCostOptions.patch_radius must be in [0, 50], got {}", patch_radius);
  U4D_CHECK(num_best_views >= 1, "DepthCostOptions.num_best_views must be >= 1, got {}",
            num_best_views);
  U4D_CHECK(max_aux_views >= 1, "DepthCostOptions.max_aux_views must be >= 1, got {}",
            max_aux_views);
  U4D_CHECK(std::isfinite(unknown_cost) && unknown_cost >= 0 && unknown_cost <= 1,
            "DepthCostOptions.unknown_cost must be in [0, 1], got {}", unknown_cost);
  U4D_CHECK(std::isfinite(smooth_sigma) && smooth_sigma >= 0 && smooth_sigma <= 10,
            "DepthCostOptions.smooth_sigma must be in [0, 10], got {}", smooth_sigma);
  U4D_CHECK(std::isfinite(min_patch_std) && min_patch_std >= 0,
            "DepthCostOptions.min_patch_std must be >= 0, got {}", min_patch_std);
}

std::vector<float> InverseDepthSamples(double near, double far, int n) {
  U4D_CHECK(std::isfinite(near) && std::isfinite(far) && near > 0 && far > near,
            "depth range: need 0 < near < far (finite), got near {} far {}", near, far);
  U4D_CHECK(n >= 2, "InverseDepthSamples: need at least 2 samples, got {}", n);
  std::vector<float> z(n);
  const double inv_near = 1.0 / near, inv_far = 1.0 / far;
  for (int i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / (n - 1);
    z[i] = static_cast<float>(1.0 / (inv_near + t * (inv_far - inv_near)));
  }
  z.front() = static_cast<float>(near);
  z.back() = static_cast<float>(far);
  return z;
}

std::vector<int> SelectAuxViews(const std::vector<Camera>& cameras, int ref_view,
                                int max_aux_views) {
  U4D_CHECK(ref_view >= 0 && ref_view < static_cast<int>(cameras.size()),
            "ref_view {} out of range [0, {})", ref_view, cameras.size());
  const Eigen::Vector3d ref_axis = cameras[ref_view].ViewDirection();
  std::vector<std::pair<double, int>> by_angle;  // (-cos angle, view)
  for (int v = 0; v < static_cast<int>(cameras.size()); ++v) {
    if (v == ref_view) continue;
    const double c = ref_axis.dot(cameras[v].ViewDirection());
    if (c > 0) by_angle.emplace_back(-c, v);  // less than 90 degrees apart
  }
  std::sort(by_angle.begin(), by_angle.end());
  std::vector<int> aux;
  for (int i = 0; i < static_cast<int>(by_angle.size()) && i < max_aux_views; ++i)
    aux.push_back(by_angle[i].second);
  return aux;
}

namespace {

// Float planes centred on 0 (so the squared moments stay small in float):
// BGR (CV_32FC3) or grey (CV_32FC1), optionally Gaussian-smoothed.
cv::Mat CentredPlanes(const cv::Mat& bgr, bool color, double sigma) {
  cv::Mat src = bgr, out;
  if (!color) cv::cvtColor(bgr, src, cv::COLOR_BGR2GRAY);
  src.convertTo(out, color ? CV_32FC3 : CV_32FC1, 1.0, -127.5);
  if (sigma > 0) cv::GaussianBlur(out, out, cv::Size(), sigma, sigma, cv::BORDER_REPLICATE);
  return out;
}

// Pixel of a normalised (undistorted) point in `cam`, with its distortion.
inline Eigen::Vector2d NormalizedToPixel(const Camera& cam, double xn, double yn) {
  Eigen::Vector2d n(xn, yn);
  if (cam.HasDistortion()) n = Distort(cam.dist, n);
  const Eigen::Matrix3d& K = cam.K;
  return {K(0, 0) * n.x() + K(0, 1) * n.y() + K(0, 2), K(1, 1) * n.y() + K(1, 2)};
}

}  // namespace

DepthCostVolume ComputeDepthCostVolume(const std::vector<Camera>& cameras,
                                       const std::vector<cv::Mat>& images, int ref_view,
                                       const cv::Mat& roi, double depth_near, double depth_far,
                                       const DepthCostOptions& options) {
  options.Check();
  U4D_CHECK(cameras.size() == images.size(),
            "ComputeDepthCostVolume: {} cameras but {} images (one per view expected)",
            cameras.size(), images.size());
  U4D_CHECK(cameras.size() >= 2, "ComputeDepthCostVolume: need at least 2 views, got {}",
            cameras.size());
  U4D_CHECK(ref_view >= 0 && ref_view < static_cast<int>(cameras.size()),
            "ComputeDepthCostVolume: ref_view {} out of range [0, {})", ref_view, cameras.size());
  for (size_t v = 0; v < cameras.size(); ++v) {
    U4D_CHECK(images[v].type() == CV_8UC3,
              "ComputeDepthCostVolume: image of view {} must be BGR 8-bit (CV_8UC3), got type {}",
              v, images[v].type());
    U4D_CHECK(images[v].cols == cameras[v].width && images[v].rows == cameras[v].height,
              "ComputeDepthCostVolume: image of view {} is {}x{} but its camera is {}x{}", v,
              images[v].cols, images[v].rows, cameras[v].width, cameras[v].height);
  }
  const Camera& ref = cameras[ref_view];
  const int W = ref.width, H = ref.height;
  U4D_CHECK(roi.empty() || (roi.type() == CV_8UC1 && roi.cols == W && roi.rows == H),
            "ComputeDepthCostVolume: roi must be empty or CV_8U {}x{} (the reference size), "
            "got type {} {}x{}",
            W, H, roi.type(), roi.cols, roi.rows);

  DepthCostVolume vol;
  vol.width = W;
  vol.height = H;
  vol.depths = InverseDepthSamples(depth_near, depth_far, options.num_depths);
  vol.unknown_cost = static_cast<float>(options.unknown_cost);
  const int L = options.num_depths;
  vol.slots = MakeRoiSlots(roi, W, H);
  const size_t plane = vol.slots.count;
  vol.cost.assign(plane * L, 1.0f);

  const std::vector<int> aux = SelectAuxViews(cameras, ref_view, options.max_aux_views);
  const cv::Rect box = vol.slots.box;
  if (aux.empty() || box.area() == 0) return vol;

  // Working region: the ROI's bounding box plus the patch radius.
  const int r = options.patch_radius;
  const cv::Rect region =
      cv::Rect(box.x - r, box.y - r, box.width + 2 * r, box.height + 2 * r) & cv::Rect(0, 0, W, H);
  const int rw = region.width, rh = region.height;
  const size_t rn = static_cast<size_t>(rw) * rh;
  const cv::Size ksize(2 * r + 1, 2 * r + 1);

  // Reference moments over the patch; the patch variance is summed over the
  // channels (colour ZNCC: the patch as one vector of nc * (2r+1)^2 values,
  // the mean removed per channel).
  const int nc = options.use_color ? 3 : 1;
  const cv::Mat ref_planes =
      CentredPlanes(images[ref_view], options.use_color, options.smooth_sigma)(region).clone();
  cv::Mat mean_i, mean_ii;
  cv::boxFilter(ref_planes, mean_i, -1, ksize, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
  cv::boxFilter(ref_planes.mul(ref_planes), mean_ii, -1, ksize, cv::Point(-1, -1), true,
                cv::BORDER_REPLICATE);
  std::vector<float> var_i(rn, 0.0f);
  {
    const float* m = mean_i.ptr<float>();
    const float* mm = mean_ii.ptr<float>();
    for (size_t i = 0; i < rn; ++i)
      for (int c = 0; c < nc; ++c) var_i[i] += mm[i * nc + c] - m[i * nc + c] * m[i * nc + c];
  }

  // Pixels to fill: the ROI's (region coordinates), in slot order.
  std::vector<int> todo;  // region index
  todo.reserve(vol.slots.count);
  for (int y = box.y; y < box.y + box.height; ++y)
    for (int x = box.x; x < box.x + box.width; ++x)
      if (roi.empty() || roi.at<uint8_t>(y, x))
        todo.push_back((y - region.y) * rw + (x - region.x));

  // Per aux view: ray directions rotated into the aux camera, A = R_rel * ray,
  // so that the point at depth z is z * A + t_rel in the aux camera frame.
  const int na = static_cast<int>(aux.size());
  std::vector<cv::Mat> aux_planes(na);
  std::vector<std::vector<Eigen::Vector3f>> dirs(na, std::vector<Eigen::Vector3f>(rn));
  std::vector<Eigen::Vector3f> t_rel(na);
  std::vector<Eigen::Vector3d> rays(rn);
  for (int y = 0; y < rh; ++y)
    for (int x = 0; x < rw; ++x) {
      const Eigen::Vector2d n = ref.PixelToNormalized(Eigen::Vector2d(x + region.x, y + region.y));
      rays[static_cast<size_t>(y) * rw + x] = Eigen::Vector3d(n.x(), n.y(), 1.0);
    }
  const Eigen::Matrix3d R_ref = ref.cam_from_world.rotation;
  const Eigen::Vector3d t_ref = ref.cam_from_world.translation;
  for (int a = 0; a < na; ++a) {
    const Camera& cam = cameras[aux[a]];
    aux_planes[a] = CentredPlanes(images[aux[a]], options.use_color, options.smooth_sigma);
    const Eigen::Matrix3d R_rel = cam.cam_from_world.rotation * R_ref.transpose();
    t_rel[a] = (cam.cam_from_world.translation - R_rel * t_ref).cast<float>();
    for (size_t i = 0; i < rn; ++i) dirs[a][i] = (R_rel * rays[i]).cast<float>();
  }

  const float min_var = static_cast<float>(nc * options.min_patch_std * options.min_patch_std);
  const int k = options.num_best_views;

  tbb::parallel_for(0, L, [&](int label) {
    const float z = vol.depths[label];
    // costs[i * na + a]: m of todo pixel i in aux view a; > 1 = not seen.
    std::vector<float> costs(todo.size() * na, 2.0f);
    cv::Mat map_x(rh, rw, CV_32F), map_y(rh, rw, CV_32F), warped, mean_w, mean_ww, mean_iw;
    std::vector<uint8_t> seen(rn);
    for (int a = 0; a < na; ++a) {
      const Camera& cam = cameras[aux[a]];
      const double fx = cam.K(0, 0), s = cam.K(0, 1), cx = cam.K(0, 2), fy = cam.K(1, 1),
                   cy = cam.K(1, 2);
      const bool distorted = cam.HasDistortion();
      for (int y = 0; y < rh; ++y) {
        float* mx = map_x.ptr<float>(y);
        float* my = map_y.ptr<float>(y);
        for (int x = 0; x < rw; ++x) {
          const size_t i = static_cast<size_t>(y) * rw + x;
          const Eigen::Vector3f p = z * dirs[a][i] + t_rel[a];
          seen[i] = 0;
          mx[x] = my[x] = -1e4f;
          if (!(p.z() > 1e-6f)) continue;
          const double xn = p.x() / p.z(), yn = p.y() / p.z();
          double px, py;
          if (distorted) {
            const Eigen::Vector2d q = NormalizedToPixel(cam, xn, yn);
            px = q.x();
            py = q.y();
          } else {
            px = fx * xn + s * yn + cx;
            py = fy * yn + cy;
          }
          if (px >= -0.5 && py >= -0.5 && px < cam.width - 0.5 && py < cam.height - 0.5) {
            seen[i] = 1;
            mx[x] = static_cast<float>(px);
            my[x] = static_cast<float>(py);
          }
        }
      }
      cv::remap(aux_planes[a], warped, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      cv::boxFilter(warped, mean_w, -1, ksize, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
      cv::boxFilter(warped.mul(warped), mean_ww, -1, ksize, cv::Point(-1, -1), true,
                    cv::BORDER_REPLICATE);
      cv::boxFilter(warped.mul(ref_planes), mean_iw, -1, ksize, cv::Point(-1, -1), true,
                    cv::BORDER_REPLICATE);
      const float* mi = mean_i.ptr<float>();
      const float* vi = var_i.data();
      const float* mw = mean_w.ptr<float>();
      const float* mww = mean_ww.ptr<float>();
      const float* miw = mean_iw.ptr<float>();
      for (size_t t = 0; t < todo.size(); ++t) {
        const int i = todo[t];
        if (!seen[i]) continue;
        float m = 0.5f;  // textureless reference patch
        if (vi[i] >= min_var) {
          // A flat warped patch gets its variance floored: ZNCC towards 0, m towards 0.5.
          float var_w = 0, cov = 0;
          for (int c = 0; c < nc; ++c) {
            const int j = i * nc + c;
            var_w += mww[j] - mw[j] * mw[j];
            cov += miw[j] - mi[j] * mw[j];
          }
          const float ncc = cov / std::sqrt(vi[i] * std::max(var_w, min_var));
          m = 0.5f * (1.0f - std::clamp(ncc, -1.0f, 1.0f));
        }
        costs[t * na + a] = m;
      }
    }
    // Mean of the k lowest costs among the views that see the point.
    float* out = vol.cost.data() + static_cast<size_t>(label) * plane;
    float buf[64];
    const int nb = std::min(na, 64);
    for (size_t t = 0; t < todo.size(); ++t) {
      int n = 0;
      for (int a = 0; a < nb; ++a)
        if (costs[t * na + a] <= 1.0f) buf[n++] = costs[t * na + a];
      if (n == 0) continue;  // stays 1
      const int kk = std::min(k, n);
      std::partial_sort(buf, buf + kk, buf + n);
      float sum = 0;
      for (int j = 0; j < kk; ++j) sum += buf[j];
      out[t] = sum / kk;  // todo is in slot order
    }
  });
  return vol;
}

float RefinedDepth(const DepthCostVolume& volume, int pixel, int label) {
  const int n = volume.NumLabels();
  const float z = volume.depths[label];
  if (label <= 0 || label >= n - 1) return z;
  const float c0 = volume.At(pixel, label - 1), c1 = volume.At(pixel, label),
              c2 = volume.At(pixel, label + 1);
  const float denom = c0 - 2 * c1 + c2;
  if (!(denom > 1e-9f)) return z;
  const float delta = 0.5f * (c0 - c2) / denom;  // vertex offset in label steps
  if (!(std::abs(delta) <= 0.5f)) return z;
  const float inv = 1.0f / z;
  const float step =
      delta >= 0 ? 1.0f / volume.depths[label + 1] - inv : inv - 1.0f / volume.depths[label - 1];
  return 1.0f / (inv + delta * step);
}

cv::Mat WinnerTakeAllDepth(const DepthCostVolume& volume, const cv::Mat& roi) {
  const int W = volume.width, H = volume.height;
  U4D_CHECK(roi.empty() || (roi.type() == CV_8UC1 && roi.cols == W && roi.rows == H),
            "WinnerTakeAllDepth: roi must be empty or CV_8U {}x{}, got type {} {}x{}", W, H,
            roi.type(), roi.cols, roi.rows);
  const int L = volume.NumLabels();
  U4D_CHECK(volume.slots.slot.size() == static_cast<size_t>(W) * H &&
                volume.cost.size() == static_cast<size_t>(volume.slots.count) * L,
            "WinnerTakeAllDepth: volume holds {} costs and {} slots, expected {} labels x {} "
            "slots and {}x{} slots",
            volume.cost.size(), volume.slots.slot.size(), L, volume.slots.count, W, H);
  cv::Mat depth(H, W, CV_32F, cv::Scalar(0));
  tbb::parallel_for(0, H, [&](int y) {
    float* row = depth.ptr<float>(y);
    for (int x = 0; x < W; ++x) {
      if (!roi.empty() && !roi.at<uint8_t>(y, x)) continue;
      const int p = y * W + x;
      int best = 0;
      float best_cost = volume.At(p, 0);
      for (int l = 1; l < L; ++l) {
        const float c = volume.At(p, l);
        if (c < best_cost) {
          best_cost = c;
          best = l;
        }
      }
      if (best_cost < volume.unknown_cost) row[x] = RefinedDepth(volume, p, best);
    }
  });
  return depth;
}

cv::Mat RefineDepthLabels(const DepthCostVolume& volume, const std::vector<int>& labels) {
  const int W = volume.width, H = volume.height, L = volume.NumLabels();
  U4D_CHECK(labels.size() == static_cast<size_t>(W) * H,
            "RefineDepthLabels: {} labels for a {}x{} volume (one per pixel expected)",
            labels.size(), W, H);
  cv::Mat depth(H, W, CV_32F, cv::Scalar(0));
  for (int p = 0; p < W * H; ++p) {
    const int l = labels[p];
    U4D_CHECK(l >= -1 && l < L, "RefineDepthLabels: label {} at pixel {} outside [-1, {})", l, p,
              L);
    if (l >= 0) depth.at<float>(p / W, p % W) = RefinedDepth(volume, p, l);
  }
  return depth;
}

}  // namespace u4d
