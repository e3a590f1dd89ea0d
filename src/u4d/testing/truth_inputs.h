// Ground truth of a synthetic capture in the forms the joint optimisation's
// tests and benchmarks compare against or stand in for (the stages that
// produce these inputs are measured on their own).
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/io/capture.h"
#include "u4d/io/instance_mask.h"
#include "u4d/io/poses.h"
#include "u4d/joint/motion_labels.h"

namespace u4d {

// GT maps of one view and frame (layout.h Gt*). Throws naming a missing file.
struct ViewTruth {
  InstanceMask instances;
  cv::Mat depth, flow, flow_valid;  // CV_32F z, CV_32FC2, CV_8U
};
ViewTruth ReadViewTruth(const Capture& capture, int view, int frame);

// The GT 3D poses of every frame (layout.h GtJoints3d), indexed by frame: the
// stand-in for the estimated poses (pose/ measures its own accuracy). Their
// head joint is moved to the estimated poses' convention, the head centre
// (docs/annotations.md): the GT head joint is the crown and its neck the
// head's base (docs/synthetic.md), so the centre is their mid-point.
std::vector<std::vector<Pose3d>> ReadGtPoses3d(const Capture& capture);

// The truth at another resolution (a working resolution): ids, depth and
// validity by nearest neighbour, the flow resampled the same way and
// multiplied by `scale` (new size / camera size). Unchanged when `size` is
// already the truth's size.
ViewTruth ScaleViewTruth(const ViewTruth& truth, const cv::Size& size, double scale);

// An id image (CV_16U) as an InstanceMask whose instances are all "person".
InstanceMask PersonInstances(const cv::Mat& ids);

// `count` sparse correspondences from the GT flow at random GT-valid person
// pixels (deterministic in `seed`): a stand-in for the temporal tracks.
std::vector<SparseMotion> SparseMotionsFromTruth(const ViewTruth& truth, int count, uint64_t seed);

}  // namespace u4d
