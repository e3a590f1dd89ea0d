#include "u4d/pipeline/scene_outputs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/label_ids.h"
#include "u4d/io/layout.h"
#include "u4d/io/visualize.h"
#include "u4d/pipeline/object_classes.h"
#include "u4d/util/check.h"

namespace u4d {

namespace {

// Where a camera pixel (x, y) lies on the working grid: q, the working pixel
// cv::resize's INTER_NEAREST gives it, and f, its centre in working
// coordinates.
struct WorkingPlace {
  int x = 0, y = 0, qx = 0, qy = 0;
  double fx = 0, fy = 0;
};

// Calls fn(place) for every camera pixel of `camera` over `working`.
template <typename Fn>
void ForEachCameraPixel(cv::Size working, cv::Size camera, Fn fn) {
  const double sx = double(working.width) / camera.width;
  const double sy = double(working.height) / camera.height;
  WorkingPlace at;
  for (at.y = 0; at.y < camera.height; ++at.y) {
    at.fy = (at.y + 0.5) * sy - 0.5;
    at.qy = std::min(working.height - 1, static_cast<int>(at.y * sy));
    for (at.x = 0; at.x < camera.width; ++at.x) {
      at.fx = (at.x + 0.5) * sx - 0.5;
      at.qx = std::min(working.width - 1, static_cast<int>(at.x * sx));
      fn(at);
    }
  }
}

// Calls fn(nx, ny, d2) for the working pixels of the 3x3 around the place's
// q, d2 their squared distance to its centre f.
template <typename Fn>
void ForEachNeighbour(const WorkingPlace& at, cv::Size working, Fn fn) {
  for (int ny = std::max(0, at.qy - 1); ny <= std::min(working.height - 1, at.qy + 1); ++ny)
    for (int nx = std::max(0, at.qx - 1); nx <= std::min(working.width - 1, at.qx + 1); ++nx)
      fn(nx, ny, (nx - at.fx) * (nx - at.fx) + (ny - at.fy) * (ny - at.fy));
}

// The working maps must share one size, the camera-size maps another, and
// the labels and depth their types.
void CheckUpscaleMaps(const char* who, const std::vector<const cv::Mat*>& working,
                      const std::vector<const cv::Mat*>& camera, const cv::Mat& working_labels,
                      const cv::Mat& working_depth, const cv::Mat& labels, const cv::Mat& depth) {
  U4D_CHECK(working_labels.type() == CV_16UC1 && labels.type() == CV_16UC1 &&
                working_depth.type() == CV_32FC1 && depth.type() == CV_32FC1,
            "{}: labels must be CV_16U and depth CV_32F", who);
  bool same = true;
  for (const cv::Mat* m : working) same = same && m->size() == working_labels.size();
  for (const cv::Mat* m : camera) same = same && m->size() == labels.size();
  U4D_CHECK(same,
            "{}: the working maps ({}x{}) and the camera-size maps ({}x{}) must each have one size",
            who, working_labels.cols, working_labels.rows, labels.cols, labels.rows);
}

}  // namespace

void KeepInitialDetail(const cv::Mat& working_labels, const cv::Mat& working_depth,
                       const cv::Mat& initial_working, const cv::Mat& initial_full, cv::Mat* labels,
                       cv::Mat* depth) {
  CheckUpscaleMaps("KeepInitialDetail", {&working_depth, &initial_working}, {&initial_full, depth},
                   working_labels, working_depth, *labels, *depth);
  U4D_CHECK(initial_working.type() == CV_16UC1 && initial_full.type() == CV_16UC1,
            "KeepInitialDetail: the initial labels must be CV_16U");
  const cv::Size working = working_labels.size();
  // Working pixels whose 3x3 neighbourhood the solve left as it was given.
  cv::Mat kept;
  cv::erode(working_labels == initial_working, kept, cv::Mat::ones(3, 3, CV_8U), {-1, -1}, 1,
            cv::BORDER_REPLICATE);
  ForEachCameraPixel(working, labels->size(), [&](const WorkingPlace& at) {
    const int l = initial_full.at<uint16_t>(at.y, at.x);
    if (!kept.at<uint8_t>(at.qy, at.qx) || l == labels->at<uint16_t>(at.y, at.x)) return;
    // The nearest working pixel of the 3x3 holding label l.
    double best = 1e9;
    float z = 0;
    ForEachNeighbour(at, working, [&](int nx, int ny, double d2) {
      if (working_labels.at<uint16_t>(ny, nx) == l && d2 < best)
        best = d2, z = working_depth.at<float>(ny, nx);
    });
    if (best == 1e9) return;  // l not among the solve's labels there
    labels->at<uint16_t>(at.y, at.x) = static_cast<uint16_t>(l);
    depth->at<float>(at.y, at.x) = l == 0 ? 0.f : z;
  });
}

void GuidedLabels(const cv::Mat& working_labels, const cv::Mat& working_depth,
                  const cv::Mat& working_image, const cv::Mat& full_image, cv::Mat* labels,
                  cv::Mat* depth) {
  CheckUpscaleMaps("GuidedLabels", {&working_depth, &working_image}, {&full_image, depth},
                   working_labels, working_depth, *labels, *depth);
  U4D_CHECK(working_image.type() == CV_8UC3 && full_image.type() == CV_8UC3,
            "GuidedLabels: the images must be BGR 8-bit");
  const cv::Size working = working_labels.size();
  // β: the mean squared colour difference of neighbouring working pixels
  // (4-neighbours of the whole image; E_c's is over its 8-neighbour pairs).
  double sum = 0;
  long count = 0;
  for (int y = 0; y < working.height; ++y)
    for (int x = 0; x < working.width; ++x) {
      const cv::Vec3d c = working_image.at<cv::Vec3b>(y, x);
      if (x + 1 < working.width)
        sum += cv::norm(c - cv::Vec3d(working_image.at<cv::Vec3b>(y, x + 1)), cv::NORM_L2SQR),
            ++count;
      if (y + 1 < working.height)
        sum += cv::norm(c - cv::Vec3d(working_image.at<cv::Vec3b>(y + 1, x)), cv::NORM_L2SQR),
            ++count;
    }
  const double beta = std::max(1.0, count > 0 ? sum / count : 1.0);
  // Working pixels with another label among their 8 neighbours.
  cv::Mat lo, hi;
  cv::erode(working_labels, lo, cv::Mat::ones(3, 3, CV_8U), {-1, -1}, 1, cv::BORDER_REPLICATE);
  cv::dilate(working_labels, hi, cv::Mat::ones(3, 3, CV_8U), {-1, -1}, 1, cv::BORDER_REPLICATE);
  const cv::Mat boundary = lo != hi;
  ForEachCameraPixel(working, labels->size(), [&](const WorkingPlace& at) {
    if (!boundary.at<uint8_t>(at.qy, at.qx)) return;
    const cv::Vec3d colour = full_image.at<cv::Vec3b>(at.y, at.x);
    // Per label of the 9 working pixels: its summed weight, and the depth of
    // its heaviest pixel.
    struct Vote {
      int label;
      double weight, heaviest;
      float depth;
    };
    std::array<Vote, 9> votes;
    int num_votes = 0;
    ForEachNeighbour(at, working, [&](int nx, int ny, double d2) {
      const double c2 =
          cv::norm(colour - cv::Vec3d(working_image.at<cv::Vec3b>(ny, nx)), cv::NORM_L2SQR);
      const double w = std::exp(-0.5 * d2 - c2 / (2 * beta));
      const int l = working_labels.at<uint16_t>(ny, nx);
      Vote* v = std::find_if(votes.begin(), votes.begin() + num_votes,
                             [&](const Vote& e) { return e.label == l; });
      if (v == votes.begin() + num_votes) *v = {l, 0, -1, 0}, ++num_votes;
      v->weight += w;
      if (w > v->heaviest) v->heaviest = w, v->depth = working_depth.at<float>(ny, nx);
    });
    const Vote& win = *std::max_element(
        votes.begin(), votes.begin() + num_votes, [](const Vote& a, const Vote& b) {
          return a.weight < b.weight || (a.weight == b.weight && a.label > b.label);
        });
    labels->at<uint16_t>(at.y, at.x) = static_cast<uint16_t>(win.label);
    depth->at<float>(at.y, at.x) = win.label == 0 ? 0.f : win.depth;
  });
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
  for (int id : IdsIn(maps.labels)) mask.instances.push_back({id, ObjectClass(classes, id), 1.0});
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
