// GrabCut refinement of initial instance masks: the segmentation baseline the
// joint optimisation's instance labels are compared against (paper Sec. 4).
//
// Each instance of the initial id image is refined independently by
// cv::grabCut (Rother et al. 2004, GMM colour models + graph cut) inside its
// bounding box padded by pad_px, seeded from its mask: pixels of the mask are
// probable foreground, pixels within band_px outside it probable background,
// everything farther (and every pixel of another initial instance, unless
// others_probable_background) definite background. Where refined instances
// overlap, a pixel goes to the instance whose original mask holds it, else to
// the one whose foreground GMM gives its colour the larger likelihood. An
// instance whose GrabCut fails (OpenCV rejects a seed with no foreground or
// no background sample) or returns an empty foreground keeps its initial mask.
#pragma once

#include <opencv2/core.hpp>

namespace u4d::baselines {

struct GrabCutOptions {
  int iterations = 5;  // cv::grabCut iterations per instance (>= 1)
  int band_px = 15;    // width of the probable-background band around each mask (>= 1)
  int pad_px = 30;     // padding of each instance's box (pixels, >= band_px)
  bool others_probable_background = false;  // other instances' pixels: probable (true) or
                                            // definite (false) background
  void Check() const;                       // throws u4d::Error naming the bad field
};

// `image` BGR 8-bit; `initial_ids` CV_16UC1 of the same size (0 = background).
// Returns CV_16UC1 ids, each an id of initial_ids (an instance may vanish only
// by losing every pixel to overlapping instances). Throws u4d::Error on bad
// options, an empty image, wrong types or mismatched sizes.
cv::Mat GrabCutInstances(const cv::Mat& image, const cv::Mat& initial_ids,
                         const GrabCutOptions& options = {});

}  // namespace u4d::baselines
