#include "u4d/eval/baseline_grabcut.h"

#include <atomic>

#include <tbb/parallel_for.h>

#include "u4d/io/frame_reader.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/layout.h"

namespace u4d::eval {

int WriteGrabCutPrediction(const Capture& capture, const fs::path& out,
                           const baselines::GrabCutOptions& options) {
  options.Check();
  FrameReader reader(capture);
  std::atomic<int> written = 0;
  // Views in parallel, each view's frames in order (FrameReader's contract).
  tbb::parallel_for(0, capture.NumViews(), [&](int v) {
    const std::string& view = capture.views[v].name;
    for (int f = 0; f < capture.num_frames; ++f) {
      const fs::path png = capture.root / layout::Mask(view, f);
      if (!fs::exists(png)) continue;
      InstanceMask mask = ReadInstanceMask(png, capture.root / layout::MaskInfo(view, f));
      mask.ids = baselines::GrabCutInstances(reader.Read(v, f), mask.ids, options);
      WriteInstanceMask(out / layout::GtInstances(view, f).lexically_relative("gt"),
                        out / layout::GtInstancesInfo(view, f).lexically_relative("gt"), mask);
      ++written;
    }
  });
  return written;
}

}  // namespace u4d::eval
