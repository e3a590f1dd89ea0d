// u4d_init_demo: runs the unsupervised initial masks (init.h) on a capture
// and writes a picture of them; with ground truth (gt/instances) prints the
// foreground IoU and instance counts. Usage:
//   u4d_init_demo <capture> <out.png> [frame ...]   (default: 4 frames spread)
// Prints per view the background noise level and per frame the timings.
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "u4d/init/init.h"
#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

using namespace u4d;

namespace {

cv::Mat Overlay(const cv::Mat& image, const cv::Mat& ids, int out_width) {
  // Grey image (compresses well), background dimmed, instances tinted.
  static const cv::Vec3b kColors[] = {{180, 119, 31}, {14, 127, 255},  {44, 160, 44},
                                      {40, 39, 214},  {189, 103, 148}, {75, 86, 140}};
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  cv::Mat out(image.size(), CV_8UC3);
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x) {
      const int id = ids.at<uint16_t>(y, x);
      const double g = grey.at<uint8_t>(y, x);
      cv::Vec3b& p = out.at<cv::Vec3b>(y, x);
      if (id == 0) {
        p = cv::Vec3b::all(static_cast<uint8_t>(0.55 * g));
        continue;
      }
      const cv::Vec3b c = kColors[(id - 1) % 6];
      for (int k = 0; k < 3; ++k) p[k] = static_cast<uint8_t>(0.4 * g + 0.6 * c[k]);
    }
  cv::resize(out, out, cv::Size(out_width, out_width * out.rows / out.cols), 0, 0, cv::INTER_AREA);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    U4D_CHECK(argc >= 3, "usage: u4d_init_demo <capture> <out.png> [frame ...]");
    const Capture capture = ReadCapture(argv[1]);
    std::vector<int> frames;
    for (int i = 3; i < argc; ++i) frames.push_back(std::stoi(argv[i]));
    if (frames.empty())
      for (int k = 0; k < 4; ++k) frames.push_back((2 * k + 1) * capture.num_frames / 8);
    FrameReader reader(capture);
    const int nv = capture.NumViews();
    std::vector<BackgroundModel> bg(nv);
    std::vector<Camera> cams(nv);
    Timer timer;
    for (int v = 0; v < nv; ++v) {
      bg[v] = EstimateBackground(capture.num_frames, [&](int f) { return reader.Read(v, f); });
      cams[v] = capture.views[v].CameraAt(0);
      fmt::print("view {}: background from {} frames, sigma {:.2f} Lab\n", capture.views[v].name,
                 bg[v].frames_used, bg[v].sigma);
    }
    fmt::print("backgrounds: {:.2f} s\n", timer.Seconds());
    if (std::getenv("U4D_INIT_SAVE_BACKGROUNDS")) {  // <out>.bg.png: the background models
      std::vector<cv::Mat> tiles;
      for (int v = 0; v < nv; ++v) {
        cv::Mat b;
        b = bg[v].bgr.clone();
        if (!bg[v].envelope.empty()) {  // the temporal envelope (step 5) tinted red
          cv::Mat red(b.size(), CV_8UC3, cv::Scalar(0, 0, 255));
          cv::Mat mixed;
          cv::addWeighted(b, 0.5, red, 0.5, 0, mixed);
          mixed.copyTo(b, bg[v].envelope);
        }
        cv::resize(b, b, cv::Size(240, 240 * bg[0].Height() / bg[0].Width()));
        tiles.push_back(b);
      }
      cv::Mat row;
      cv::hconcat(tiles, row);
      cv::imwrite(std::string(argv[2]) + ".bg.png", row);
    }
    const char* tw = std::getenv("U4D_INIT_TILE");
    const int tile_w = tw ? std::atoi(tw) : 240;
    std::vector<cv::Mat> rows;
    InitOptions options;
    // Environment overrides for experiments (docs/init.md).
    if (const char* g = std::getenv("U4D_INIT_GRABCUT"))
      options.people.grabcut_iterations = std::atoi(g);
    if (const char* g = std::getenv("U4D_INIT_BOX_FILL"))
      options.people.box_fill = BoxFillFromString(g);
    if (const char* g = std::getenv("U4D_INIT_STILL"))
      options.still.still_grabcut_iterations = std::atoi(g);
    if (const char* g = std::getenv("U4D_INIT_CARVE_STILL"))
      options.still.carve_still_fill = std::atoi(g) != 0;
    if (const char* g = std::getenv("U4D_INIT_GHOSTS"))
      options.still.remove_ghosts = std::atoi(g) != 0;
    if (const char* g = std::getenv("U4D_INIT_HOG")) options.people.use_hog = std::atoi(g) != 0;
    if (const char* g = std::getenv("U4D_INIT_CROSS_VIEW"))
      options.cross_view.enabled = std::atoi(g) != 0;
    if (const char* g = std::getenv("U4D_INIT_OCCUPANCY"))
      options.ground.enabled = std::atoi(g) != 0;
    for (const int f : frames) {
      std::vector<cv::Mat> images(nv);
      for (int v = 0; v < nv; ++v) images[v] = reader.Read(v, f);
      Timer t;
      const std::vector<cv::Mat> ids = UnsupervisedInstanceMasks(cams, images, bg, options);
      const double sec = t.Seconds();
      std::vector<cv::Mat> tiles;
      std::string counts;
      double inter = 0, uni = 0;
      for (int v = 0; v < nv; ++v) {
        std::set<int> present;  // distinct ids (step 6's need not be 1..n)
        for (auto it = ids[v].begin<uint16_t>(); it != ids[v].end<uint16_t>(); ++it)
          if (*it) present.insert(*it);
        counts += fmt::format(" {}", present.size());
        const fs::path gt = capture.root / layout::GtInstances(capture.views[v].name, f);
        if (fs::exists(gt)) {
          const cv::Mat g = cv::imread(gt.string(), cv::IMREAD_UNCHANGED) > 0;
          const cv::Mat p = ids[v] > 0;
          inter += cv::countNonZero(g & p);
          uni += cv::countNonZero(g | p);
        }
        cv::Mat shown = images[v].clone();
        const auto boxes = DetectPeople(images[v], options);
        counts += fmt::format("/{}", boxes.size());
        tiles.push_back(Overlay(shown, ids[v], tile_w));
        const double s = static_cast<double>(tile_w) / images[v].cols;
        for (const PersonBox& b : boxes)
          cv::rectangle(tiles.back(),
                        cv::Rect(b.box.x * s, b.box.y * s, b.box.width * s, b.box.height * s),
                        cv::Scalar(255, 255, 255), 1);
        cv::resize(tiles.back(), tiles.back(), tiles.front().size());
      }
      fmt::print("frame {}: {:.2f} s, instances per view:{}", f, sec, counts);
      if (uni > 0) fmt::print(", foreground IoU {:.3f}", inter / uni);
      fmt::print("\n");
      cv::Mat row;
      cv::hconcat(tiles, row);
      rows.push_back(row);
    }
    cv::Mat all;
    cv::vconcat(rows, all);
    // Fewer levels per channel (and a slight blur) keep the PNG small for the docs.
    if (const char* p = std::getenv("U4D_INIT_POSTERIZE")) {
      const int step = std::max(1, std::atoi(p));
      cv::GaussianBlur(all, all, cv::Size(3, 3), 0.6);
      all = (all / step) * step + step / 2;
    }
    cv::imwrite(argv[2], all, {cv::IMWRITE_PNG_COMPRESSION, 9});
    fmt::print("wrote {}\n", argv[2]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
