// Offline smoothing of tracked 3D poses over time.
//
// Poses triangulated from 2D detections jitter by centimetres from frame to
// frame (pose_tracking.h's causal alpha-beta filter keeps most of that
// noise on a still joint). The joint energy uses the poses' motion from t to
// t+1 (E_p's e_2d^M and e_3d^M, joint/pose_prior.h), and on a nearly still
// person that jitter is far larger than the true motion, and the flow is
// pulled towards pixels of motion that is not there.
// Since `u4d run` sees the whole sequence, it can smooth non-causally.
//
// Method: a local polynomial (Savitzky-Golay-style least squares) per person
// id and joint. At frame k the joint's samples at frames k - h ... k + h
// (h = round(window_seconds * fps / 2), frames where the person has the
// joint with confidence > 0) are fitted by a polynomial in (t - k) of degree
// min(degree, n - 2), n the number of samples, and the joint becomes its
// value at t = k. With fewer than 3 samples, or degree < 1, the joint is
// left as it is. A quadratic keeps constant acceleration exactly (no lag on
// a limb speeding up); with 7 samples it cuts the noise of the frame-to-frame
// motion x(t+1) - x(t) by about 3.4x (the difference of two consecutive
// fits weighs the samples by (-2, 5, 3, 1, -1, -3, -5, 2) / 21: variance
// 0.18 s^2 against 2 s^2 for raw positions). Confidences, ids, the order of
// the poses, and missing joints are kept.
#pragma once

#include <vector>

#include "u4d/io/poses.h"

namespace u4d {

struct PoseSmoothingOptions {
  // Length of the fitting window in seconds (0 turns smoothing off). 0.25 s
  // is 7 frames at 25 fps: short against a hand shake's period (~0.4 s).
  double window_seconds = 0.25;
  int degree = 2;      // polynomial degree (>= 1)
  void Check() const;  // throws u4d::Error naming the bad field
};

// frames[t] = the poses of frame t with track ids (person_id >= 0), as
// TrackPoses returns them; fps > 0. Throws u4d::Error on bad options, a
// non-positive fps, or two poses with the same id in one frame.
std::vector<std::vector<Pose3d>> SmoothTrackedPoses(const std::vector<std::vector<Pose3d>>& frames,
                                                    double fps,
                                                    const PoseSmoothingOptions& options = {});

}  // namespace u4d
