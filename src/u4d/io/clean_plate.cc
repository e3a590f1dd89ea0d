#include "u4d/io/clean_plate.h"

#include <algorithm>

#include "u4d/io/image_io.h"
#include "u4d/io/layout.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

bool IsPicture(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

cv::Mat ReadPlateFrame(const fs::path& path, int width, int height) {
  cv::Mat image = ReadColorImage(path);
  U4D_CHECK(image.cols == width && image.rows == height,
            "{}: the clean plate is {}x{}, the camera {}x{}", path.string(), image.cols, image.rows,
            width, height);
  return image;
}

}  // namespace

std::vector<cv::Mat> ReadCleanPlate(const fs::path& capture_root, const std::string& view,
                                    int width, int height) {
  const fs::path base = capture_root / layout::CleanPlateDir() / view;
  std::vector<fs::path> files;
  if (fs::is_directory(base)) {
    for (const fs::directory_entry& e : fs::directory_iterator(base))
      if (e.is_regular_file() && IsPicture(e.path())) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    U4D_CHECK(!files.empty(), "{}: a clean-plate folder with no .png or .jpg image", base.string());
  } else {
    for (const char* ext : {".png", ".jpg", ".jpeg"}) {
      const fs::path file = base.string() + ext;
      if (fs::exists(file)) {
        files.push_back(file);
        break;
      }
    }
  }
  std::vector<cv::Mat> frames;
  frames.reserve(files.size());
  for (const fs::path& file : files) frames.push_back(ReadPlateFrame(file, width, height));
  return frames;
}

}  // namespace u4d
