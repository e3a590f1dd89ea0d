#include "u4d/pipeline/scene_outputs.h"

#include <set>

#include <opencv2/imgproc.hpp>

#include "u4d/io/image_io.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"
#include "u4d/io/visualize.h"
#include "u4d/pipeline/object_classes.h"
#include "u4d/util/check.h"

namespace u4d {

ViewMaps ToCameraSize(const JointViewResult& result, int width, int height, double scale) {
  U4D_CHECK(scale > 0 && scale <= 1, "ToCameraSize: scale must be in (0, 1], got {}", scale);
  U4D_CHECK(result.labels.type() == CV_16UC1 && result.depth.type() == CV_32FC1,
            "ToCameraSize: labels must be CV_16U and depth CV_32F");
  const cv::Size size(width, height);
  ViewMaps maps;
  cv::resize(result.labels, maps.labels, size, 0, 0, cv::INTER_NEAREST);
  cv::resize(result.depth, maps.depth, size, 0, 0, cv::INTER_NEAREST);
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
