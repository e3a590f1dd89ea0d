// Chroma key: silhouettes on green- or blue-screen stages (docs/init.md
// "Keyed stages"), in place of a background model.
//
// Colour. A pixel's chroma is its rgb chromaticity in the hue plane,
//   p = (r - (g + b) / 2, sqrt(3) / 2 (g - b)) / (r + g + b),
// hue = atan2(p.y, p.x) (red 0 deg, green 120, blue 240), saturation |p|.
// Scaling r, g, b together (a shadow, an exposure change) leaves p
// unchanged: the key is on chroma, not on luminance.
//
// The backdrop colour (FindChromaKey). Pixels in a band along the image
// border (border_fraction x the shorter side) of a few frames whose
// saturation is at least min_saturation vote for their hue; the hue window
// of width hue_tolerance_deg holding most votes is the backdrop's hue (or
// the hue of ChromaKeyOptions::colour when one is given). The key is the
// per-component median chroma and the median brightness (r + g + b) of the
// saturated border pixels within hue_tolerance_deg of it. Its border share
// is the share of all border pixels the key classifies as backdrop.
//
// Backdrop (ChromaKeyMask). A pixel is backdrop when its hue is within
// hue_tolerance_deg of the key's, its chroma along the key's direction is at
// least min_key_fraction of the key's saturation, and its brightness is at
// least min_brightness x the key's. Hence
//  - shadows on the backdrop (darker, same chroma) are backdrop;
//  - spill (the backdrop's light reflected on people: a moderate excess of
//    the key colour) stays foreground: on a non-key hue (skin, red) the hue
//    test fails, on a grey or white surface the excess is a small fraction
//    of the backdrop's saturation;
//  - very dark pixels (hair, black clothes, whose chroma is noise) are
//    foreground;
//  - clothes of the backdrop's own colour are backdrop (as in any keyer).
//
// When a view is keyed (ChooseChromaKey): mode off never; on always (the
// backdrop colour must be found at the border); auto when the key's border
// share is at least min_border_share, i.e. the border is dominated by one
// saturated hue, as on a stage whose walls and floor are the screen.
//
// Throws u4d::Error on empty or non-BGR images, differing sizes, bad
// options (naming the field), an unparsable colour, and (mode on) a view
// whose border holds no saturated pixel of the backdrop's hue.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace u4d {

struct ChromaKeyOptions {
  enum class Mode { kOff, kAuto, kOn };
  Mode mode = Mode::kAuto;          // off, auto (key views whose border is the backdrop), on
  std::string colour = "auto";      // backdrop colour: auto (found), green, blue or #RRGGBB
  int max_frames = 5;               // frames sampled (evenly) to find the backdrop colour
  double border_fraction = 0.08;    // border band width (x the image's shorter side)
  double min_saturation = 0.15;     // saturated: |chroma| >= this (grey 0, pure primary 1)
  double hue_tolerance_deg = 30.0;  // backdrop hue +- this
  double min_key_fraction = 0.5;    // backdrop: chroma along the key >= this x the key's
  double min_brightness = 0.1;      // backdrop: r + g + b >= this x the key's
  double min_border_share = 0.6;    // auto: key a view when this share of its border is backdrop

  void Check() const;  // throws u4d::Error naming the offending field
};

// Mode names: "off", "auto", "on" (throws on another).
ChromaKeyOptions::Mode ChromaKeyModeFromString(const std::string& name);

struct ChromaKey {
  bool keyed = false;            // the view is keyed (ChooseChromaKey's decision)
  Eigen::Vector2d chroma{0, 0};  // the backdrop's chroma (above)
  double brightness = 0;         // the backdrop's median r + g + b (8-bit units)
  double border_share = 0;       // share of the border classified as backdrop
  int border_pixels = 0;         // pixels in the sampled border bands
  ChromaKeyOptions options;      // the tolerances ChromaKeyMask applies

  double HueDegrees() const;
};

// The chroma of a BGR colour (above); zero for black.
Eigen::Vector2d Chroma(const cv::Vec3b& bgr);

// The backdrop colour from `frames` (BGR, same size) as above; `keyed` is
// left false. A key with chroma 0 and border_share 0 when no border pixel
// is saturated in the wanted hue.
ChromaKey FindChromaKey(const std::vector<cv::Mat>& frames, const ChromaKeyOptions& options);

// FindChromaKey with the decision of the mode (above) in `keyed`. `view`
// names the view in errors.
ChromaKey ChooseChromaKey(const std::vector<cv::Mat>& frames, const ChromaKeyOptions& options,
                          const std::string& view);

// CV_8UC1, 255 where `image_bgr` is not backdrop (foreground), 0 on the
// backdrop; not cleaned (the init chain cleans it as its step 2).
cv::Mat ChromaKeyMask(const cv::Mat& image_bgr, const ChromaKey& key);

}  // namespace u4d
