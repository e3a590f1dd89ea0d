// What a static view's stage gives the unsupervised initial masks (init.h)
// when the capture has no masks: a chroma key (init/chroma_key.h) on a
// green- or blue-screen stage, else a background model from the view's
// clean plate (io/clean_plate.h) when the capture has one, else from the
// capture's own frames. Order and choice: docs/init.md "Keyed stages".
#pragma once

#include <functional>
#include <string>

#include <opencv2/core.hpp>

#include "u4d/init/init.h"
#include "u4d/io/capture.h"

namespace u4d {

struct ViewStage {
  ChromaKey key;               // key.keyed: the view is keyed, `background` is empty
  BackgroundModel background;  // when not keyed
};

// View `v` of `capture` (static), frame f read by `read_frame(f)`. The key
// is chosen (ChooseChromaKey) from up to chroma.max_frames frames spread
// evenly over the capture unless chroma.mode is off. Without a clean plate,
// `known_foreground` (may be empty) tells the median which pixels of frame f
// a given mask covers (EstimateBackground). Prints one line per keyed view or
// clean plate used. Throws what its steps throw.
ViewStage ReadViewStage(const Capture& capture, int v,
                        const std::function<cv::Mat(int)>& read_frame,
                        const BackgroundOptions& background, const ChromaKeyOptions& chroma,
                        const std::function<cv::Mat(int)>& known_foreground = {});

}  // namespace u4d
