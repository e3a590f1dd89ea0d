// The one place U4D calls OpenCV's dense optical flow: the flow baselines
// (flow_baselines.h) and the joint optimisation's uses (flow fusion
// proposals, E_f's dense matches, the background flow, E_sem's label maps
// carried over time) all go through DenseFlow, so a method always runs with
// the same parameters wherever it is used.
#pragma once

#include <opencv2/core.hpp>

namespace u4d::baselines {

enum class DenseFlowMethod {
  // DeepFlow (Weinzaepfel et al. 2013), OpenCV contrib optflow, its defaults.
  kDeepFlow,
  // DIS (Kroeger et al. 2016), cv::DISOpticalFlow with PRESET_MEDIUM, nothing
  // else changed.
  kDisMedium,
  // DIS, PRESET_MEDIUM, then down to the finest pyramid scale
  // (setFinestScale(0)) with 10 variational refinement iterations.
  kDisFine,
  // cv::calcOpticalFlowFarneback with OpenCV's sample parameters (fback.cpp):
  // pyramid scale 0.5, 3 levels, window 15, 3 iterations, poly_n 5,
  // poly_sigma 1.2, no flags.
  kFarneback,
};

// Forward flow image_t -> image_t1 by `method`: CV_32FC2 of the images' size,
// (dx, dy) in pixels, pixel (x, y) of image_t moves to (x, y) + flow(x, y).
// The images are 8-bit, grey or BGR (converted to grey with
// cv::COLOR_BGR2GRAY; a grey image is used as it is), of one size; the flow
// is computed on the grey images, so a BGR pair and its grey pair give the
// same flow. Each call creates its own OpenCV algorithm object: no state is
// kept between calls, and calls may run concurrently. Throws u4d::Error on an
// empty image, one that is not 8-bit grey or BGR, or images of different sizes.
cv::Mat DenseFlow(DenseFlowMethod method, const cv::Mat& image_t, const cv::Mat& image_t1);

}  // namespace u4d::baselines
