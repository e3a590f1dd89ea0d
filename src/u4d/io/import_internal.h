// Helpers shared by the importers' sources (import_calibration.cc,
// import_opencv.cc); not part of the io module's API.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "u4d/io/capture.h"
#include "u4d/io/import_calibration.h"
#include "u4d/util/file.h"

namespace u4d::import_internal {

// `token` as a finite number; throws naming context and what.
double ParseFinite(const std::string& token, const std::string& context, const std::string& what);

// All numbers of a (possibly nested) JSON array, flattened; exactly `n`.
std::vector<double> JsonNumbers(const nlohmann::json& j, const std::string& key, size_t n,
                                const std::string& context);

Eigen::Matrix3d RowMajor3x3(const double* v);

// An image width or height read from a file as a number: a whole number in
// [1, 1 << 20]; throws naming context and what (a cast of a larger or
// non-finite double to int is undefined behaviour).
int ImageDimension(double value, const std::string& context, const std::string& what);

// A rotation from 3 values (a Rodrigues vector: axis times angle in
// radians, as cv::Rodrigues) or 9 (a row-major matrix, not yet checked:
// pass it through CleanRotation).
Eigen::Matrix3d RotationFromValues(const std::vector<double>& values);

// Checks `m` is a rotation to within `tol` (files write few digits), then
// returns the nearest exact rotation.
Eigen::Matrix3d CleanRotation(const Eigen::Matrix3d& m, const std::string& context,
                              double tol = 1e-2);

std::string Lower(std::string s);
bool IsImageFile(const fs::path& p);  // a regular file with an image extension
std::vector<fs::path> SortedImages(const fs::path& dir);
cv::Size ImageSize(const fs::path& path);  // throws naming an unreadable image

struct VideoInfo {
  int frames = 0;
  double fps = 0;
  cv::Size size;
};
VideoInfo ProbeVideo(const fs::path& path);  // throws on a missing or unreadable video

fs::path Absolute(const fs::path& p);

// `source` itself when it is a file, else the one file in it ending in `suffix`.
fs::path FindOneFile(const fs::path& source, const std::string& suffix);

// Limits the capture to options.max_frames frames, sets its fps, checks it.
void Finish(Capture& capture, const ImportOptions& options, double source_fps);

// Views from image folders: per view the sorted files; frames are the keys
// (`frame_key` of a file) common to all views, and the capture's
// source_frames the keys as numbers (SourceFrameNumbers).
void FillCommonImageFrames(Capture& capture, const std::vector<std::vector<fs::path>>& files,
                           const std::function<std::string(const fs::path&)>& frame_key);
std::vector<int64_t> SourceFrameNumbers(const std::vector<std::string>& keys);

}  // namespace u4d::import_internal
