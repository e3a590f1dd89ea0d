// The synthetic handshake shared by the fusion tests: 8 views at 320x180,
// 3 frames from script frame 10 (0.4 s: the people are walking towards each
// other, so consecutive frames differ by centimetres), with GT meshes, and reading a frame's GT
// maps. Include from *_test.cc and bench/ only.
#pragma once

#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "u4d/io/capture.h"
#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/synth/generate.h"
#include "u4d/util/testing.h"

namespace u4d::fusion_test {

struct FrameMaps {
  std::vector<Camera> cameras;
  std::vector<cv::Mat> depths, ids, images, flows;
};

// The capture's folder is removed when the test process exits (test_util::RemovedAtExit).
inline fs::path WriteSmallCapture(const std::string& name) {
  synth::SynthOptions o = synth::SmallHandshakeOptions(8, 320, 180, 3);
  o.write_meshes = true;
  o.start_frame = 10;
  return test_util::RemovedAtExit(synth::WriteCaptureToTempDir(name, o));
}

// Smooth zero-mean noise of standard deviation `sigma` (Gaussian noise
// blurred over `blur_px` pixels, as the errors of a regularised estimate are).
inline cv::Mat SmoothNoise(cv::Size size, int channels, double sigma, double blur_px,
                           cv::RNG& rng) {
  cv::Mat n(size, CV_32FC(channels));
  rng.fill(n, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar::all(1));
  cv::GaussianBlur(n, n, cv::Size(0, 0), blur_px);
  cv::Scalar mean, stddev;
  cv::meanStdDev(n.reshape(1), mean, stddev);
  n.convertTo(n, -1, sigma / stddev[0]);
  return n;
}

// GT maps of `frame` (flow only when frame + 1 exists).
inline FrameMaps ReadGtFrame(const Capture& c, int frame) {
  FrameMaps m;
  for (int v = 0; v < c.NumViews(); ++v) {
    const std::string& name = c.views[v].name;
    m.cameras.push_back(c.views[v].CameraAt(frame));
    m.depths.push_back(ReadPfm(c.root / layout::GtDepth(name, frame)));
    m.ids.push_back(ReadLabelImage(c.root / layout::GtInstances(name, frame)));
    m.images.push_back(ReadColorImage(c.ImagePath(v, frame)));
    if (frame + 1 < c.num_frames) m.flows.push_back(ReadFlo(c.root / layout::GtFlow(name, frame)));
  }
  return m;
}

}  // namespace u4d::fusion_test
