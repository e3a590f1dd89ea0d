// A view's stage for unsupervised masks (view_stage.h).
#include "u4d/pipeline/view_stage.h"

#include <algorithm>
#include <vector>

#include <fmt/format.h>

#include "u4d/io/clean_plate.h"

namespace u4d {

ViewStage ReadViewStage(const Capture& capture, int v,
                        const std::function<cv::Mat(int)>& read_frame,
                        const BackgroundOptions& background, const ChromaKeyOptions& chroma,
                        const std::function<cv::Mat(int)>& known_foreground) {
  const std::string& name = capture.views[v].name;
  ViewStage stage;
  if (chroma.mode != ChromaKeyOptions::Mode::kOff) {
    const int n = capture.num_frames, m = std::min(n, chroma.max_frames);
    std::vector<cv::Mat> frames;
    frames.reserve(static_cast<size_t>(std::max(m, 0)));
    for (int k = 0; k < m; ++k) frames.push_back(read_frame(m == 1 ? 0 : k * (n - 1) / (m - 1)));
    stage.key = ChooseChromaKey(frames, chroma, name);
    if (stage.key.keyed) {
      fmt::print("[initial] view {}: keyed backdrop (hue {:.0f} deg, {:.0f}% of the border)\n",
                 name, stage.key.HueDegrees(), 100 * stage.key.border_share);
      return stage;
    }
  }
  const Camera& cam = capture.views[v].CameraAt(0);
  const std::vector<cv::Mat> plate = ReadCleanPlate(capture.root, name, cam.width, cam.height);
  if (plate.empty()) {
    stage.background =
        EstimateBackground(capture.num_frames, read_frame, background, known_foreground);
  } else {
    fmt::print("[initial] view {}: background from its clean plate ({} frames)\n", name,
               plate.size());
    stage.background = BackgroundFromPlate(plate, capture.num_frames, read_frame, background);
  }
  return stage;
}

}  // namespace u4d
