// Chroma key (chroma_key.h).
#include "u4d/init/chroma_key.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "u4d/util/check.h"

namespace u4d {
namespace {

constexpr double kSqrt3Half = 0.86602540378443864676;
constexpr double kDegrees = 180.0 / M_PI;

double HueOf(const Eigen::Vector2d& chroma) {
  return std::atan2(chroma.y(), chroma.x()) * kDegrees;
}

// |a - b| on the circle of degrees, in [0, 180].
double HueDistance(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 360.0);
  return d > 180.0 ? 360.0 - d : d;
}

double Median(std::vector<double> v) {
  U4D_ASSERT(!v.empty());
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The BGR of a colour name or #RRGGBB.
cv::Vec3b ParseColour(const std::string& name) {
  if (name == "green") return {0, 255, 0};
  if (name == "blue") return {255, 0, 0};
  U4D_CHECK(name.size() == 7 && name[0] == '#' &&
                name.find_first_not_of("0123456789abcdefABCDEF", 1) == std::string::npos,
            "ChromaKeyOptions.colour must be auto, green, blue or #RRGGBB, found '{}'", name);
  const auto byte = [&](int i) {
    return static_cast<uint8_t>(std::stoi(name.substr(1 + 2 * i, 2), nullptr, 16));
  };
  return {byte(2), byte(1), byte(0)};
}

struct BorderPixel {
  Eigen::Vector2d chroma;
  double brightness = 0;
};

// The pixels of the border bands of every frame.
std::vector<BorderPixel> BorderPixels(const std::vector<cv::Mat>& frames,
                                      const ChromaKeyOptions& options) {
  std::vector<BorderPixel> out;
  for (const cv::Mat& f : frames) {
    const int band =
        std::max(1, static_cast<int>(options.border_fraction * std::min(f.rows, f.cols)));
    for (int y = 0; y < f.rows; ++y) {
      const cv::Vec3b* p = f.ptr<cv::Vec3b>(y);
      const bool row_in = y < band || y >= f.rows - band;
      for (int x = 0; x < f.cols; ++x) {
        if (!row_in && x >= band && x < f.cols - band) continue;
        out.push_back({Chroma(p[x]), static_cast<double>(p[x][0]) + p[x][1] + p[x][2]});
      }
    }
  }
  return out;
}

// The hue whose window (+- tolerance / 2) holds most saturated pixels: the
// circular mean of the pixels in the best window of 5-degree bins.
double DominantHue(const std::vector<BorderPixel>& pixels, const ChromaKeyOptions& options) {
  constexpr int kBins = 72;
  std::vector<double> count(kBins, 0);
  for (const BorderPixel& p : pixels) {
    if (p.chroma.norm() < options.min_saturation) continue;
    const double h = HueOf(p.chroma) + 360.0;
    ++count[static_cast<int>(h / 5.0) % kBins];
  }
  const int half = std::max(0, static_cast<int>(options.hue_tolerance_deg / 10.0));
  int best = 0;
  double best_sum = -1;
  for (int b = 0; b < kBins; ++b) {
    double sum = 0;
    for (int d = -half; d <= half; ++d) sum += count[(b + d + kBins) % kBins];
    if (sum > best_sum) best_sum = sum, best = b;
  }
  return best * 5.0 + 2.5;
}

bool IsBackdrop(const Eigen::Vector2d& chroma, double brightness, const ChromaKey& key,
                double key_hue) {
  const ChromaKeyOptions& o = key.options;
  if (brightness < o.min_brightness * key.brightness) return false;
  const double saturation = chroma.norm();
  if (saturation <= 0) return false;
  const double dh = HueDistance(HueOf(chroma), key_hue);
  if (dh > o.hue_tolerance_deg) return false;
  return saturation * std::cos(dh / kDegrees) >= o.min_key_fraction * key.chroma.norm();
}

void CheckFrames(const std::vector<cv::Mat>& frames, const char* who) {
  U4D_CHECK(!frames.empty(), "{}: no frames given", who);
  for (size_t i = 0; i < frames.size(); ++i) {
    U4D_CHECK(!frames[i].empty() && frames[i].type() == CV_8UC3,
              "{}: frame {} is not a non-empty BGR image (CV_8UC3)", who, i);
    U4D_CHECK(frames[i].size() == frames[0].size(), "{}: frame {} is {}x{}, frame 0 {}x{}", who, i,
              frames[i].cols, frames[i].rows, frames[0].cols, frames[0].rows);
  }
}

}  // namespace

void ChromaKeyOptions::Check() const {
  U4D_CHECK(max_frames >= 1, "ChromaKeyOptions.max_frames must be >= 1, found {}", max_frames);
  U4D_CHECK(border_fraction > 0 && border_fraction <= 0.5,
            "ChromaKeyOptions.border_fraction must be in (0, 0.5], found {}", border_fraction);
  U4D_CHECK(min_saturation > 0 && min_saturation < 1,
            "ChromaKeyOptions.min_saturation must be in (0, 1), found {}", min_saturation);
  U4D_CHECK(hue_tolerance_deg > 0 && hue_tolerance_deg < 90,
            "ChromaKeyOptions.hue_tolerance_deg must be in (0, 90), found {}", hue_tolerance_deg);
  U4D_CHECK(min_key_fraction > 0 && min_key_fraction <= 1,
            "ChromaKeyOptions.min_key_fraction must be in (0, 1], found {}", min_key_fraction);
  U4D_CHECK(min_brightness >= 0 && min_brightness < 1,
            "ChromaKeyOptions.min_brightness must be in [0, 1), found {}", min_brightness);
  U4D_CHECK(min_border_share > 0 && min_border_share <= 1,
            "ChromaKeyOptions.min_border_share must be in (0, 1], found {}", min_border_share);
  if (colour != "auto") ParseColour(colour);
}

ChromaKeyOptions::Mode ChromaKeyModeFromString(const std::string& name) {
  if (name == "off") return ChromaKeyOptions::Mode::kOff;
  if (name == "auto") return ChromaKeyOptions::Mode::kAuto;
  if (name == "on") return ChromaKeyOptions::Mode::kOn;
  ThrowError(fmt::format("chroma key mode must be off, auto or on, found '{}'", name));
}

double ChromaKey::HueDegrees() const { return HueOf(chroma); }

Eigen::Vector2d Chroma(const cv::Vec3b& bgr) {
  const double b = bgr[0], g = bgr[1], r = bgr[2];
  const double s = r + g + b;
  if (s <= 0) return {0, 0};
  return Eigen::Vector2d(r - 0.5 * (g + b), kSqrt3Half * (g - b)) / s;
}

ChromaKey FindChromaKey(const std::vector<cv::Mat>& frames, const ChromaKeyOptions& options) {
  options.Check();
  CheckFrames(frames, "FindChromaKey");
  const std::vector<BorderPixel> border = BorderPixels(frames, options);
  const double hue = options.colour == "auto" ? DominantHue(border, options)
                                              : HueOf(Chroma(ParseColour(options.colour)));
  std::vector<double> cx, cy, brightness;
  for (const BorderPixel& p : border) {
    if (p.chroma.norm() < options.min_saturation) continue;
    if (HueDistance(HueOf(p.chroma), hue) > options.hue_tolerance_deg) continue;
    cx.push_back(p.chroma.x());
    cy.push_back(p.chroma.y());
    brightness.push_back(p.brightness);
  }
  ChromaKey key;
  key.options = options;
  key.border_pixels = static_cast<int>(border.size());
  if (cx.empty()) return key;
  key.chroma = {Median(cx), Median(cy)};
  key.brightness = Median(brightness);
  const double key_hue = key.HueDegrees();
  int backdrop = 0;
  for (const BorderPixel& p : border) backdrop += IsBackdrop(p.chroma, p.brightness, key, key_hue);
  key.border_share = static_cast<double>(backdrop) / static_cast<double>(border.size());
  return key;
}

ChromaKey ChooseChromaKey(const std::vector<cv::Mat>& frames, const ChromaKeyOptions& options,
                          const std::string& view) {
  options.Check();
  if (options.mode == ChromaKeyOptions::Mode::kOff) return ChromaKey{};
  ChromaKey key = FindChromaKey(frames, options);
  if (options.mode == ChromaKeyOptions::Mode::kOn) {
    U4D_CHECK(key.border_share > 0,
              "view {}: chroma key on, but no saturated pixel of the backdrop's colour ({}) at "
              "the image border (lower chroma_key.min_saturation or give chroma_key.colour)",
              view, options.colour);
    key.keyed = true;
  } else {
    key.keyed = key.border_share >= options.min_border_share;
  }
  return key;
}

cv::Mat ChromaKeyMask(const cv::Mat& image_bgr, const ChromaKey& key) {
  CheckFrames({image_bgr}, "ChromaKeyMask");
  U4D_CHECK(key.chroma.norm() > 0, "ChromaKeyMask: the key has no colour (none was found)");
  const double key_hue = key.HueDegrees();
  cv::Mat fg(image_bgr.size(), CV_8UC1);
  tbb::parallel_for(0, image_bgr.rows, [&](int y) {
    const cv::Vec3b* p = image_bgr.ptr<cv::Vec3b>(y);
    uint8_t* out = fg.ptr<uint8_t>(y);
    for (int x = 0; x < image_bgr.cols; ++x) {
      const double s = static_cast<double>(p[x][0]) + p[x][1] + p[x][2];
      out[x] = IsBackdrop(Chroma(p[x]), s, key, key_hue) ? 0 : 255;
    }
  });
  return fg;
}

}  // namespace u4d
