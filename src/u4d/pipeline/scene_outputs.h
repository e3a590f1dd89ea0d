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
// frame) becomes zeros. With the initial labels of the view at both sizes
// (`initial_working`, the solve's input, and `initial_full`, camera size;
// both CV_16U, or both empty = plain nearest neighbour) the labels keep the
// initial masks' detail where the solve kept them (KeepInitialDetail).
// With the view's image at both sizes (`working_image`, the solve's, and
// `full_image`; both BGR, or both empty) the labels are upscaled guided by
// the image first (GuidedLabels).
ViewMaps ToCameraSize(const JointViewResult& result, int width, int height, double scale,
                      const cv::Mat& initial_working = {}, const cv::Mat& initial_full = {},
                      const cv::Mat& working_image = {}, const cv::Mat& full_image = {});

// Joint bilateral upsampling of the labels (Kopf et al. 2007) near the
// solve's boundaries: a camera pixel whose working pixel has another label
// among its 8 neighbours takes the label of those 9 working pixels with the
// most weight exp(−d²/2 − |I − I_q|²/(2β)), d the distance in working pixels
// and I − I_q the colour difference between the camera pixel and the working
// pixel q (β: the mean squared colour difference of neighbouring working
// pixels, as E_c's); its depth is that of the heaviest working pixel of the
// label (0 for the background). A boundary the working resolution puts
// within a working pixel follows the colour edge at camera size. `labels`,
// `depth`: already upscaled by nearest neighbour, changed in place. Throws
// u4d::Error on mismatched sizes or types.
void GuidedLabels(const cv::Mat& working_labels, const cv::Mat& working_depth,
                  const cv::Mat& working_image, const cv::Mat& full_image, cv::Mat* labels,
                  cv::Mat* depth);

// The camera-size labels and depth of a working-resolution solve where the
// solve agreed with its input: the working resolution cannot hold a boundary
// finer than its pixel (a 2x downscale moves it by up to a camera pixel and
// makes a hand or a foot one or two working pixels wide), so a solve that
// kept perfect masks would give them back jagged. A camera pixel takes its
// `initial_full` label where the solve left its working pixel and the 8
// around it at their `initial_working` labels and that label is among the
// solve's labels of those 9 pixels; it then takes the depth of the nearest
// of them with that label (0 for the background). Elsewhere, and wherever
// the solve changed a label nearby, the nearest working pixel's label and
// depth (`labels`, `depth`: already upscaled by nearest neighbour, camera
// size, changed in place). Throws u4d::Error on mismatched sizes or types.
void KeepInitialDetail(const cv::Mat& working_labels, const cv::Mat& working_depth,
                       const cv::Mat& initial_working, const cv::Mat& initial_full, cv::Mat* labels,
                       cv::Mat* depth);

// All-background maps of the camera's size (a view where no object projects).
ViewMaps EmptyViewMaps(int width, int height);

// instances/ (+ .json, each id's class from `classes`, object_classes.h's
// ObjectClass: "person" when not listed), depth/ (PFM), flow/ (.flo) and the
// pictures image/instances/depth/flow (picture_width wide, 0 = full size).
void WriteViewMaps(const fs::path& out, const std::string& view, int frame, const ViewMaps& maps,
                   const cv::Mat& image, int picture_width,
                   const std::map<int, std::string>& classes = {});

}  // namespace u4d
