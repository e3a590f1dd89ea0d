// Clean plates: the empty stage filmed from each camera before or after the
// take (docs/formats.md "Clean plates"). A capture may hold, per view,
//   background/<view>.png (or .jpg)        one picture of the empty stage, or
//   background/<view>/<any name>.png|jpg   frames of a short video of it,
//                                          read in name order.
// The unsupervised initial masks (init/init.h) then subtract the plate
// instead of a background taken from the capture's own frames, so that
// people who stay in place are found (BackgroundFromPlate).
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/util/file.h"

namespace u4d {

// The plate frames (BGR, CV_8UC3) of `view`, empty when the capture has no
// plate for it. Throws u4d::Error naming the file on an unreadable image or
// one whose size is not width x height, and on a plate folder with no image.
std::vector<cv::Mat> ReadCleanPlate(const fs::path& capture_root, const std::string& view,
                                    int width, int height);

}  // namespace u4d
