#include "u4d/pipeline/unlabelled_objects.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include "u4d/util/check.h"

namespace u4d {

void UnlabelledObjectOptions::Check() const {
  U4D_CHECK(margin_px >= 0, "UnlabelledObjectOptions.margin_px must be >= 0, got {}", margin_px);
  U4D_CHECK(min_view_fraction > 0 && min_view_fraction <= 1,
            "UnlabelledObjectOptions.min_view_fraction must be in (0, 1], got {}",
            min_view_fraction);
  U4D_CHECK(min_area_fraction >= 0 && min_area_fraction < 1,
            "UnlabelledObjectOptions.min_area_fraction must be in [0, 1), got {}",
            min_area_fraction);
  U4D_CHECK(!class_name.empty(), "UnlabelledObjectOptions.class_name must not be empty");
}

namespace {

// The foreground of view v no given instance explains (before the cross-view check).
cv::Mat UnexplainedInView(const cv::Mat& image, const BackgroundModel* background,
                          const ChromaKey* key, const InstanceMask& given, const InitOptions& init,
                          const UnlabelledObjectOptions& options) {
  // No mask file: the detector did not run there (io/instance_mask.h), so
  // nothing there is known to be unexplained.
  if (given.ids.empty()) return cv::Mat::zeros(image.size(), CV_8U);
  U4D_CHECK(given.ids.size() == image.size(),
            "UnexplainedForeground: a mask of {}x{} for an image of {}x{}", given.ids.cols,
            given.ids.rows, image.cols, image.rows);
  cv::Mat foreground = key ? ChromaKeyMask(image, *key) : ForegroundMask(image, *background, init);
  foreground = foreground > 0;
  // Where a median background holds a person who has since moved (init.h step 5).
  if (!key && init.still.remove_ghosts)
    foreground = RemoveGhosts(image, foreground, *background, init);
  foreground.setTo(0, ExplainedPixels(given, options));
  return foreground;
}

}  // namespace

cv::Mat ExplainedPixels(const InstanceMask& given, const UnlabelledObjectOptions& options) {
  if (given.ids.empty()) return {};
  const int margin = options.margin_px > 0 ? options.margin_px : std::max(1, given.ids.rows / 60);
  cv::Mat explained;
  cv::dilate(given.ids > 0, explained,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * margin + 1, 2 * margin + 1}));
  return explained;
}

std::vector<cv::Mat> UnexplainedForeground(const std::vector<Camera>& cameras,
                                           const std::vector<cv::Mat>& images,
                                           const std::vector<BackgroundModel>& backgrounds,
                                           const std::vector<ChromaKey>& keys,
                                           const std::vector<InstanceMask>& given,
                                           const InitOptions& init,
                                           const UnlabelledObjectOptions& options) {
  options.Check();
  const size_t n = cameras.size();
  U4D_CHECK(images.size() == n && backgrounds.size() == n && given.size() == n &&
                (keys.empty() || keys.size() == n),
            "UnexplainedForeground: {} cameras, {} images, {} backgrounds, {} masks, {} keys", n,
            images.size(), backgrounds.size(), given.size(), keys.size());
  std::vector<cv::Mat> unexplained(n);
  tbb::parallel_for(size_t{0}, n, [&](size_t v) {
    const bool keyed = !keys.empty() && keys[v].keyed;
    unexplained[v] = UnexplainedInView(images[v], keyed ? nullptr : &backgrounds[v],
                                       keyed ? &keys[v] : nullptr, given[v], init, options);
  });
  InitOptions check = init;
  check.cross_view.enabled = true;
  check.cross_view.min_view_fraction = options.min_view_fraction;
  return CrossViewConsistentMasks(cameras, unexplained, check);
}

int AddUnlabelledObjects(const std::vector<cv::Mat>& unexplained,
                         const UnlabelledObjectOptions& options, std::vector<InstanceMask>* given) {
  options.Check();
  U4D_CHECK(unexplained.size() == given->size(),
            "AddUnlabelledObjects: {} unexplained masks for {} views", unexplained.size(),
            given->size());
  int added = 0;
  for (size_t v = 0; v < unexplained.size(); ++v) {
    InstanceMask& mask = (*given)[v];
    if (unexplained[v].empty() || mask.ids.empty()) continue;
    U4D_CHECK(unexplained[v].size() == mask.ids.size(),
              "AddUnlabelledObjects: view {}'s unexplained mask and instance mask differ in size",
              v);
    int next_id = 1;
    for (const InstanceInfo& info : mask.instances) next_id = std::max(next_id, info.id + 1);
    // One pass over the components' areas, one over the pixels.
    cv::Mat components, stats, centroids;
    const int num = cv::connectedComponentsWithStats(unexplained[v] > 0, components, stats,
                                                     centroids, 8, CV_32S);
    const double min_area = std::max(1.0, options.min_area_fraction * unexplained[v].total());
    std::vector<uint16_t> new_id(num, 0);
    for (int c = 1; c < num && next_id < 65536; ++c) {
      if (stats.at<int>(c, cv::CC_STAT_AREA) < min_area) continue;
      new_id[c] = static_cast<uint16_t>(next_id);
      mask.instances.push_back({next_id, options.class_name, 1.0});
      ++next_id, ++added;
    }
    for (int y = 0; y < components.rows; ++y)
      for (int x = 0; x < components.cols; ++x)
        if (const uint16_t id = new_id[components.at<int>(y, x)]) mask.ids.at<uint16_t>(y, x) = id;
  }
  return added;
}

}  // namespace u4d
