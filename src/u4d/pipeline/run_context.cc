#include "u4d/pipeline/run_context.h"

#include <tbb/parallel_for.h>

namespace u4d {

std::vector<cv::Mat> ReadViews(RunContext& c, int f) {
  std::vector<cv::Mat> images(c.NumViews());
  tbb::parallel_for(0, c.NumViews(), [&](int v) { images[v] = c.reader.Read(v, f); });
  return images;
}

}  // namespace u4d
