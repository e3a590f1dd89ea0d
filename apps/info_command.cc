// `u4d info <capture>`: reads a capture and prints what it holds.
#include <memory>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/io/capture.h"

namespace u4d::apps {

Command MakeInfoCommand() {
  auto capture_dir = std::make_shared<std::string>();
  return {"info", "print a summary of a capture",
          [=](CLI::App& app) {
            app.add_option("capture", *capture_dir, "capture directory")->required();
          },
          [=] {
            const Capture c = ReadCapture(*capture_dir);
            fmt::print("capture {}: {} views, {} frames at {} fps, {} scene\n", c.name,
                       c.NumViews(), c.num_frames, c.fps, ToString(c.scene));
            for (const CaptureView& v : c.views) {
              const Camera& cam = v.cameras[0];
              const Eigen::Vector3d center = cam.Center();
              fmt::print("  {:<10} {}x{}  f={:.1f}  centre=({:.3f}, {:.3f}, {:.3f}) m  {}\n",
                         v.name, cam.width, cam.height, cam.K(0, 0), center.x(), center.y(),
                         center.z(), v.IsMoving() ? "moving" : "static");
            }
            for (const char* sub : {"masks", "poses2d", "poses3d", "gt"})
              fmt::print("  {:<8} {}\n", sub, fs::exists(c.root / sub) ? "present" : "absent");
            return 0;
          }};
}

}  // namespace u4d::apps
