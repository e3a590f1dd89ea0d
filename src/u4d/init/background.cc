// Background model and foreground masks (init.h, steps 1 and 2).
#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include "u4d/init/init.h"
#include "u4d/init/init_internal.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

// Median of a 3-dof chi distribution (distance of 3-channel Gaussian noise of
// unit std): converts a median distance into a per-channel noise level.
constexpr double kChi3Median = 1.5382;

void CheckFrame(const cv::Mat& frame, const std::string& what) {
  U4D_CHECK(!frame.empty(), "{}: empty image", what);
  U4D_CHECK(frame.type() == CV_8UC3, "{}: expected a BGR image (CV_8UC3), found type {}", what,
            frame.type());
}

// Indices of up to m frames spread evenly over [0, n).
std::vector<int> SampleIndices(int n, int m) {
  std::vector<int> out;
  if (n <= m) {
    for (int i = 0; i < n; ++i) out.push_back(i);
    return out;
  }
  for (int k = 0; k < m; ++k) {
    const int i = static_cast<int>(std::lround((k + 0.5) * n / m - 0.5));
    if (out.empty() || out.back() != i) out.push_back(std::clamp(i, 0, n - 1));
  }
  return out;
}

// Per pixel, the median of `labs` over the frames whose `known[i]` (empty:
// none) does not hold the pixel; over all frames where every frame holds it.
BackgroundModel MedianOfLab(const std::vector<cv::Mat>& labs, const std::vector<cv::Mat>& known) {
  const int n = static_cast<int>(labs.size());
  const int rows = labs[0].rows, cols = labs[0].cols;
  BackgroundModel model;
  model.lab.create(rows, cols, CV_8UC3);
  model.pixel_sigma.create(rows, cols, CV_32FC1);
  model.frames_used = n;
  tbb::parallel_for(0, rows, [&](int y) {
    // Row pointers, once per row: the frames' pixels and their known masks
    // (nullptr: nothing known in that frame).
    std::vector<const cv::Vec3b*> row(n), in(n);
    std::vector<const uint8_t*> known_row(n, nullptr);
    for (int i = 0; i < n; ++i) {
      row[i] = labs[i].ptr<cv::Vec3b>(y);
      if (!known.empty() && !known[i].empty()) known_row[i] = known[i].ptr<uint8_t>(y);
    }
    std::vector<uint8_t> v(n);
    std::vector<float> d(n);
    cv::Vec3b* out = model.lab.ptr<cv::Vec3b>(y);
    float* sig = model.pixel_sigma.ptr<float>(y);
    for (int x = 0; x < cols; ++x) {
      int m = 0;
      for (int i = 0; i < n; ++i)
        if (!known_row[i] || !known_row[i][x]) in[m++] = row[i] + x;
      if (m == 0)
        for (int i = 0; i < n; ++i) in[m++] = row[i] + x;
      for (int c = 0; c < 3; ++c) {
        for (int i = 0; i < m; ++i) v[i] = (*in[i])[c];
        std::nth_element(v.begin(), v.begin() + m / 2, v.begin() + m);
        out[x][c] = v[m / 2];
      }
      for (int i = 0; i < m; ++i) d[i] = LabDistance(*in[i], out[x]);
      std::nth_element(d.begin(), d.begin() + m / 2, d.begin() + m);
      sig[x] = static_cast<float>(d[m / 2] / kChi3Median);
    }
  });
  // Global noise level: the median of the per-pixel levels (histogram, 0.05 bins).
  std::vector<long> hist(4096, 0);
  for (int y = 0; y < rows; ++y) {
    const float* s = model.pixel_sigma.ptr<float>(y);
    for (int x = 0; x < cols; ++x) ++hist[std::min(4095, static_cast<int>(s[x] * 20.0f))];
  }
  const long half = static_cast<long>(rows) * cols / 2;
  long acc = 0;
  for (int b = 0; b < 4096; ++b) {
    acc += hist[b];
    if (acc > half) {
      model.sigma = (b + 0.5) / 20.0;
      break;
    }
  }
  cv::cvtColor(model.lab, model.bgr, cv::COLOR_Lab2BGR);
  return model;
}

cv::Mat ToLab(const cv::Mat& bgr) {
  cv::Mat lab;
  cv::cvtColor(bgr, lab, cv::COLOR_BGR2Lab);
  return lab;
}

// Up to options.max_frames frames, evenly spread, in Lab.
std::vector<cv::Mat> SampledLabs(int num_frames, const std::function<cv::Mat(int)>& read_frame,
                                 const BackgroundOptions& options, const std::string& who) {
  U4D_CHECK(num_frames >= 1, "{}: expected at least one frame, found {}", who, num_frames);
  U4D_CHECK(static_cast<bool>(read_frame), "{}: no frame reader given", who);
  std::vector<cv::Mat> labs;
  for (const int i : SampleIndices(num_frames, options.max_frames)) {
    const cv::Mat frame = read_frame(i);
    CheckFrame(frame, fmt::format("{}: frame {}", who, i));
    if (!labs.empty()) {
      U4D_CHECK(frame.size() == labs[0].size(),
                "{}: frame {} is {}x{}, the first sampled frame is {}x{}", who, i, frame.cols,
                frame.rows, labs[0].cols, labs[0].rows);
    }
    labs.push_back(ToLab(frame));
  }
  return labs;
}

// known_foreground(i) of the frames SampledLabs samples (CV_8U, the size of
// `labs[0]`); none without a function.
std::vector<cv::Mat> SampledKnown(int num_frames,
                                  const std::function<cv::Mat(int)>& known_foreground,
                                  const BackgroundOptions& options, const cv::Size& size) {
  std::vector<cv::Mat> known;
  if (!known_foreground) return known;
  for (const int i : SampleIndices(num_frames, options.max_frames)) {
    cv::Mat mask = known_foreground(i);
    U4D_CHECK(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == size),
              "EstimateBackground: frame {}'s known foreground is not a {}x{} CV_8U mask", i,
              size.width, size.height);
    known.push_back(std::move(mask));
  }
  return known;
}

// Per pixel, whether at least envelope_min_frames of `labs` have it in their
// (cleaned) foreground against `model`.
cv::Mat Envelope(const std::vector<cv::Mat>& labs, const BackgroundModel& model,
                 const BackgroundOptions& options) {
  const InitOptions fg_options;
  cv::Mat count = cv::Mat::zeros(model.lab.size(), CV_16UC1);
  for (const cv::Mat& lab : labs)
    cv::add(count, ForegroundFromLab(lab, model, fg_options) / 255, count, cv::noArray(), CV_16UC1);
  return count >= options.envelope_min_frames;
}

// Fewer plate frames than this cannot tell noise per pixel: the noise level
// then comes from the take (below).
constexpr int kMinPlateFramesForNoise = 3;

// The global noise level from the take's frames against the plate: per
// pixel the median distance over the frames, then the median over pixels
// (people cover a minority of the pixels, so the median sees the noise).
// No per-pixel level: where a person stays in place, the take's distance is
// the person, not noise.
void TakeNoise(const std::vector<cv::Mat>& labs, BackgroundModel* model) {
  const int n = static_cast<int>(labs.size());
  const int rows = model->lab.rows, cols = model->lab.cols;
  cv::Mat per_pixel(rows, cols, CV_32FC1);
  tbb::parallel_for(0, rows, [&](int y) {
    std::vector<float> d(n);
    const cv::Vec3b* bg = model->lab.ptr<cv::Vec3b>(y);
    float* out = per_pixel.ptr<float>(y);
    for (int x = 0; x < cols; ++x) {
      for (int i = 0; i < n; ++i) d[i] = LabDistance(labs[i].ptr<cv::Vec3b>(y)[x], bg[x]);
      std::nth_element(d.begin(), d.begin() + n / 2, d.end());
      out[x] = d[n / 2];
    }
  });
  std::vector<float> all(per_pixel.begin<float>(), per_pixel.end<float>());
  std::nth_element(all.begin(), all.begin() + all.size() / 2, all.end());
  model->sigma = all[all.size() / 2] / kChi3Median;
  model->pixel_sigma = cv::Mat::zeros(rows, cols, CV_32FC1);
}

}  // namespace

void BackgroundOptions::Check() const {
  U4D_CHECK(max_frames >= 1, "BackgroundOptions.max_frames must be >= 1, found {}", max_frames);
  U4D_CHECK(envelope_min_frames >= 1,
            "BackgroundOptions.envelope_min_frames must be >= 1, found {}", envelope_min_frames);
}

BackgroundModel EstimateBackground(int num_frames, const std::function<cv::Mat(int)>& read_frame,
                                   const BackgroundOptions& options,
                                   const std::function<cv::Mat(int)>& known_foreground) {
  options.Check();
  const std::vector<cv::Mat> labs =
      SampledLabs(num_frames, read_frame, options, "EstimateBackground");
  BackgroundModel model =
      MedianOfLab(labs, SampledKnown(num_frames, known_foreground, options, labs[0].size()));
  if (options.envelope) model.envelope = Envelope(labs, model, options);
  return model;
}

BackgroundModel BackgroundFromPlate(const std::vector<cv::Mat>& plate, int num_frames,
                                    const std::function<cv::Mat(int)>& read_frame,
                                    const BackgroundOptions& options) {
  options.Check();
  U4D_CHECK(!plate.empty(), "BackgroundFromPlate: no clean-plate frame given");
  // All the plate's frames (up to max_frames), checked as the take's are.
  const std::vector<cv::Mat> plate_labs = SampledLabs(
      static_cast<int>(plate.size()), [&](int i) { return plate[i]; }, options,
      "BackgroundFromPlate: clean plate");
  BackgroundModel model = MedianOfLab(plate_labs, {});
  const std::vector<cv::Mat> labs =
      SampledLabs(num_frames, read_frame, options, "BackgroundFromPlate");
  U4D_CHECK(labs[0].size() == plate_labs[0].size(),
            "BackgroundFromPlate: the frames are {}x{}, the clean plate {}x{}", labs[0].cols,
            labs[0].rows, plate_labs[0].cols, plate_labs[0].rows);
  if (static_cast<int>(plate_labs.size()) < kMinPlateFramesForNoise) TakeNoise(labs, &model);
  if (options.envelope) model.envelope = Envelope(labs, model, options);
  return model;
}

BackgroundModel EstimateBackground(const std::vector<cv::Mat>& frames,
                                   const BackgroundOptions& options) {
  U4D_CHECK(!frames.empty(), "EstimateBackground: no frames given");
  return EstimateBackground(
      static_cast<int>(frames.size()), [&](int i) { return frames[i]; }, options);
}

cv::Mat ForegroundMask(const cv::Mat& image_bgr, const BackgroundModel& background,
                       const InitOptions& options) {
  options.Check();
  CheckFrame(image_bgr, "ForegroundMask: image");
  U4D_CHECK(!background.Empty(), "ForegroundMask: empty background model");
  U4D_CHECK(image_bgr.size() == background.lab.size(),
            "ForegroundMask: image is {}x{} but its background is {}x{}", image_bgr.cols,
            image_bgr.rows, background.Width(), background.Height());
  cv::Mat lab;
  cv::cvtColor(image_bgr, lab, cv::COLOR_BGR2Lab);
  return ForegroundFromLab(lab, background, options);
}

cv::Mat ForegroundFromLab(const cv::Mat& lab, const BackgroundModel& background,
                          const InitOptions& options) {
  const double global = std::max(background.sigma, options.foreground.min_noise_sigma);
  cv::Mat fg(lab.size(), CV_8UC1, cv::Scalar(0));
  tbb::parallel_for(0, lab.rows, [&](int y) {
    const cv::Vec3b* p = lab.ptr<cv::Vec3b>(y);
    const cv::Vec3b* b = background.lab.ptr<cv::Vec3b>(y);
    const float* ps = background.pixel_sigma.ptr<float>(y);
    uint8_t* out = fg.ptr<uint8_t>(y);
    for (int x = 0; x < lab.cols; ++x) {
      const double noise = std::max(global, static_cast<double>(ps[x]));
      const double d = LabDistance(p[x], b[x]);
      if (d <= options.foreground.threshold_sigmas * noise) continue;
      if (options.foreground.suppress_shadows && b[x][0] > 0) {
        const double ratio = static_cast<double>(p[x][0]) / b[x][0];
        const double da = static_cast<double>(p[x][1]) - b[x][1];
        const double db = static_cast<double>(p[x][2]) - b[x][2];
        if (ratio >= options.foreground.shadow_min_ratio &&
            ratio <= options.foreground.shadow_max_ratio &&
            std::sqrt(da * da + db * db) <= options.foreground.shadow_chroma_sigmas * noise) {
          continue;
        }
      }
      out[x] = 255;
    }
  });
  return CleanMask(fg, options);
}

cv::Mat CleanMask(const cv::Mat& mask, const InitOptions& options) {
  const int r = options.foreground.morph_radius_px > 0 ? options.foreground.morph_radius_px
                                                       : std::max(1, (mask.rows + 180) / 360);
  const cv::Mat kernel =
      cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  cv::Mat m;
  cv::morphologyEx(mask, m, cv::MORPH_OPEN, kernel);
  cv::morphologyEx(m, m, cv::MORPH_CLOSE, kernel);
  const double min_area = options.foreground.min_blob_fraction * mask.total();
  RemoveSmallComponents(m, min_area);
  // Fill small holes: small background components.
  cv::Mat holes = 255 - m;
  RemoveSmallComponents(holes, min_area);
  return 255 - holes;
}

void RemoveSmallComponents(cv::Mat& mask, double min_area) {
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  std::vector<uint8_t> keep(n, 0);
  for (int i = 1; i < n; ++i) keep[i] = stats.at<int>(i, cv::CC_STAT_AREA) >= min_area;
  for (int y = 0; y < mask.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    uint8_t* m = mask.ptr<uint8_t>(y);
    for (int x = 0; x < mask.cols; ++x) m[x] = (l[x] > 0 && keep[l[x]]) ? 255 : 0;
  }
}

}  // namespace u4d
