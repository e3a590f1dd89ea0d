#include "u4d/io/frame_reader.h"

#include <opencv2/videoio.hpp>

#include "u4d/io/image_io.h"
#include "u4d/util/check.h"

namespace u4d {

struct FrameReader::VideoState {
  cv::VideoCapture capture;
  int next_index = 0;  // index of the frame the next read() returns
};

FrameReader::FrameReader(Capture capture)
    : capture_(std::move(capture)), videos_(capture_.NumViews()) {}
FrameReader::~FrameReader() = default;

cv::Mat FrameReader::Read(int view, int frame) {
  U4D_CHECK(view >= 0 && view < capture_.NumViews(), "view index {} out of range", view);
  U4D_CHECK(frame >= 0 && frame < capture_.num_frames, "frame {} out of range [0, {})", frame,
            capture_.num_frames);
  const CaptureView& v = capture_.views[view];
  const Camera& cam = v.CameraAt(frame);
  cv::Mat image;
  std::string what;
  if (v.source.kind == FrameSource::Kind::kImages) {
    const fs::path path = capture_.ImagePath(view, frame);
    what = path.string();
    image = ReadColorImage(path);
  } else {
    const fs::path path = capture_.root / v.source.path;
    const int index = frame + v.source.first_index;
    what = fmt::format("{} frame {}", path.string(), index);
    auto& state = videos_[view];
    if (!state || index < state->next_index) {
      CheckFileExists(path, "video");
      state = std::make_unique<VideoState>();
      U4D_CHECK(state->capture.open(path.string()), "{}: cannot open video", path.string());
    }
    while (state->next_index <= index) {
      U4D_CHECK(state->capture.read(image), "{}: cannot decode (video has {} frames?)", what,
                state->next_index);
      ++state->next_index;
    }
    image = image.clone();
  }
  CheckImageSize(image, cam.width, cam.height, what);
  return image;
}

}  // namespace u4d
