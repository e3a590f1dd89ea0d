#include "u4d/baselines/stereo_baseline.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d::baselines {
namespace {

constexpr double kPi = 3.14159265358979323846;

cv::Mat ToCv(const Eigen::Matrix3d& m) {
  cv::Mat out;
  cv::eigen2cv(m, out);
  return out;
}

cv::Mat Distortion(const Camera& c) {
  cv::Mat d(1, 5, CV_64F);
  for (int i = 0; i < 5; ++i) d.at<double>(i) = c.dist[i];
  return d;
}

void CheckImage(const Camera& camera, const cv::Mat& image, const char* what) {
  U4D_CHECK(
      !image.empty() && image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3),
      "SgbmPairDepth: the {} image must be BGR or grey 8-bit, got type {}", what, image.type());
  U4D_CHECK(image.cols == camera.width && image.rows == camera.height,
            "SgbmPairDepth: the {} image is {}x{}, its camera {}x{}", what, image.cols, image.rows,
            camera.width, camera.height);
}

}  // namespace

void StereoSgbmOptions::Check() const {
  U4D_CHECK(num_pairs >= 1, "StereoSgbmOptions.num_pairs must be >= 1, got {}", num_pairs);
  U4D_CHECK(max_pair_angle_deg > 0 && max_pair_angle_deg < 180,
            "StereoSgbmOptions.max_pair_angle_deg must be in (0, 180), got {}", max_pair_angle_deg);
  U4D_CHECK(block_size >= 1 && block_size % 2 == 1,
            "StereoSgbmOptions.block_size must be odd and >= 1, got {}", block_size);
  U4D_CHECK(p1_per_px >= 0, "StereoSgbmOptions.p1_per_px must be >= 0, got {}", p1_per_px);
  U4D_CHECK(p2_per_px > p1_per_px, "StereoSgbmOptions.p2_per_px must be > p1_per_px, got {}",
            p2_per_px);
  U4D_CHECK(uniqueness_ratio >= 0, "StereoSgbmOptions.uniqueness_ratio must be >= 0, got {}",
            uniqueness_ratio);
  U4D_CHECK(speckle_window >= 0 && speckle_range >= 0,
            "StereoSgbmOptions.speckle_window/speckle_range must be >= 0, got {}/{}",
            speckle_window, speckle_range);
  U4D_CHECK(max_disparities >= 16 && max_disparities % 16 == 0,
            "StereoSgbmOptions.max_disparities must be a positive multiple of 16, got {}",
            max_disparities);
  U4D_CHECK(range_margin >= 0 && range_margin < 1,
            "StereoSgbmOptions.range_margin must be in [0, 1), got {}", range_margin);
}

std::vector<int> SelectStereoPairs(const std::vector<Camera>& cameras, int ref_view,
                                   double scene_depth, const StereoSgbmOptions& options) {
  options.Check();
  U4D_CHECK(ref_view >= 0 && ref_view < static_cast<int>(cameras.size()),
            "SelectStereoPairs: ref_view {} out of range [0, {})", ref_view, cameras.size());
  U4D_CHECK(scene_depth > 0, "SelectStereoPairs: scene_depth must be > 0, got {}", scene_depth);
  const Camera& ref = cameras[ref_view];
  const Eigen::Vector3d point = ref.Center() + scene_depth * ref.ViewDirection();
  const Eigen::Vector3d to_ref = (ref.Center() - point).normalized();
  std::vector<std::pair<double, int>> candidates;
  for (int v = 0; v < static_cast<int>(cameras.size()); ++v) {
    if (v == ref_view || !(cameras[v].Depth(point) > 0)) continue;
    const Eigen::Vector3d to_aux = (cameras[v].Center() - point).normalized();
    const double angle = std::acos(std::clamp(to_ref.dot(to_aux), -1.0, 1.0)) * 180 / kPi;
    // Below half a degree the pair has no usable baseline.
    if (angle > 0.5 && angle <= options.max_pair_angle_deg) candidates.push_back({angle, v});
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<int> out;
  for (const auto& [angle, v] : candidates) {
    if (static_cast<int>(out.size()) == options.num_pairs) break;
    out.push_back(v);
  }
  return out;
}

cv::Mat SgbmPairDepth(const Camera& ref_camera, const cv::Mat& ref_image, const Camera& aux_camera,
                      const cv::Mat& aux_image, double depth_near, double depth_far,
                      const StereoSgbmOptions& options) {
  options.Check();
  ref_camera.Check("SgbmPairDepth reference camera");
  aux_camera.Check("SgbmPairDepth auxiliary camera");
  CheckImage(ref_camera, ref_image, "reference");
  CheckImage(aux_camera, aux_image, "auxiliary");
  U4D_CHECK(ref_image.type() == aux_image.type(),
            "SgbmPairDepth: the images differ in type ({} vs {})", ref_image.type(),
            aux_image.type());
  U4D_CHECK(depth_near > 0 && depth_near < depth_far,
            "SgbmPairDepth: need 0 < depth_near < depth_far, got [{}, {}]", depth_near, depth_far);
  const cv::Size size(ref_camera.width, ref_camera.height);
  U4D_CHECK(aux_camera.width == size.width && aux_camera.height == size.height,
            "SgbmPairDepth: the cameras differ in size ({}x{} vs {}x{})", size.width, size.height,
            aux_camera.width, aux_camera.height);

  // X_aux = R X_ref + T.
  const Rigid3d aux_from_ref = aux_camera.cam_from_world * ref_camera.cam_from_world.Inverse();
  cv::Mat R = ToCv(aux_from_ref.rotation), T(3, 1, CV_64F);
  for (int i = 0; i < 3; ++i) T.at<double>(i) = aux_from_ref.translation[i];
  const cv::Mat K1 = ToCv(ref_camera.K), K2 = ToCv(aux_camera.K);
  const cv::Mat D1 = Distortion(ref_camera), D2 = Distortion(aux_camera);
  cv::Mat R1, R2, P1, P2, Q;
  // No CALIB_ZERO_DISPARITY: with converging cameras equal principal points
  // put the disparities of the scene beyond the image width; the principal
  // points' offset is subtracted from the disparity instead.
  cv::stereoRectify(K1, D1, K2, D2, size, R, T, R1, R2, P1, P2, Q, 0, -1, size);
  const bool vertical = std::abs(P2.at<double>(1, 3)) > std::abs(P2.at<double>(0, 3));
  const double shift = vertical ? P2.at<double>(1, 3) : P2.at<double>(0, 3);  // f * baseline
  const double f_b = std::abs(shift);
  if (!(f_b > 0)) return cv::Mat::zeros(size, CV_32F);
  const bool mirror = shift > 0;
  const int axis = vertical ? 1 : 0;
  const double sign = mirror ? -1 : 1;
  // d = x_ref - x_aux (after the turn) = f b / z + offset, offset = sign
  // (c_ref - c_aux) along the baseline. Converging cameras put the two
  // rectified images far apart (hundreds of pixels for 45-90 degree pairs);
  // the auxiliary principal point is moved (a translation of its rectified
  // image, no change of geometry) so that the disparities searched are
  // centred on 0: SGBM then matches the reference columns [n/2, width - n/2)
  // for a search of n disparities, a band centred on the image.
  const double margin = options.range_margin;
  const double target_offset =
      -0.5 * f_b * (1 / (depth_far * (1 + margin)) + 1 / (depth_near * (1 - margin)));
  P2.at<double>(axis, 2) = P1.at<double>(axis, 2) - sign * target_offset;
  const double offset = sign * (P1.at<double>(axis, 2) - P2.at<double>(axis, 2));

  cv::Mat map1x, map1y, map2x, map2y, rect_ref, rect_aux;
  cv::initUndistortRectifyMap(K1, D1, R1, P1, size, CV_32FC1, map1x, map1y);
  cv::initUndistortRectifyMap(K2, D2, R2, P2, size, CV_32FC1, map2x, map2y);
  cv::remap(ref_image, rect_ref, map1x, map1y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::remap(aux_image, rect_aux, map2x, map2y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  // Make the reference the left image of a horizontal pair: transpose a
  // vertical pair, mirror when the auxiliary camera is on the left (shift > 0
  // in OpenCV's convention: then x_aux = x_ref + f b / z).
  auto to_left = [&](cv::Mat& m) {
    if (vertical) cv::transpose(m, m);
    if (mirror) cv::flip(m, m, 1);
  };
  to_left(rect_ref);
  to_left(rect_aux);

  const double d_lo = f_b / (depth_far * (1 + margin)) + offset;
  const double d_hi = f_b / (depth_near * (1 - margin)) + offset;
  const int min_disp = static_cast<int>(std::floor(d_lo));
  int num_disp = static_cast<int>(std::ceil(d_hi)) - min_disp + 1;
  num_disp = std::min(options.max_disparities, (num_disp + 15) / 16 * 16);
  // SGBM matches the columns [max(min + num, 0), width + min(min, 0)) only.
  if (rect_ref.cols + std::min(min_disp, 0) - std::max(min_disp + num_disp, 0) <
      2 * options.block_size) {
    return cv::Mat::zeros(size, CV_32F);
  }
  const int cn = rect_ref.channels(), area = options.block_size * options.block_size;
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
      min_disp, num_disp, options.block_size, options.p1_per_px * cn * area,
      options.p2_per_px * cn * area, options.disp12_max_diff, 0, options.uniqueness_ratio,
      options.speckle_window, options.speckle_range,
      options.three_way ? cv::StereoSGBM::MODE_SGBM_3WAY : cv::StereoSGBM::MODE_SGBM);
  cv::Mat disp16;
  sgbm->compute(rect_ref, rect_aux, disp16);
  // Back to the rectified reference frame.
  if (mirror) cv::flip(disp16, disp16, 1);
  if (vertical) cv::transpose(disp16, disp16);

  // Each reference pixel's rectified position, then the point on its
  // rectified ray at z_rect = f b / d, then its z in the reference camera.
  std::vector<cv::Point2d> pixels, rectified;
  pixels.reserve(static_cast<size_t>(size.area()));
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) pixels.emplace_back(x, y);
  cv::undistortPoints(pixels, rectified, K1, D1, R1, P1);
  const double fx = P1.at<double>(0, 0), fy = P1.at<double>(1, 1);
  const double cx = P1.at<double>(0, 2), cy = P1.at<double>(1, 2);
  const double lo = depth_near * (1 - margin), hi = depth_far * (1 + margin);
  cv::Mat depth = cv::Mat::zeros(size, CV_32F);
  for (int i = 0; i < size.area(); ++i) {
    const cv::Point2d r = rectified[i];
    const int u = static_cast<int>(std::lround(r.x)), v = static_cast<int>(std::lround(r.y));
    if (u < 0 || v < 0 || u >= disp16.cols || v >= disp16.rows) continue;
    const int raw = disp16.at<int16_t>(v, u);
    if (raw < min_disp * 16) continue;  // SGBM's invalid marker is (min_disp - 1) * 16
    const double d = raw / 16.0 - offset;
    if (!(d > 0)) continue;
    const double z_rect = f_b / d;
    const Eigen::Vector3d x_rect(z_rect * (r.x - cx) / fx, z_rect * (r.y - cy) / fy, z_rect);
    const double z = R1.at<double>(0, 2) * x_rect.x() + R1.at<double>(1, 2) * x_rect.y() +
                     R1.at<double>(2, 2) * x_rect.z();  // (R1^T x_rect).z
    if (z >= lo && z <= hi) depth.ptr<float>()[i] = static_cast<float>(z);
  }
  return depth;
}

cv::Mat SgbmFusedDepth(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& images,
                       int ref_view, double depth_near, double depth_far,
                       const StereoSgbmOptions& options) {
  U4D_CHECK(cameras.size() == images.size(), "SgbmFusedDepth: {} cameras but {} images",
            cameras.size(), images.size());
  U4D_CHECK(depth_near > 0 && depth_near < depth_far,
            "SgbmFusedDepth: need 0 < depth_near < depth_far, got [{}, {}]", depth_near, depth_far);
  const std::vector<int> aux =
      SelectStereoPairs(cameras, ref_view, 0.5 * (depth_near + depth_far), options);
  const Camera& ref = cameras[ref_view];
  std::vector<cv::Mat> depths;
  depths.reserve(aux.size());
  for (int a : aux)
    depths.push_back(SgbmPairDepth(ref, images[ref_view], cameras[a], images[a], depth_near,
                                   depth_far, options));
  cv::Mat fused = cv::Mat::zeros(ref.height, ref.width, CV_32F);
  std::vector<float> values;
  for (int i = 0; i < ref.width * ref.height; ++i) {
    values.clear();
    for (const cv::Mat& d : depths)
      if (d.ptr<float>()[i] > 0) values.push_back(d.ptr<float>()[i]);
    if (values.empty()) continue;
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    fused.ptr<float>()[i] = n % 2 == 1 ? values[n / 2] : 0.5f * (values[n / 2 - 1] + values[n / 2]);
  }
  return fused;
}

}  // namespace u4d::baselines
