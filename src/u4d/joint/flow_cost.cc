#include "u4d/joint/flow_cost.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {
namespace {

// BGR 8-bit -> CV_32FC3 in [0, 1].
cv::Mat ToFloat(const cv::Mat& bgr) {
  cv::Mat f;
  bgr.convertTo(f, CV_32FC3, 1.0 / 255.0);
  return f;
}

// Bilinear sample of a CV_32FC3 image at (x, y), pixel-centre origin. False
// when (x, y) is outside [-0.5, w - 0.5) x [-0.5, h - 0.5) (the image area);
// within half a pixel of the border the nearest row/column is repeated.
inline bool Sample(const cv::Mat& img, float x, float y, cv::Vec3f* out) {
  const int w = img.cols, h = img.rows;
  if (!(x >= -0.5f && y >= -0.5f && x < w - 0.5f && y < h - 0.5f)) return false;
  x = std::clamp(x, 0.0f, static_cast<float>(w - 1));
  y = std::clamp(y, 0.0f, static_cast<float>(h - 1));
  const int x0 = std::min(static_cast<int>(x), w - 1), y0 = std::min(static_cast<int>(y), h - 1);
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const float ax = x - x0, ay = y - y0;
  const cv::Vec3f* r0 = img.ptr<cv::Vec3f>(y0);
  const cv::Vec3f* r1 = img.ptr<cv::Vec3f>(y1);
  *out = (1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x1]) + ay * ((1 - ax) * r1[x0] + ax * r1[x1]);
  return true;
}

inline float ColourCost(const cv::Vec3f& a, const cv::Vec3f& b) {
  const cv::Vec3f d = a - b;
  return (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / 3.0f;
}

bool IsInteger(float v) { return v == std::round(v); }

void CheckColour(const char* fn, const cv::Mat& img, const Camera& cam, const std::string& what) {
  U4D_CHECK(!img.empty(), "{}: {} is empty", fn, what);
  U4D_CHECK(img.type() == CV_8UC3, "{}: {} must be BGR 8-bit (CV_8UC3), got type {}", fn, what,
            img.type());
  U4D_CHECK(img.cols == cam.width && img.rows == cam.height,
            "{}: {} is {}x{} but its camera is {}x{}", fn, what, img.cols, img.rows, cam.width,
            cam.height);
}

// Per other view i at t+1: pixel homogeneous h(p, m) = h0_i(p) + A_i[:, 0:2] m
// for a distortion-free rig (see flow_cost.h, e_F^V).
struct CrossViewGeometry {
  int view = 0;
  Eigen::Matrix<float, 3, 2> a2;
  std::vector<Eigen::Vector3f> h0;  // per pixel; unused where the depth is unknown
};

// Checked inputs and everything E_f's photometric terms need (shared by the
// cost volume and the per-field evaluation).
struct Prepared {
  int W = 0, H = 0;
  cv::Mat ref_t, ref_t1;          // CV_32FC3 in [0, 1]
  std::vector<uint8_t> in_roi;    // per pixel: compute
  std::vector<uint8_t> needed;    // per pixel: enters the patch of a roi pixel
  bool use_cross = false;         // e_F^V on
  std::vector<cv::Mat> other_t1;  // indexed like `geometry`
  std::vector<CrossViewGeometry> geometry;
  bool distorted = false;
};

Prepared Prepare(const FlowCostInput& input, const FlowCostOptions& options, const char* fn) {
  Prepared P;
  const int num_views = static_cast<int>(input.images_t1.size());
  U4D_CHECK(num_views >= 1, "{}: no images at t+1", fn);
  U4D_CHECK(input.ref_view >= 0 && input.ref_view < num_views,
            "{}: ref_view {} out of range [0, {})", fn, input.ref_view, num_views);
  U4D_CHECK(static_cast<int>(input.cameras_t.size()) == num_views &&
                static_cast<int>(input.cameras_t1.size()) == num_views,
            "{}: expected {} cameras at t and t+1 (one per image at t+1), got "
            "{} and {}",
            fn, num_views, input.cameras_t.size(), input.cameras_t1.size());
  U4D_CHECK(static_cast<int>(input.images_t.size()) > input.ref_view,
            "{}: images_t has no image of the reference view {}", fn, input.ref_view);
  const int r = input.ref_view;
  const Camera& cam_t = input.cameras_t[r];
  const Camera& cam_t1 = input.cameras_t1[r];
  cam_t.Check(fmt::format("{}: reference camera at t", fn));
  cam_t1.Check(fmt::format("{}: reference camera at t+1", fn));
  U4D_CHECK(cam_t.width == cam_t1.width && cam_t.height == cam_t1.height,
            "{}: reference camera is {}x{} at t but {}x{} at t+1", fn, cam_t.width, cam_t.height,
            cam_t1.width, cam_t1.height);
  CheckColour(fn, input.images_t[r], cam_t, fmt::format("images_t[{}] (reference)", r));
  CheckColour(fn, input.images_t1[r], cam_t1, fmt::format("images_t1[{}] (reference)", r));
  const int W = cam_t.width, H = cam_t.height, N = W * H;
  P.W = W, P.H = H;
  if (!input.depth_t.empty())
    U4D_CHECK(
        input.depth_t.type() == CV_32FC1 && input.depth_t.cols == W && input.depth_t.rows == H,
        "{}: depth_t must be CV_32FC1 {}x{}, got type {} {}x{}", fn, W, H, input.depth_t.type(),
        input.depth_t.cols, input.depth_t.rows);
  if (!input.roi.empty())
    U4D_CHECK(input.roi.type() == CV_8UC1 && input.roi.cols == W && input.roi.rows == H,
              "{}: roi must be CV_8UC1 {}x{}, got type {} {}x{}", fn, W, H, input.roi.type(),
              input.roi.cols, input.roi.rows);

  P.ref_t = ToFloat(input.images_t[r]);
  P.ref_t1 = ToFloat(input.images_t1[r]);
  std::vector<uint8_t>& in_roi = P.in_roi;
  in_roi.assign(N, 1);
  if (!input.roi.empty())
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) in_roi[y * W + x] = input.roi.at<uint8_t>(y, x) != 0;

  // Pixels whose per-pixel costs enter the patch of some roi pixel.
  std::vector<uint8_t>& needed = P.needed;
  needed = in_roi;
  if (!input.roi.empty() && options.patch_radius > 0) {
    cv::Mat grown;
    const int k = 2 * options.patch_radius + 1;
    cv::dilate(input.roi != 0, grown, cv::Mat::ones(k, k, CV_8U));
    for (int p = 0; p < N; ++p) needed[p] = grown.at<uint8_t>(p) != 0;
  }

  // e_F^V set-up: the other views at t+1 and their geometry.
  const bool use_cross = P.use_cross =
      options.cross_view && !input.depth_t.empty() && num_views > 1;
  std::vector<cv::Mat>& other_t1 = P.other_t1;
  std::vector<CrossViewGeometry>& geometry = P.geometry;
  bool& distorted = P.distorted;
  if (use_cross) {
    distorted = cam_t.HasDistortion() || cam_t1.HasDistortion();
    const Eigen::Matrix3d k_inv = cam_t1.K.inverse();
    for (int i = 0; i < num_views; ++i) {
      if (i == r) continue;
      const Camera& ci = input.cameras_t1[i];
      ci.Check(fmt::format("{}: camera {} at t+1", fn, i));
      CheckColour(fn, input.images_t1[i], ci, fmt::format("images_t1[{}]", i));
      const double cos_angle = ci.ViewDirection().dot(cam_t1.ViewDirection());
      if (cos_angle < std::cos(options.max_view_angle_deg * M_PI / 180) - 1e-9) continue;
      distorted = distorted || ci.HasDistortion();
      other_t1.push_back(ToFloat(input.images_t1[i]));
      const Rigid3d i_from_ref = ci.cam_from_world * cam_t1.cam_from_world.Inverse();
      const Eigen::Matrix3d a = ci.K * i_from_ref.rotation * k_inv;
      const Eigen::Vector3d b = ci.K * i_from_ref.translation;
      CrossViewGeometry g;
      g.view = i;
      g.a2 = a.leftCols<2>().cast<float>();
      g.h0.assign(N, Eigen::Vector3f::Zero());
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          const float z = input.depth_t.at<float>(y, x);
          if (!(z > 0) || !std::isfinite(z)) continue;
          g.h0[y * W + x] = (a * Eigen::Vector3d(x, y, 1) + b / z).cast<float>();
        }
      geometry.push_back(std::move(g));
    }
  }

  return P;
}

}  // namespace

void FlowCostOptions::Check() const {
  U4D_CHECK(patch_radius >= 0 && patch_radius <= 32,
            "FlowCostOptions.patch_radius must be in [0, 32], got {}", patch_radius);
  U4D_CHECK(
      std::isfinite(max_view_angle_deg) && max_view_angle_deg > 0 && max_view_angle_deg <= 180,
      "FlowCostOptions.max_view_angle_deg must be in (0, 180], got {}", max_view_angle_deg);
  U4D_CHECK(std::isfinite(truncation) && truncation > 0,
            "FlowCostOptions.truncation must be finite and > 0, got {}", truncation);
}

MotionCostVolume ComputeFlowCostVolume(const FlowCostInput& input,
                                       const std::vector<Eigen::Vector2f>& motions,
                                       const MotionLabelOptions& label_options,
                                       const FlowCostOptions& options) {
  options.Check();
  label_options.Check();
  U4D_CHECK(!motions.empty(), "ComputeFlowCostVolume: the motion label set is empty");
  for (size_t l = 0; l < motions.size(); ++l)
    U4D_CHECK(motions[l].allFinite(), "ComputeFlowCostVolume: motion label {} is not finite", l);
  const Prepared P = Prepare(input, options, "ComputeFlowCostVolume");
  const int r = input.ref_view;
  const Camera& cam_t1 = input.cameras_t1[r];
  const int W = P.W, H = P.H, N = W * H;
  const cv::Mat& ref_t = P.ref_t;
  const cv::Mat& ref_t1 = P.ref_t1;
  const std::vector<uint8_t>& in_roi = P.in_roi;
  const std::vector<uint8_t>& needed = P.needed;
  const bool use_cross = P.use_cross;
  const std::vector<cv::Mat>& other_t1 = P.other_t1;
  const std::vector<CrossViewGeometry>& geometry = P.geometry;
  const bool distorted = P.distorted;

  // e_F^S set-up: per pixel the bitset of allowed labels (empty = all allowed).
  const int L = static_cast<int>(motions.size());
  const int words = (L + 63) / 64;
  std::vector<uint64_t> allowed;  // N * words, only when the constraint applies
  std::vector<uint8_t> constrained(N, 0);
  const bool use_dense = options.sparse && options.dense_support && !input.dense_matches.empty();
  if (use_dense)
    U4D_CHECK(input.dense_matches.type() == CV_32FC2 && input.dense_matches.cols == W &&
                  input.dense_matches.rows == H,
              "ComputeFlowCostVolume: dense matches must be CV_32FC2 of {}x{}", W, H);
  if (options.sparse && (!input.sparse.empty() || use_dense)) {
    const int n_sparse = static_cast<int>(input.sparse.size());
    std::vector<uint64_t> sparse_bits(static_cast<size_t>(n_sparse) * words, 0);
    const float win = static_cast<float>(label_options.window);
    for (int s = 0; s < n_sparse; ++s) {
      const SparseMotion& sm = input.sparse[s];
      U4D_CHECK(sm.pixel.allFinite() && sm.displacement.allFinite(),
                "ComputeFlowCostVolume: sparse correspondence {} is not finite", s);
      const Eigen::Vector2f d = sm.displacement.cast<float>();
      for (int l = 0; l < L; ++l)
        if ((motions[l] - d).cwiseAbs().maxCoeff() <= win + 1e-4f)
          sparse_bits[static_cast<size_t>(s) * words + l / 64] |= uint64_t{1} << (l % 64);
    }
    // Buckets of side support_radius: a pixel's neighbours lie in its 3x3 buckets.
    const double rad = label_options.support_radius;
    const int bw = static_cast<int>(std::ceil(W / rad)) + 1,
              bh = static_cast<int>(std::ceil(H / rad)) + 1;
    std::vector<std::vector<int>> buckets(static_cast<size_t>(bw) * bh);
    for (int s = 0; s < n_sparse; ++s) {
      const Eigen::Vector2d& p = input.sparse[s].pixel;
      const int bx = static_cast<int>(std::floor(p.x() / rad)),
                by = static_cast<int>(std::floor(p.y() / rad));
      if (bx < -1 || by < -1 || bx > bw || by > bh) continue;  // too far to reach any pixel
      buckets[std::clamp(by, 0, bh - 1) * bw + std::clamp(bx, 0, bw - 1)].push_back(s);
    }
    allowed.assign(static_cast<size_t>(N) * words, 0);
    const double rad2 = rad * rad;
    tbb::parallel_for(0, H, [&](int y) {
      for (int x = 0; x < W; ++x) {
        const int p = y * W + x;
        if (!in_roi[p]) continue;
        uint64_t* bits = &allowed[static_cast<size_t>(p) * words];
        bool near = false;
        const int bx = static_cast<int>(std::floor(x / rad)),
                  by = static_cast<int>(std::floor(y / rad));
        for (int yy = std::max(by - 1, 0); yy <= std::min(by + 1, bh - 1); ++yy)
          for (int xx = std::max(bx - 1, 0); xx <= std::min(bx + 1, bw - 1); ++xx)
            for (int s : buckets[yy * bw + xx]) {
              if ((input.sparse[s].pixel - Eigen::Vector2d(x, y)).squaredNorm() > rad2) continue;
              near = true;
              const uint64_t* sb = &sparse_bits[static_cast<size_t>(s) * words];
              for (int k = 0; k < words; ++k) bits[k] |= sb[k];
            }
        if (use_dense) {
          const cv::Vec2f d = input.dense_matches.at<cv::Vec2f>(y, x);
          if (std::isfinite(d[0]) && std::isfinite(d[1])) {
            near = true;
            for (int l = 0; l < L; ++l)
              if (std::max(std::abs(motions[l].x() - d[0]), std::abs(motions[l].y() - d[1])) <=
                  win + 1e-4f)
                bits[l / 64] |= uint64_t{1} << (l % 64);
          }
        }
        bool any = false;
        for (int k = 0; k < words; ++k) any = any || bits[k] != 0;
        constrained[p] = near && any;
      }
    });
  }

  MotionCostVolume volume;
  volume.width = W;
  volume.height = H;
  volume.motions = motions;
  volume.slots = MakeRoiSlots(input.roi, W, H);
  const std::vector<int>& slot = volume.slots.slot;
  const size_t S = volume.slots.count;
  volume.cost.assign(static_cast<size_t>(L) * S, 0.0f);
  if (S == 0) return volume;
  const float trunc = static_cast<float>(options.truncation);
  const int pr = options.patch_radius;
  const cv::Size ksize(2 * pr + 1, 2 * pr + 1);
  // Work in the bounding box of the needed pixels: every roi pixel's patch
  // lies in it (or beyond the image border, where the borders below act as on
  // the whole image), so the box-filtered costs of the roi pixels are those of
  // the whole image.
  const cv::Rect region =
      cv::boundingRect(cv::Mat(H, W, CV_8U, const_cast<uint8_t*>(needed.data())));
  const int rx = region.x, ry = region.y, rw = region.width, rh = region.height;
  // Adds the region-sized `c` (region coordinates) at the roi pixels.
  auto add_roi = [&](float* out, auto&& cost_at) {
    for (int yy = 0; yy < rh; ++yy) {
      const int* sl = &slot[static_cast<size_t>(yy + ry) * W + rx];
      for (int xx = 0; xx < rw; ++xx)
        if (sl[xx] >= 0) out[sl[xx]] += cost_at(yy, xx);
    }
  };

  tbb::parallel_for(0, L, [&](int l) {
    const Eigen::Vector2f& m = motions[l];
    float* out = &volume.cost[static_cast<size_t>(l) * S];
    if (options.temporal) {
      cv::Mat c(rh, rw, CV_32F);
      const bool integer = IsInteger(m.x()) && IsInteger(m.y());
      const int mx = static_cast<int>(m.x()), my = static_cast<int>(m.y());
      for (int yy = 0; yy < rh; ++yy) {
        const int y = yy + ry;
        const cv::Vec3f* a = ref_t.ptr<cv::Vec3f>(y);
        float* cr = c.ptr<float>(yy);
        for (int xx = 0; xx < rw; ++xx) {
          const int x = xx + rx;
          if (!needed[y * W + x]) {
            cr[xx] = 0;
            continue;
          }
          cv::Vec3f b;
          if (integer) {
            const int tx = x + mx, ty = y + my;
            if (tx < 0 || ty < 0 || tx >= W || ty >= H) {
              cr[xx] = trunc;
              continue;
            }
            b = ref_t1.at<cv::Vec3f>(ty, tx);
          } else if (!Sample(ref_t1, x + m.x(), y + m.y(), &b)) {
            cr[xx] = trunc;
            continue;
          }
          cr[xx] = ColourCost(a[x], b);
        }
      }
      if (pr > 0) cv::boxFilter(c, c, CV_32F, ksize, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
      add_roi(out, [&](int yy, int xx) { return std::min(c.at<float>(yy, xx), trunc); });
    }
    if (use_cross) {
      cv::Mat c(rh, rw, CV_32F, cv::Scalar(0)), w(rh, rw, CV_32F, cv::Scalar(0));
      std::vector<Eigen::Vector3f> dm(geometry.size());
      for (size_t g = 0; g < geometry.size(); ++g) dm[g] = geometry[g].a2 * m;
      for (int yy = 0; yy < rh; ++yy) {
        const int y = yy + ry;
        const cv::Vec3f* a = ref_t.ptr<cv::Vec3f>(y);
        const float* z = input.depth_t.ptr<float>(y);
        float* cr = c.ptr<float>(yy);
        float* wr = w.ptr<float>(yy);
        for (int xx = 0; xx < rw; ++xx) {
          const int x = xx + rx;
          const int p = y * W + x;
          if (!needed[p] || !(z[x] > 0) || !std::isfinite(z[x])) continue;
          float sum = 0;
          int n = 0;
          for (size_t g = 0; g < geometry.size(); ++g) {
            Eigen::Vector2f q;
            if (!distorted) {
              const Eigen::Vector3f h = geometry[g].h0[p] + dm[g];
              if (!(h.z() > 0)) continue;
              q = h.head<2>() / h.z();
            } else {
              const Eigen::Vector3d X =
                  cam_t1.Unproject(Eigen::Vector2d(x + m.x(), y + m.y()), z[x]);
              const Camera& ci = input.cameras_t1[geometry[g].view];
              if (!(ci.Depth(X) > 0)) continue;
              q = ci.Project(X).cast<float>();
            }
            cv::Vec3f b;
            if (!Sample(other_t1[g], q.x(), q.y(), &b)) continue;
            sum += ColourCost(a[x], b);
            ++n;
          }
          if (n > 0) {
            cr[xx] = sum / n;
            wr[xx] = 1;
          }
        }
      }
      if (pr > 0) {
        cv::boxFilter(c, c, CV_32F, ksize, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
        cv::boxFilter(w, w, CV_32F, ksize, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
      }
      add_roi(out, [&](int yy, int xx) {
        const float wp = w.at<float>(yy, xx);
        return wp > 0.5f ? std::min(c.at<float>(yy, xx) / wp, trunc) : 0.0f;
      });
    }
    if (!allowed.empty()) {
      const int word = l / 64;
      const uint64_t bit = uint64_t{1} << (l % 64);
      for (int p = 0; p < N; ++p)
        if (constrained[p] && !(allowed[static_cast<size_t>(p) * words + word] & bit))
          out[slot[p]] += kForbiddenMotion;  // constrained pixels are roi pixels
    }
  });
  return volume;
}

cv::Mat FlowFieldCosts(const FlowCostInput& input, const cv::Mat& flow,
                       const FlowCostOptions& options) {
  options.Check();
  const Prepared P = Prepare(input, options, "FlowFieldCosts");
  const int W = P.W, H = P.H;
  U4D_CHECK(flow.type() == CV_32FC2 && flow.cols == W && flow.rows == H,
            "FlowFieldCosts: flow must be CV_32FC2 {}x{}, got type {} {}x{}", W, H, flow.type(),
            flow.cols, flow.rows);
  const int r = input.ref_view;
  const Camera& cam_t1 = input.cameras_t1[r];
  const float trunc = static_cast<float>(options.truncation);
  const int pr = options.patch_radius;
  const float patch_area = static_cast<float>((2 * pr + 1) * (2 * pr + 1));
  cv::Mat out(H, W, CV_32F, cv::Scalar(0));
  tbb::parallel_for(0, H, [&](int y) {
    float* row = out.ptr<float>(y);
    for (int x = 0; x < W; ++x) {
      if (!P.in_roi[y * W + x]) continue;
      const cv::Vec2f& fv = flow.at<cv::Vec2f>(y, x);
      const Eigen::Vector2f m(fv[0], fv[1]);
      U4D_CHECK(m.allFinite(), "FlowFieldCosts: flow at ({}, {}) is not finite", x, y);
      float cost = 0;
      if (options.temporal) {  // as the volume: replicate border, normalised box
        float sum = 0;
        for (int dy = -pr; dy <= pr; ++dy)
          for (int dx = -pr; dx <= pr; ++dx) {
            const int qx = std::clamp(x + dx, 0, W - 1), qy = std::clamp(y + dy, 0, H - 1);
            cv::Vec3f b;
            if (!Sample(P.ref_t1, qx + m.x(), qy + m.y(), &b)) {
              sum += trunc;
              continue;
            }
            sum += ColourCost(P.ref_t.at<cv::Vec3f>(qy, qx), b);
          }
        cost += std::min(sum / patch_area, trunc);
      }
      if (P.use_cross) {  // as the volume: zero border, mean over defined pixels
        float sum = 0, weight = 0;
        for (int dy = -pr; dy <= pr; ++dy)
          for (int dx = -pr; dx <= pr; ++dx) {
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
            const int q = qy * W + qx;
            const float z = input.depth_t.at<float>(qy, qx);
            if (!P.needed[q] || !(z > 0) || !std::isfinite(z)) continue;
            const cv::Vec3f a = P.ref_t.at<cv::Vec3f>(qy, qx);
            float s = 0;
            int n = 0;
            for (size_t g = 0; g < P.geometry.size(); ++g) {
              Eigen::Vector2f qi;
              if (!P.distorted) {
                const Eigen::Vector3f h = P.geometry[g].h0[q] + P.geometry[g].a2 * m;
                if (!(h.z() > 0)) continue;
                qi = h.head<2>() / h.z();
              } else {
                const Eigen::Vector3d X =
                    cam_t1.Unproject(Eigen::Vector2d(qx + m.x(), qy + m.y()), z);
                const Camera& ci = input.cameras_t1[P.geometry[g].view];
                if (!(ci.Depth(X) > 0)) continue;
                qi = ci.Project(X).cast<float>();
              }
              cv::Vec3f b;
              if (!Sample(P.other_t1[g], qi.x(), qi.y(), &b)) continue;
              s += ColourCost(a, b);
              ++n;
            }
            if (n > 0) {
              sum += s / n;
              weight += 1;
            }
          }
        if (weight > 0.5f) cost += std::min(sum / weight, trunc);
      }
      row[x] = cost;
    }
  });
  return out;
}

namespace {

// Sub-pixel offset in [-0.5, 0.5] of the parabola through (-1, cm), (0, c0), (1, cp).
float Parabola(float cm, float c0, float cp) {
  const float limit = 0.5f * kForbiddenMotion;
  if (!(cm < limit && cp < limit && c0 < limit)) return 0;
  const float denom = cm - 2 * c0 + cp;
  if (!(denom > 1e-12f)) return 0;
  return std::clamp(0.5f * (cm - cp) / denom, -0.5f, 0.5f);
}

cv::Mat Refine(const MotionCostVolume& v, const std::vector<int>& labels) {
  const MotionLabelGrid grid(v.motions);
  cv::Mat flow(v.height, v.width, CV_32FC2, cv::Scalar(0, 0));
  const int N = v.width * v.height;
  tbb::parallel_for(0, v.height, [&](int y) {
    cv::Vec2f* row = flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < v.width; ++x) {
      const int p = y * v.width + x;
      const int l = labels[p];
      if (l < 0) continue;
      const Eigen::Vector2f m = v.motions[l];
      const float c0 = v.At(p, l);
      float ox = 0, oy = 0;
      const int xm = grid.Find(m.x() - 1, m.y()), xp = grid.Find(m.x() + 1, m.y());
      const int ym = grid.Find(m.x(), m.y() - 1), yp = grid.Find(m.x(), m.y() + 1);
      if (xm >= 0 && xp >= 0) ox = Parabola(v.At(p, xm), c0, v.At(p, xp));
      if (ym >= 0 && yp >= 0) oy = Parabola(v.At(p, ym), c0, v.At(p, yp));
      row[x] = cv::Vec2f(m.x() + ox, m.y() + oy);
    }
  });
  (void)N;
  return flow;
}

void CheckVolume(const MotionCostVolume& v, const std::string& fn) {
  U4D_CHECK(v.width > 0 && v.height > 0 && !v.motions.empty() &&
                v.slots.slot.size() == static_cast<size_t>(v.width) * v.height &&
                v.cost.size() == v.motions.size() * v.slots.count,
            "{}: inconsistent cost volume ({}x{}, {} labels, {} slots for {} pixels, {} costs)", fn,
            v.width, v.height, v.motions.size(), v.slots.count, v.slots.slot.size(), v.cost.size());
}

}  // namespace

bool ForbiddenMotion(const MotionCostVolume& volume, const FlowCostInput& input,
                     const FlowCostOptions& options, int window, int p, int label,
                     const Eigen::Vector2f& m) {
  if (label >= 0 && volume.At(p, label) < kForbiddenMotion) return false;
  if (!options.sparse) return label < 0;
  if (!options.dense_support || input.dense_matches.empty()) return true;
  const cv::Vec2f d = input.dense_matches.ptr<cv::Vec2f>()[p];
  return !(std::max(std::abs(m.x() - d[0]), std::abs(m.y() - d[1])) <= window + 1e-4f);
}

cv::Mat WinnerTakeAllFlow(const MotionCostVolume& volume, const cv::Mat& roi) {
  CheckVolume(volume, "WinnerTakeAllFlow");
  const int W = volume.width, H = volume.height, N = W * H, L = volume.NumLabels();
  if (!roi.empty())
    U4D_CHECK(roi.type() == CV_8UC1 && roi.cols == W && roi.rows == H,
              "WinnerTakeAllFlow: roi must be CV_8UC1 {}x{}, got type {} {}x{}", W, H, roi.type(),
              roi.cols, roi.rows);
  std::vector<int> labels(N, 0);
  tbb::parallel_for(0, H, [&](int y) {
    for (int x = 0; x < W; ++x) {
      const int p = y * W + x;
      if (!roi.empty() && roi.at<uint8_t>(y, x) == 0) {
        labels[p] = -1;
        continue;
      }
      int best = 0;
      float best_cost = volume.At(p, 0);
      for (int l = 1; l < L; ++l) {
        const float c = volume.At(p, l);
        if (c < best_cost) best_cost = c, best = l;
      }
      labels[p] = best;
    }
  });
  return Refine(volume, labels);
}

cv::Mat RefineFlowLabels(const MotionCostVolume& volume, const std::vector<int>& labels) {
  CheckVolume(volume, "RefineFlowLabels");
  U4D_CHECK(labels.size() == static_cast<size_t>(volume.width) * volume.height,
            "RefineFlowLabels: expected {} labels ({}x{}), got {}", volume.width * volume.height,
            volume.width, volume.height, labels.size());
  for (size_t p = 0; p < labels.size(); ++p)
    U4D_CHECK(labels[p] >= -1 && labels[p] < volume.NumLabels(),
              "RefineFlowLabels: label {} at pixel {} is outside [-1, {})", labels[p], p,
              volume.NumLabels());
  return Refine(volume, labels);
}

}  // namespace u4d
