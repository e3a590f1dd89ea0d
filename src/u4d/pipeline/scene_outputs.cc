#include "u4d/pipeline/scene_outputs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include <opencv2/imgproc.hpp>

#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/visualize.h"
#include "u4d/pipeline/object_classes.h"
#include "u4d/util/check.h"

namespace u4d {

void KeepInitialDetail(const cv::Mat& working_labels, const cv::Mat& working_depth,
                       const cv::Mat& initial_working, const cv::Mat& initial_full, cv::Mat* labels,
                       cv::Mat* depth) {
  U4D_CHECK(working_labels.type() == CV_16UC1 && initial_working.type() == CV_16UC1 &&
                initial_full.type() == CV_16UC1 && working_depth.type() == CV_32FC1 &&
                labels->type() == CV_16UC1 && depth->type() == CV_32FC1,
            "KeepInitialDetail: labels must be CV_16U and depth CV_32F");
  U4D_CHECK(working_labels.size() == initial_working.size() &&
                working_labels.size() == working_depth.size() &&
                initial_full.size() == labels->size() && initial_full.size() == depth->size(),
            "KeepInitialDetail: the working maps ({}x{}) and the camera-size maps ({}x{}) must "
            "each have one size",
            working_labels.cols, working_labels.rows, initial_full.cols, initial_full.rows);
  const int ww = working_labels.cols, wh = working_labels.rows;
  // Working pixels whose 3x3 neighbourhood the solve left as it was given.
  cv::Mat kept;
  cv::erode(working_labels == initial_working, kept, cv::Mat::ones(3, 3, CV_8U), {-1, -1}, 1,
            cv::BORDER_REPLICATE);
  const double sx = double(ww) / labels->cols, sy = double(wh) / labels->rows;
  for (int y = 0; y < labels->rows; ++y) {
    const double fy = (y + 0.5) * sy - 0.5;
    const int qy = std::min(wh - 1, static_cast<int>(y * sy));
    for (int x = 0; x < labels->cols; ++x) {
      const int qx = std::min(ww - 1, static_cast<int>(x * sx));
      const int l = initial_full.at<uint16_t>(y, x);
      if (!kept.at<uint8_t>(qy, qx) || l == labels->at<uint16_t>(y, x)) continue;
      // The nearest working pixel of the 3x3 holding label l.
      const double fx = (x + 0.5) * sx - 0.5;
      double best = 1e9;
      float z = 0;
      for (int ny = std::max(0, qy - 1); ny <= std::min(wh - 1, qy + 1); ++ny)
        for (int nx = std::max(0, qx - 1); nx <= std::min(ww - 1, qx + 1); ++nx) {
          if (working_labels.at<uint16_t>(ny, nx) != l) continue;
          const double d = (nx - fx) * (nx - fx) + (ny - fy) * (ny - fy);
          if (d < best) best = d, z = working_depth.at<float>(ny, nx);
        }
      if (best == 1e9) continue;  // l not among the solve's labels there
      labels->at<uint16_t>(y, x) = static_cast<uint16_t>(l);
      depth->at<float>(y, x) = l == 0 ? 0.f : z;
    }
  }
}

void GuidedLabels(const cv::Mat& working_labels, const cv::Mat& working_depth,
                  const cv::Mat& working_image, const cv::Mat& full_image, cv::Mat* labels,
                  cv::Mat* depth) {
  U4D_CHECK(working_labels.type() == CV_16UC1 && working_depth.type() == CV_32FC1 &&
                working_image.type() == CV_8UC3 && full_image.type() == CV_8UC3 &&
                labels->type() == CV_16UC1 && depth->type() == CV_32FC1,
            "GuidedLabels: labels must be CV_16U, depth CV_32F and images BGR 8-bit");
  U4D_CHECK(working_labels.size() == working_depth.size() &&
                working_labels.size() == working_image.size() &&
                full_image.size() == labels->size() && full_image.size() == depth->size(),
            "GuidedLabels: the working maps ({}x{}) and the camera-size maps ({}x{}) must each "
            "have one size",
            working_labels.cols, working_labels.rows, full_image.cols, full_image.rows);
  const int ww = working_labels.cols, wh = working_labels.rows;
  // β: the mean squared colour difference of neighbouring working pixels (E_c's).
  double sum = 0;
  long count = 0;
  for (int y = 0; y < wh; ++y)
    for (int x = 0; x < ww; ++x) {
      const cv::Vec3d c = working_image.at<cv::Vec3b>(y, x);
      if (x + 1 < ww)
        sum += cv::norm(c - cv::Vec3d(working_image.at<cv::Vec3b>(y, x + 1)), cv::NORM_L2SQR),
            ++count;
      if (y + 1 < wh)
        sum += cv::norm(c - cv::Vec3d(working_image.at<cv::Vec3b>(y + 1, x)), cv::NORM_L2SQR),
            ++count;
    }
  const double beta = std::max(1.0, count > 0 ? sum / count : 1.0);
  // Working pixels with another label among their 8 neighbours.
  cv::Mat lo, hi;
  cv::erode(working_labels, lo, cv::Mat::ones(3, 3, CV_8U), {-1, -1}, 1, cv::BORDER_REPLICATE);
  cv::dilate(working_labels, hi, cv::Mat::ones(3, 3, CV_8U), {-1, -1}, 1, cv::BORDER_REPLICATE);
  const cv::Mat boundary = lo != hi;
  const double sx = double(ww) / labels->cols, sy = double(wh) / labels->rows;
  for (int y = 0; y < labels->rows; ++y) {
    const double fy = (y + 0.5) * sy - 0.5;
    const int qy = std::min(wh - 1, static_cast<int>(y * sy));
    for (int x = 0; x < labels->cols; ++x) {
      const int qx = std::min(ww - 1, static_cast<int>(x * sx));
      if (!boundary.at<uint8_t>(qy, qx)) continue;
      const double fx = (x + 0.5) * sx - 0.5;
      const cv::Vec3d colour = full_image.at<cv::Vec3b>(y, x);
      // Per label of the 9 working pixels: its summed weight, and the depth
      // of its heaviest pixel.
      struct Vote {
        int label;
        double weight, heaviest;
        float depth;
      };
      std::array<Vote, 9> votes;
      int num_votes = 0;
      for (int ny = std::max(0, qy - 1); ny <= std::min(wh - 1, qy + 1); ++ny)
        for (int nx = std::max(0, qx - 1); nx <= std::min(ww - 1, qx + 1); ++nx) {
          const double d2 = (nx - fx) * (nx - fx) + (ny - fy) * (ny - fy);
          const double c2 =
              cv::norm(colour - cv::Vec3d(working_image.at<cv::Vec3b>(ny, nx)), cv::NORM_L2SQR);
          const double w = std::exp(-0.5 * d2 - c2 / (2 * beta));
          const int l = working_labels.at<uint16_t>(ny, nx);
          const float z = working_depth.at<float>(ny, nx);
          Vote* v = std::find_if(votes.begin(), votes.begin() + num_votes,
                                 [&](const Vote& e) { return e.label == l; });
          if (v == votes.begin() + num_votes) *v = {l, 0, -1, 0}, ++num_votes;
          v->weight += w;
          if (w > v->heaviest) v->heaviest = w, v->depth = z;
        }
      const Vote& win = *std::max_element(
          votes.begin(), votes.begin() + num_votes, [](const Vote& a, const Vote& b) {
            return a.weight < b.weight || (a.weight == b.weight && a.label > b.label);
          });
      const int l = win.label;
      labels->at<uint16_t>(y, x) = static_cast<uint16_t>(l);
      depth->at<float>(y, x) = l == 0 ? 0.f : win.depth;
    }
  }
}

ViewMaps ToCameraSize(const JointViewResult& result, int width, int height, double scale,
                      const cv::Mat& initial_working, const cv::Mat& initial_full,
                      const cv::Mat& working_image, const cv::Mat& full_image) {
  U4D_CHECK(scale > 0 && scale <= 1, "ToCameraSize: scale must be in (0, 1], got {}", scale);
  U4D_CHECK(result.labels.type() == CV_16UC1 && result.depth.type() == CV_32FC1,
            "ToCameraSize: labels must be CV_16U and depth CV_32F");
  const cv::Size size(width, height);
  ViewMaps maps;
  cv::resize(result.labels, maps.labels, size, 0, 0, cv::INTER_NEAREST);
  cv::resize(result.depth, maps.depth, size, 0, 0, cv::INTER_NEAREST);
  if (!working_image.empty() && !full_image.empty() && result.labels.size() != size)
    GuidedLabels(result.labels, result.depth, working_image, full_image, &maps.labels, &maps.depth);
  if (!initial_working.empty() && !initial_full.empty() && result.labels.size() != size)
    KeepInitialDetail(result.labels, result.depth, initial_working, initial_full, &maps.labels,
                      &maps.depth);
  if (result.flow.empty()) {
    maps.flow = cv::Mat::zeros(size, CV_32FC2);
  } else {
    cv::resize(result.flow, maps.flow, size, 0, 0, cv::INTER_LINEAR);
    maps.flow *= 1.0 / scale;
  }
  return maps;
}

ViewMaps EmptyViewMaps(int width, int height) {
  return {cv::Mat::zeros(height, width, CV_16U), cv::Mat::zeros(height, width, CV_32F),
          cv::Mat::zeros(height, width, CV_32FC2)};
}

void WriteViewMaps(const fs::path& out, const std::string& view, int frame, const ViewMaps& maps,
                   const cv::Mat& image, int picture_width,
                   const std::map<int, std::string>& classes) {
  InstanceMask mask;
  mask.ids = maps.labels;
  std::set<int> ids;
  for (int y = 0; y < maps.labels.rows; ++y)
    for (int x = 0; x < maps.labels.cols; ++x)
      if (const int id = maps.labels.at<uint16_t>(y, x)) ids.insert(id);
  for (int id : ids) mask.instances.push_back({id, ObjectClass(classes, id), 1.0});
  WriteInstanceMask(out / layout::SceneInstances(view, frame),
                    out / layout::SceneInstancesInfo(view, frame), mask);
  WritePfm(out / layout::SceneDepth(view, frame), maps.depth);
  WriteFlo(out / layout::SceneFlow(view, frame), maps.flow);

  WriteImage(out / layout::ScenePicture("image", view, frame),
             DownscaleToWidth(image, picture_width, false));
  WriteImage(out / layout::ScenePicture("instances", view, frame),
             DownscaleToWidth(ColorizeInstances(maps.labels, {}), picture_width, true));
  const auto [near, far] = VisibleDepthRange(maps.depth);
  WriteImage(out / layout::ScenePicture("depth", view, frame),
             DownscaleToWidth(ColorizeDepth(maps.depth, near, far), picture_width, true));
  WriteImage(out / layout::ScenePicture("flow", view, frame),
             DownscaleToWidth(ColorizeFlow(maps.flow, MaxFlowMagnitude(maps.flow, maps.labels > 0)),
                              picture_width, true));
}

}  // namespace u4d
