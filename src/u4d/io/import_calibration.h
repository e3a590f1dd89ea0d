// Importers for the calibration and frame conventions users already have.
// Each importer returns a u4d::Capture (io/capture.h) in the project's
// conventions (docs/conventions.md): metres, cam_from_world (x_cam = R x + t),
// OpenCV distortion (k1, k2, p1, p2, k3), pixel origin at the centre of the
// top-left pixel. Frame sources point at the ORIGINAL files with absolute
// paths (FrameSource.files, or FrameSource.path for a video), so the returned
// Capture can be handed to FrameReader directly; `root` is the source folder.
// WriteImportedCapture turns it into a self-contained native capture.
//
// Formats (each section of docs/importers.md says how it was verified):
//  panoptic    CMU Panoptic: <dir>/camera_parameters.json (K, distCoef, R, t in
//              centimetres) + <dir>/<cam>/<cam>_<frame:08d>.jpg. Views are the
//              image folders present; frames the sorted frame numbers common
//              to all views (they need not be consecutive).
//  qualisys    Qualisys QTM export <dir>/*.qca.txt (XML; mm; camera-to-world
//              transform with column-major r values; cameras looking along -z;
//              intrinsics in sensor units of 1/64 pixel) + <dir>/videos/<serial>.mp4.
//  fourda      4D Association: <dir>/calibration.json (per camera K as 9
//              values, RT 3x4 cam_from_world in metres, imgSize) + optional
//              <dir>/video/<cam>.mp4 (see import_fourda.h).
//  middlebury  Middlebury multi-view stereo: <dir>/<name>_par.txt (count, then
//              "img.png k11..k33 r11..r33 t1 t2 t3" per image) + the images.
//              Every image is its own view; the capture has one frame. Units
//              are the file's own (the dino/temple sets are in metres).
//  easymocap   EasyMocap: <dir>/intri.yml (names, K_<cam>, dist_<cam>, optional
//              H_<cam>, W_<cam>) and <dir>/extri.yml (R_<cam> Rodrigues 3x1,
//              Rot_<cam> 3x3, T_<cam> 3x1 in metres) + <dir>/images/<cam>/<frame>.jpg
//              (or <dir>/videos/<cam>.mp4).
//  opencv      OpenCV FileStorage files (XML, YAML) per camera or one file for
//              all, with the usual key spellings (camera_matrix / CameraMatrix /
//              K, ...), translations in the unit of ImportOptions::unit; frames
//              from a video or an image folder per camera (see import_opencv.h).
//
// Every reader throws u4d::Error naming the file and the problem on a missing
// file, a syntax error, a missing key, a wrong matrix size, a non-finite value,
// a non-rotation, or views without frames.
#pragma once

#include <string>
#include <vector>

#include "u4d/geometry/camera.h"
#include "u4d/io/capture.h"
#include "u4d/util/file.h"

namespace u4d {

enum class ImportFormat { kPanoptic, kQualisys, kFourda, kMiddlebury, kEasyMocap, kOpenCv };

// "panoptic", "qualisys", "fourda", "middlebury", "easymocap", "opencv".
std::string ToString(ImportFormat format);
ImportFormat ImportFormatFromString(const std::string& s);  // throws on unknown names

struct ImportOptions {
  // Keep at most this many frames (the first ones); 0 keeps all.
  int max_frames = 0;
  // Frame rate written to the capture; 0 takes the source's (the video's
  // rate, else the format's nominal rate: Panoptic HD 29.97, Shelf 25,
  // EasyMocap image folders 30, Middlebury 1).
  double fps = 0;
  // opencv only: the unit of the files' translations, "m", "cm" or "mm"
  // (the files do not say; OpenCV's calibration takes the board's unit).
  std::string unit = "m";

  void Check() const;
  double MetresPerUnit() const;  // 1, 0.01 or 0.001
};

// A camera with the name its source file gives it.
struct NamedCamera {
  std::string name;
  Camera camera;
};

// ---- calibration-only readers ------------------------------------------------

// All cameras of a Panoptic camera_parameters.json (centimetres -> metres).
std::vector<NamedCamera> ReadPanopticCalibration(const fs::path& json_path);

// All cameras of a Qualisys .qca.txt, named by their serial (e.g. "cam01").
// Conversion: world_from_qcam = [M | p/1000] with M filled column by column
// from r11..r33 (r11, r12, r13 is the first column) and p = (x, y, z) mm;
// cam_from_world = Rx(pi) * world_from_qcam^-1 (Qualisys cameras look along
// -z); fx, fy, cx, cy = focalLengthU/64, focalLengthV/64, centerPointU/64 -
// fov_video.left, centerPointV/64 - fov_video.top; image size from fov_video;
// distortion (radialDistortion1, 2, tangentalDistortion1, 2, radialDistortion3).
std::vector<NamedCamera> ReadQualisysCalibration(const fs::path& qca_path);

// A 4D Association calibration.json; cameras named by their JSON keys,
// sorted by name. RT is cam_from_world in metres; rotations written with few
// digits are projected onto the nearest rotation (after a 1e-2 sanity check).
std::vector<NamedCamera> ReadFourdaCalibration(const fs::path& json_path);

// A Middlebury *_par.txt; `width` x `height` is the image size (not in the
// file). Names are the image file names as written (e.g. "dinoSR0001.png").
std::vector<NamedCamera> ReadMiddleburyCalibration(const fs::path& par_path, int width, int height);

// EasyMocap intri.yml + extri.yml, cameras in the order of intri's `names`.
// Rot_<cam> is used when present, else Rodrigues(R_<cam>). The image size is
// H_<cam>/W_<cam> when intri has them; otherwise that of the first image in
// `image_root`/<cam>/ (sorted); when neither exists this throws.
std::vector<NamedCamera> ReadEasyMocapCalibration(const fs::path& intri_path,
                                                  const fs::path& extri_path,
                                                  const fs::path& image_root = {});

// Writes an EasyMocap folder: intri.yml (names, K_, dist_, H_, W_), extri.yml
// (names, R_, Rot_, T_) and images/<view>/<frame:06d>.jpg for the first
// `max_frames` frames (0 = all) read through FrameReader (JPEG sources are
// copied byte for byte, others are encoded as JPEG).
void WriteEasyMocap(const Capture& capture, const fs::path& out_dir, int max_frames = 0);

// ---- whole-capture importers -------------------------------------------------

Capture ImportPanoptic(const fs::path& dir, const ImportOptions& options = {});
// `source` is the .qca.txt file or a folder holding exactly one.
Capture ImportQualisys(const fs::path& source, const ImportOptions& options = {});
Capture ImportFourda(const fs::path& dir, const ImportOptions& options = {});
// `source` is the *_par.txt file or a folder holding exactly one.
Capture ImportMiddlebury(const fs::path& source, const ImportOptions& options = {});
Capture ImportEasyMocap(const fs::path& dir, const ImportOptions& options = {});

Capture ImportCapture(ImportFormat format, const fs::path& source,
                      const ImportOptions& options = {});

// Makes `capture` self-contained under `dir`: image frames are copied to
// images/<view>/<frame:06d>.<ext> (extension kept), video files to
// videos/<view>.<ext>; missing videos are left out of the copy and keep their
// original (absolute) path. Writes capture.json + calibration.json
// (WriteCapture) and returns the capture as ReadCapture(dir) would see it.
Capture WriteImportedCapture(const Capture& capture, const fs::path& dir);

}  // namespace u4d
