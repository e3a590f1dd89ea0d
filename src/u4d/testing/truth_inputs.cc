#include "u4d/testing/truth_inputs.h"

#include <algorithm>
#include <random>

#include <opencv2/imgproc.hpp>

#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"

namespace u4d {

std::vector<std::vector<Pose3d>> ReadGtPoses3d(const Capture& capture) {
  std::vector<std::vector<Pose3d>> poses(capture.num_frames);
  for (int f = 0; f < capture.num_frames; ++f) {
    poses[f] = ReadPoses3d(capture.root / layout::GtJoints3d(f));
    for (Pose3d& pose : poses[f]) {
      Eigen::Vector4d& head = pose.joints[h36m17::kHead];
      const Eigen::Vector4d& neck = pose.joints[h36m17::kNeck];
      const Eigen::Vector3d centre = (head.head<3>() + neck.head<3>()) / 2;
      head << centre, std::min(head[3], neck[3]);
    }
  }
  return poses;
}

ViewTruth ReadViewTruth(const Capture& capture, int view, int frame) {
  const std::string& name = capture.views.at(view).name;
  ViewTruth t;
  t.instances = ReadInstanceMask(capture.root / layout::GtInstances(name, frame),
                                 capture.root / layout::GtInstancesInfo(name, frame));
  t.depth = ReadPfm(capture.root / layout::GtDepth(name, frame));
  t.flow = ReadFlo(capture.root / layout::GtFlow(name, frame));
  t.flow_valid = ReadMaskImage(capture.root / layout::GtFlowValid(name, frame));
  return t;
}

ViewTruth ScaleViewTruth(const ViewTruth& t, const cv::Size& size, double scale) {
  if (t.depth.size() == size) return t;
  ViewTruth s = t;
  cv::resize(t.instances.ids, s.instances.ids, size, 0, 0, cv::INTER_NEAREST);
  cv::resize(t.depth, s.depth, size, 0, 0, cv::INTER_NEAREST);
  cv::resize(t.flow, s.flow, size, 0, 0, cv::INTER_NEAREST);
  s.flow *= scale;
  cv::resize(t.flow_valid, s.flow_valid, size, 0, 0, cv::INTER_NEAREST);
  return s;
}

InstanceMask PersonInstances(const cv::Mat& ids) {
  InstanceMask mask;
  mask.ids = ids;
  double max_id = 0;
  cv::minMaxLoc(ids, nullptr, &max_id);
  for (int id = 1; id <= static_cast<int>(max_id); ++id)
    if (cv::countNonZero(ids == id) > 0) mask.instances.push_back({id, "person", 1.0});
  return mask;
}

std::vector<SparseMotion> SparseMotionsFromTruth(const ViewTruth& t, int count, uint64_t seed) {
  std::vector<cv::Point> candidates;
  for (int y = 0; y < t.flow.rows; ++y)
    for (int x = 0; x < t.flow.cols; ++x)
      if (t.instances.ids.at<uint16_t>(y, x) > 0 && t.flow_valid.at<uint8_t>(y, x))
        candidates.push_back({x, y});
  std::mt19937_64 rng(seed);
  std::shuffle(candidates.begin(), candidates.end(), rng);
  std::vector<SparseMotion> sparse;
  for (int i = 0; i < std::min<int>(count, static_cast<int>(candidates.size())); ++i) {
    const cv::Vec2f f = t.flow.at<cv::Vec2f>(candidates[i]);
    sparse.push_back({Eigen::Vector2d(candidates[i].x, candidates[i].y),
                      Eigen::Vector2d(f[0], f[1]), t.instances.ids.at<uint16_t>(candidates[i])});
  }
  return sparse;
}

}  // namespace u4d
