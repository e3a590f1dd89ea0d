// Reading and writing the image-like files of a capture and a 4D scene.
// Every reader throws u4d::Error naming the file when it is missing, corrupt,
// of the wrong type or of an unexpected size; every writer is atomic.
//
//  colour images   8-bit BGR (cv::Mat CV_8UC3): PNG, JPEG, BMP or TIFF
//  instance ids    16-bit single-channel PNG (CV_16UC1), 0 = background
//  masks           8-bit single-channel PNG, non-zero = true
//  depth           PFM, float32 metres along the optical axis (z), 0 = unknown
//  flow            Middlebury .flo, float32 (u, v) in pixels; NaN or >1e9 = invalid
#pragma once

#include <opencv2/core.hpp>

#include "u4d/util/file.h"

namespace u4d {

// The image formats the readers accept, told by the file's first bytes (not its
// extension). Only these are handed to OpenCV's decoders: a file in any other
// format (or none) is an error before decoding, so no other decoder linked
// into OpenCV ever sees untrusted bytes.
enum class ImageFormat { kPng, kJpeg, kBmp, kTiff, kUnknown };
ImageFormat SniffImageFormat(const fs::path& path);

// The largest image the readers decode (width x height), checked on the PNG
// header before any pixel is allocated: 4 x a 4096 x 4096 frame.
constexpr int64_t kMaxImagePixels = int64_t{1} << 26;

// Reads an 8-bit colour image (grey images are converted to BGR).
cv::Mat ReadColorImage(const fs::path& path);
// Reads a 16-bit single-channel PNG of instance ids (8-bit PNGs are widened).
cv::Mat ReadLabelImage(const fs::path& path);
// Reads an 8-bit single-channel mask (any non-zero is true), returns CV_8UC1 0/255.
cv::Mat ReadMaskImage(const fs::path& path);

// Writes with OpenCV, picking the format from the extension.
void WriteImage(const fs::path& path, const cv::Mat& image);

// Portable float map, single channel (CV_32FC1) or three channels (CV_32FC3).
cv::Mat ReadPfm(const fs::path& path);
void WritePfm(const fs::path& path, const cv::Mat& image);

// Middlebury .flo: magic 202021.25, int32 width, int32 height, interleaved float32 u, v.
cv::Mat ReadFlo(const fs::path& path);  // CV_32FC2
void WriteFlo(const fs::path& path, const cv::Mat& flow);

// Throws when `image` is not `width` x `height`; `what` names the file.
void CheckImageSize(const cv::Mat& image, int width, int height, const std::string& what);

}  // namespace u4d
