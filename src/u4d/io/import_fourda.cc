#include "u4d/io/import_fourda.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "u4d/util/check.h"

namespace u4d {
namespace {

// Whitespace-separated tokens of a text file, read with errors that name the
// file and what was being read.
class TokenReader {
 public:
  explicit TokenReader(const fs::path& path) : path_(path.string()), in_(ReadTextFile(path)) {}

  double Number(const std::string& what) {
    std::string token;
    U4D_CHECK(static_cast<bool>(in_ >> token), "{}: file ends while reading {} (truncated?)", path_,
              what);
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    U4D_CHECK(end != token.c_str() && *end == '\0', "{}: {}: expected a number, found '{}'", path_,
              what, token);
    U4D_CHECK(std::isfinite(v), "{}: {}: value is not finite ('{}')", path_, what, token);
    return v;
  }

  int Count(const std::string& what, int max_value) {
    const double v = Number(what);
    U4D_CHECK(v >= 0 && v <= max_value && v == std::floor(v),
              "{}: {}: expected a count in [0, {}], found {}", path_, what, max_value, v);
    return static_cast<int>(v);
  }

  void ExpectEnd() {
    std::string token;
    U4D_CHECK(!(in_ >> token), "{}: unexpected text after the last frame: '{}'", path_, token);
  }

  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::istringstream in_;
};

// OpenPose BODY25 limbs (part-affinity fields) as joint pairs, in the order
// 4D Association writes them.
constexpr int kBody25Joints = 25;
constexpr int kBody25Limbs = 26;
constexpr int kBody25LimbA[kBody25Limbs] = {1, 9, 10, 8, 8, 12, 13, 1,  2,  3,  2,  1,  5,
                                            6, 5, 1,  0, 0, 15, 16, 14, 19, 14, 11, 22, 11};
constexpr int kBody25LimbB[kBody25Limbs] = {8, 10, 11, 9,  12, 13, 14, 2,  3,  4,  17, 5,  6,
                                            7, 18, 0,  15, 16, 17, 18, 19, 20, 21, 22, 23, 24};

}  // namespace

FourdaGroundTruth ReadFourdaGroundTruth(const fs::path& path) {
  TokenReader in(path);
  FourdaGroundTruth gt;
  gt.num_joints = in.Count("the joint count", 1000);
  U4D_CHECK(gt.num_joints > 0, "{}: the joint count must be positive", in.path());
  const int frames = in.Count("the frame count", 10000000);
  gt.frames.resize(frames);
  for (int f = 0; f < frames; ++f) {
    const int people = in.Count(fmt::format("frame {}: the person count", f), 1000);
    for (int p = 0; p < people; ++p) {
      FourdaPerson3d person;
      person.id = in.Count(fmt::format("frame {} person {}: the id", f, p), 1000000);
      person.joints.resize(4, gt.num_joints);
      for (int r = 0; r < 4; ++r)
        for (int j = 0; j < gt.num_joints; ++j)
          person.joints(r, j) = in.Number(fmt::format("frame {} person {} row {}", f, p, r));
      gt.frames[f].push_back(std::move(person));
    }
  }
  in.ExpectEnd();
  return gt;
}

FourdaDetections ReadFourdaDetections(const fs::path& path) {
  TokenReader in(path);
  FourdaDetections det;
  det.skel_type = in.Count("the skeleton type", 100);
  U4D_CHECK(det.skel_type == 4, "{}: only skeleton type 4 (BODY25) is supported, found {}",
            in.path(), det.skel_type);
  const int frames = in.Count("the frame count", 10000000);
  det.frames.resize(frames);
  for (int f = 0; f < frames; ++f) {
    FourdaDetectionFrame& frame = det.frames[f];
    frame.joints.resize(kBody25Joints);
    for (int j = 0; j < kBody25Joints; ++j) {
      const int n = in.Count(fmt::format("frame {} joint {}: the count", f, j), 10000);
      frame.joints[j].resize(3, n);
      for (int r = 0; r < 3; ++r)
        for (int i = 0; i < n; ++i)
          frame.joints[j](r, i) = in.Number(fmt::format("frame {} joint {} row {}", f, j, r));
    }
    frame.pafs.resize(kBody25Limbs);
    for (int l = 0; l < kBody25Limbs; ++l) {
      const int rows = static_cast<int>(frame.joints[kBody25LimbA[l]].cols());
      const int cols = static_cast<int>(frame.joints[kBody25LimbB[l]].cols());
      frame.pafs[l].resize(rows, cols);
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
          frame.pafs[l](r, c) = in.Number(fmt::format("frame {} limb {}", f, l));
    }
  }
  in.ExpectEnd();
  return det;
}

const std::vector<int>& ShelfToBody25() {
  // Shelf: r-ankle, r-knee, r-hip, l-hip, l-knee, l-ankle, r-wrist, r-elbow,
  // r-shoulder, l-shoulder, l-elbow, l-wrist, neck, head top, pelvis.
  // BODY25: 1 neck, 2-4 right arm, 5-7 left arm, 8 mid-hip, 9-11 right leg,
  // 12-14 left leg.
  static const std::vector<int> map = {11, 10, 9, 12, 13, 14, 4, 3, 2, 5, 6, 7, 1, -1, 8};
  return map;
}

}  // namespace u4d
