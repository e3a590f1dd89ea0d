// Readers for the 4D Association (Zhang et al., CVPR 2020) data files, as
// published with its code for the Shelf and Campus datasets. The calibration
// reader is ReadFourdaCalibration in import_calibration.h.
//
//  calibration.json  {"<cam>": {"K": [9 values, row-major],
//                               "RT": [12 values, row-major 3x4 cam_from_world, metres],
//                               "imgSize": [width, height]}, ...}
//  gt.txt            "<jointCount> <frameCount>", then per frame: the number of
//                    people, then per person its id and 4 rows of jointCount
//                    values (x, y, z in metres, confidence).
//  detection/<cam>.txt  "<skelType> <frameCount>", then per frame: per joint
//                    type a count n and 3 rows of n values (x / width,
//                    y / height, score: coordinates normalised to [0, 1]),
//                    then per limb (part-affinity field) an nA x nB matrix of
//                    scores, nA, nB the counts of the limb's two joint types.
//
// Only skelType 4 (OpenPose BODY25: 25 joints, 26 limbs) is supported for
// detections; others throw. All readers throw u4d::Error naming the file on a
// missing file, a truncated or garbled file, or non-finite values.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "u4d/io/import_calibration.h"

namespace u4d {

struct FourdaPerson3d {
  int id = -1;
  Eigen::Matrix4Xd joints;  // rows x, y, z (metres), confidence; one column per joint
};

struct FourdaGroundTruth {
  int num_joints = 0;
  std::vector<std::vector<FourdaPerson3d>> frames;  // people per frame
};

// gt.txt. On Shelf the 15 joints follow the Shelf order: right ankle, right
// knee, right hip, left hip, left knee, left ankle, right wrist, right elbow,
// right shoulder, left shoulder, left elbow, left wrist, neck, head top, pelvis.
FourdaGroundTruth ReadFourdaGroundTruth(const fs::path& path);

struct FourdaDetectionFrame {
  // Per joint type: 3 x n (x, y normalised to [0, 1], score).
  std::vector<Eigen::Matrix3Xd> joints;
  // Per limb: nA x nB part-affinity scores.
  std::vector<Eigen::MatrixXd> pafs;
};

struct FourdaDetections {
  int skel_type = 4;  // 4 = BODY25
  std::vector<FourdaDetectionFrame> frames;
};

FourdaDetections ReadFourdaDetections(const fs::path& path);

// OpenPose BODY25 joint index of each Shelf ground-truth joint above, -1 for
// the head top (BODY25 has no such joint).
const std::vector<int>& ShelfToBody25();

}  // namespace u4d
