// Writing one view's results of one frame into a 4D scene (io/layout.h,
// docs/formats.md "The 4D scene"): the joint optimisation runs at a working
// resolution, the scene's maps have the camera's size.
#pragma once

#include <map>
#include <string>

#include <opencv2/core.hpp>

#include "u4d/joint/joint_view.h"
#include "u4d/util/file.h"

namespace u4d {

// Camera-size maps of a view: CV_16U object ids, CV_32F z (0 = background or
// unknown), CV_32FC2 forward flow in camera pixels (zero where unknown).
struct ViewMaps {
  cv::Mat labels, depth, flow;
};

// Upscales a working-resolution result (scale = working / camera width):
// labels and depth by nearest neighbour (no depth mixed across a boundary),
// flow bilinearly with its vectors divided by `scale`. An empty flow (last
// frame) becomes zeros.
ViewMaps ToCameraSize(const JointViewResult& result, int width, int height, double scale);

// All-background maps of the camera's size (a view where no object projects).
ViewMaps EmptyViewMaps(int width, int height);

// instances/ (+ .json, each id's class from `classes`, object_classes.h's
// ObjectClass: "person" when not listed), depth/ (PFM), flow/ (.flo) and the
// pictures image/instances/depth/flow (picture_width wide, 0 = full size).
void WriteViewMaps(const fs::path& out, const std::string& view, int frame, const ViewMaps& maps,
                   const cv::Mat& image, int picture_width,
                   const std::map<int, std::string>& classes = {});

}  // namespace u4d
