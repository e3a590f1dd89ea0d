// A two-view, two-frame capture of 8x6 images for the io tests (not written).
#pragma once

#include <string>

#include "u4d/io/capture.h"

namespace u4d::test_util {

inline Capture TinyTwoViewCapture() {
  Capture c;
  c.name = "tiny";
  c.num_frames = 2;
  c.fps = 30;
  for (int v = 0; v < 2; ++v) {
    CaptureView view;
    view.name = "cam" + std::to_string(v);
    Camera cam;
    cam.width = 8;
    cam.height = 6;
    cam.K << 10, 0, 4, 0, 10, 3, 0, 0, 1;
    cam.cam_from_world.translation = {0.1 * v, 0, 2};
    view.cameras = {cam};
    view.source.path = "images/" + view.name + "/{:06d}.png";
    c.views.push_back(view);
  }
  return c;
}

}  // namespace u4d::test_util
