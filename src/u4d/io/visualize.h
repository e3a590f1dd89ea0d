// Pictures for people: instance ids, depth and optical flow as colour images
// (the viewer's overlays, docs, debugging). Every function returns an 8-bit
// BGR image (CV_8UC3, OpenCV's channel order, ready for WriteImage) of the
// input's size; colours passed in or returned as cv::Vec3b are RGB.
//
// Failure modes: an input of the wrong type or an empty input throws
// u4d::Error naming the function and what was found; so do a non-positive
// depth range or flow scale.
#pragma once

#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace u4d {

// A stable display colour (RGB) per instance id: 0 (background) is black,
// ids 1..10 take the Tableau-10 colours (blue, orange, green, red, purple,
// brown, pink, grey, olive, cyan), larger ids hues spaced by the golden angle
// at fixed saturation and value. The same id always gets the same colour.
cv::Vec3b InstanceColor(int id);

// CV_16U (or CV_8U) ids -> colours. Id k takes palette[k - 1] when the
// palette is non-empty and has an entry for k, else InstanceColor(k); 0 is
// black.
cv::Mat ColorizeInstances(const cv::Mat& ids16, const std::vector<cv::Vec3b>& palette_or_empty);

// CV_32F depth (z, metres) -> cv::COLORMAP_TURBO with `near` drawn red (the
// map's top end) and `far` blue (its bottom end), values clamped to
// [near, far]. 0, negative and non-finite values (unknown depth) are black.
// Requires 0 <= near < far.
cv::Mat ColorizeDepth(const cv::Mat& z32, double near, double far);

// CV_32FC2 flow (u, v pixels) -> the Middlebury colour wheel (Baker et al.,
// "A Database and Evaluation Methodology for Optical Flow", the colour code
// of its flow-code/computeColor): the hue is the direction, the saturation
// the magnitude relative to `max_magnitude` (white = no motion); a flow
// longer than max_magnitude is drawn with full saturation at 75% brightness.
// Non-finite vectors and |u| or |v| > 1e9 (the .flo "unknown" value) are
// black. Requires max_magnitude > 0.
cv::Mat ColorizeFlow(const cv::Mat& flow32fc2, double max_magnitude);

// The colour (RGB) ColorizeFlow gives the vector (u, v) for the scale
// max_magnitude; exposed for tests and legends.
cv::Vec3b FlowColor(float u, float v, double max_magnitude);

// Helpers for the viewer's pictures (`u4d run`, `u4d scene-from-gt`).

// `image` scaled to `width` pixels wide keeping the aspect ratio (area
// averaging, or nearest neighbour for ids and colourised maps); returned
// unchanged when width <= 0 or the image is not wider.
cv::Mat DownscaleToWidth(const cv::Mat& image, int width, bool nearest);

// A display range for a CV_32F depth map: the 2nd and 98th percentiles of
// its known (finite, > 0) depths widened by 5% of their spread (at least
// 5 mm), so that one far pixel does not wash out the people. (0, 10) when
// fewer than two depths are known.
std::pair<double, double> VisibleDepthRange(const cv::Mat& z32);

// The largest finite flow magnitude of a CV_32FC2 map over the pixels where
// `valid` (CV_8U, optional) is nonzero, at least 1 pixel.
double MaxFlowMagnitude(const cv::Mat& flow32fc2, const cv::Mat& valid);

}  // namespace u4d
