// Instance segmentation of one image: a label image plus what each id means.
// On disk: a 16-bit PNG of ids (0 = background) and a JSON sidecar
//   {"instances": [{"id": 1, "class": "person", "score": 0.93}, ...]}
// Ids need not be contiguous; an id in the image without a sidecar entry is
// an error when read (it would be a silent wrong answer otherwise).
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/util/file.h"

namespace u4d {

struct InstanceInfo {
  int id = 0;                    // >= 1, the value in the label image
  std::string label = "person";  // class name
  double score = 1.0;            // detector confidence in [0, 1]
};

struct InstanceMask {
  cv::Mat ids;  // CV_16UC1
  std::vector<InstanceInfo> instances;

  const InstanceInfo* Find(int id) const;
};

// Reads `png` and its sidecar `json`. Throws naming the file on a missing
// file, a corrupt image, a bad sidecar, or an id present in the image but
// not in the sidecar.
InstanceMask ReadInstanceMask(const fs::path& png, const fs::path& json);
// The sidecar alone (what each id means, without the image), checked as
// above: throws naming the file on a missing file, bad JSON, a bad field, an
// id out of range or listed twice.
std::vector<InstanceInfo> ReadInstanceInfo(const fs::path& json);
void WriteInstanceMask(const fs::path& png, const fs::path& json, const InstanceMask& mask);

// CV_32F of the mask's size: each pixel the score of the instance it holds,
// 1 on the background and on ids without an entry. Empty ids: empty.
cv::Mat ScoreImage(const InstanceMask& mask);

}  // namespace u4d
