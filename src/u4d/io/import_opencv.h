// `u4d import opencv`: calibrations written with OpenCV's FileStorage (XML,
// YAML; JSON when named as the source) by studios' own tools and OpenCV's
// calibration samples (docs/importers.md "OpenCV FileStorage").
//
// Layouts. `source` is a file or a folder. A folder's calibration files are
// its *.xml, *.yml and *.yaml files (or, when it has none, those of its
// calibration/ or calib/ subfolder), read in name order. Each file holds
//  - one camera: the keys below at its top level; the camera is named by
//    the file's stem (cam1.xml -> "cam1"), or
//  - several cameras: one top-level map per camera holding the keys, named
//    by its key (cam_0: {camera_matrix: ..., ...}), in file order.
// Keys (the first spelling present wins; values are opencv-matrix nodes or
// plain number sequences):
//   intrinsics   camera_matrix, CameraMatrix, cameraMatrix, K,
//                intrinsic_matrix, IntrinsicMatrix            (3x3, pixels)
//   distortion   distortion_coefficients, DistortionCoeffs,
//                DistortionCoefficients, distCoeffs, dist_coeffs, dist, D
//                (4, 5, 8, 12 or 14 values in OpenCV's order; values past
//                k3 must be 0; absent = no distortion)
//   rotation     rvec, RotationValues, rotation, R, Rot,
//                rotation_matrix, RotationMatrix
//                (3 values: Rodrigues vector; 9: matrix, row-major)
//   translation  tvec, TranslationValues, translation, T, t   (3 values)
//   image size   image_width + image_height, ImageWidth + ImageHeight,
//                width + height, or image_size / imageSize / ImageSize
//                (width, height); absent = taken from the camera's frames.
// The pose is OpenCV's extrinsics, cam_from_world (x_cam = R x_world + t),
// as solvePnP and calibrateCamera give it; t is in ImportOptions::unit.
//
// Frames of camera <name>, looked for under the folder (a file source: the
// file's folder; a calibration/ or calib/ subfolder: its parent): an image
// folder <name>/ or images/<name>/ (frames = the files whose stems end in
// the same number in every view), else a video <name>.<ext> or
// videos/<name>.<ext> (.mp4, .avi, .mov, .mkv, .webm, .mpg, .m4v; frames =
// the shortest video's count). All views use one kind.
//
// Throws u4d::Error naming the file (and camera and key) on a missing or
// unparsable file, a file with no camera, a missing key, a wrong count, a
// non-finite value, a non-rotation, unsupported distortion terms, a
// non-positive unit or size, or a camera without frames.
#pragma once

#include <vector>

#include "u4d/io/import_calibration.h"

namespace u4d {

// The cameras of `source` (above), translations multiplied by
// `metres_per_unit`. A camera whose files give no image size has width and
// height 0 (ImportOpenCv takes them from its frames); the others are
// checked (Camera::Check).
std::vector<NamedCamera> ReadOpenCvCalibration(const fs::path& source, double metres_per_unit);

Capture ImportOpenCv(const fs::path& source, const ImportOptions& options = {});

}  // namespace u4d
