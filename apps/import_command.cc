// `u4d import <format> <source> -o <capture_dir> [--max-frames N]`: reads a
// calibration in a convention users already have (io/import_calibration.h)
// and writes a self-contained native capture: capture.json, calibration.json,
// and the frames copied to images/<view>/<frame:06d>.<ext> or videos/.
#include <memory>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "u4d/io/import_calibration.h"

namespace u4d::apps {

namespace {

struct ImportArgs {
  std::string format;
  std::string source;
  std::string output;
  ImportOptions options;
};

}  // namespace

Command MakeImportCommand() {
  auto args = std::make_shared<ImportArgs>();
  return {
      "import", "convert a panoptic/qualisys/fourda/middlebury/easymocap/opencv capture",
      [=](CLI::App& app) {
        app.add_option("format", args->format,
                       "panoptic, qualisys, fourda, middlebury, easymocap or opencv")
            ->required();
        app.add_option("source", args->source, "source folder (or calibration file)")->required();
        app.add_option("-o,--output", args->output, "native capture directory to write")
            ->required();
        app.add_option("--max-frames", args->options.max_frames,
                       "keep at most this many frames (0 = all)");
        app.add_option("--fps", args->options.fps, "frame rate (0 = the source's)");
        app.add_option("--unit", args->options.unit,
                       "opencv: unit of the files' translations (m, cm or mm)")
            ->check(CLI::IsMember({"m", "cm", "mm"}));
      },
      [=] {
        const ImportFormat format = ImportFormatFromString(args->format);
        const Capture imported = ImportCapture(format, args->source, args->options);
        const Capture c = WriteImportedCapture(imported, args->output);
        fmt::print("imported {} capture {}: {} views, {} frames at {} fps -> {}\n",
                   ToString(format), c.name, c.NumViews(), c.num_frames, c.fps, args->output);
        for (const CaptureView& v : c.views) {
          const Camera& cam = v.cameras[0];
          const Eigen::Vector3d centre = cam.Center();
          const bool video = v.source.kind == FrameSource::Kind::kVideo;
          const bool present = !video || fs::exists(c.root / v.source.path);
          fmt::print(
              "  {:<12} {}x{}  fx={:.1f}  centre=({:.3f}, {:.3f}, {:.3f}) m  {} {}{}\n", v.name,
              cam.width, cam.height, cam.K(0, 0), centre.x(), centre.y(), centre.z(),
              video ? "video" : "images",
              video ? v.source.path : v.source.path + (v.source.files.empty() ? "" : " (list)"),
              present ? "" : "  [MISSING: frames unreadable]");
        }
        return 0;
      }};
}

}  // namespace u4d::apps
