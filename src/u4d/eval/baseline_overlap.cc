#include "u4d/eval/baseline_overlap.h"

#include "u4d/io/frame_reader.h"

namespace u4d::eval {

std::map<std::string, RatioMean> BaselineSilhouetteOverlap(
    const Capture& capture, const std::vector<baselines::FlowBaseline>& flows,
    const EvalOptions& options) {
  FrameReader reader(capture);
  std::map<std::string, RatioMean> se;
  for (baselines::FlowBaseline b : flows)
    se[baselines::ToString(b)] = GtSilhouetteOverlap(
        capture,
        [&](int view, int frame) {
          return baselines::BaselineFlow(b, reader.Read(view, frame), reader.Read(view, frame + 1));
        },
        options);
  return se;
}

}  // namespace u4d::eval
