// The segmentation baseline of the paper's IoU tables as a prediction that
// `u4d eval` reads: each view-frame's initial masks (masks/) refined by
// GrabCut (baselines/grabcut_baseline.h), laid out like <capture>/gt
// (instances/<view>/<frame>.png and .json, each instance keeping the class
// and score of the initial instance it came from). A view-frame without an
// initial mask has no prediction (a dropped detection, as `--initial`).
#pragma once

#include "u4d/baselines/grabcut_baseline.h"
#include "u4d/io/capture.h"
#include "u4d/util/file.h"

namespace u4d::eval {

// Writes the GrabCut prediction of `capture` under `out` (created); returns
// the view-frames written. Throws u4d::Error naming a missing or corrupt
// frame or mask.
int WriteGrabCutPrediction(const Capture& capture, const fs::path& out,
                           const baselines::GrabCutOptions& options = {});

}  // namespace u4d::eval
