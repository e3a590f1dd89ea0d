// The silhouette overlap error S_e of the dense-flow baselines against the
// ground truth (paper Sec. 4, Table "Silhouette overlap error": propagation by
// DeepFlow and others against the method's own motion): the capture's GT
// instance masks at each key-frame, carried through the key-frame's segment by
// OpenCV's DeepFlow, DIS or Farneback computed on the capture's images, against
// the GT masks (GtSilhouetteOverlap, evaluate.h; the same protocol
// `u4d eval` applies to a prediction's flow, so the figures sit side by side).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "u4d/baselines/flow_baselines.h"
#include "u4d/eval/evaluate.h"

namespace u4d::eval {

// S_e per baseline flow, keyed by baselines::ToString(flow). Reads the images with a
// FrameReader (a missing or corrupt frame throws u4d::Error naming it) and
// the GT instances under <capture.root>/gt (missing: u4d::Error naming it).
std::map<std::string, RatioMean> BaselineSilhouetteOverlap(
    const Capture& capture, const std::vector<baselines::FlowBaseline>& flows,
    const EvalOptions& options = {});

}  // namespace u4d::eval
