// Reading OpenCV FileStorage files (XML, YAML or JSON as cv::FileStorage
// writes them) with errors that name the file and the key. Shared by the
// importers that read such files (EasyMocap's intri.yml / extri.yml and the
// OpenCV calibration files of `u4d import opencv`, import_calibration.h).
#pragma once

#include <string>
#include <vector>

#include <opencv2/core/persistence.hpp>

#include "u4d/util/file.h"

namespace u4d {

// Opens `path` for reading. Throws u4d::Error naming the file (and `what`
// it was expected to be) when it is missing or not a FileStorage file.
cv::FileStorage OpenFileStorage(const fs::path& path, const std::string& what);

// Whether `map` (a FileStorage map node) has the key.
bool HasKey(const cv::FileNode& map, const std::string& key);

// The first of `keys` that `map` has, or "" when it has none of them.
std::string FirstKey(const cv::FileNode& map, const std::vector<std::string>& keys);

// The numbers of map[key], row-major: an opencv-matrix node (any depth, any
// shape, any channel count), a number, or a (nested) sequence of numbers.
// `counts` lists the accepted numbers of values (empty: any). `context`
// names the file (and the camera) in errors. Throws u4d::Error naming
// context and key when the key is missing, its value is not a matrix or
// numbers, the count is not accepted, or a value is not finite.
std::vector<double> ReadNumbers(const cv::FileNode& map, const std::string& key,
                                const std::vector<int>& counts, const std::string& context);

// An integer map[key] (a number, or a matrix / sequence of one value).
// Throws like ReadNumbers, and on a value that is not a whole number.
int ReadInt(const cv::FileNode& map, const std::string& key, const std::string& context);

}  // namespace u4d
