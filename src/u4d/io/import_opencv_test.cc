// `u4d import opencv` (import_opencv.h) on files written by cv::FileStorage
// itself, in the layouts studios and OpenCV's calibration samples use, and
// on a real calibration (CMU Panoptic's, ../shared/data) written out as
// FileStorage and read back.
#include <functional>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "u4d/io/import_calibration.h"
#include "u4d/io/import_opencv.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

using test_util::ExpectErrorMentions;

cv::Mat ToCv(const Eigen::Matrix3d& m) {
  cv::Mat out(3, 3, CV_64F);
  for (int i = 0; i < 9; ++i) out.at<double>(i / 3, i % 3) = m(i / 3, i % 3);
  return out;
}

cv::Mat Rodrigues(const Eigen::Matrix3d& r) {
  cv::Mat rvec;
  cv::Rodrigues(ToCv(r), rvec);
  return rvec;
}

cv::Mat Column(const Eigen::Vector3d& v) { return (cv::Mat_<double>(3, 1) << v[0], v[1], v[2]); }

cv::Mat Dist(const Camera& c, int n) {
  cv::Mat d = cv::Mat::zeros(n, 1, CV_64F);
  for (int i = 0; i < 5; ++i) d.at<double>(i) = c.dist[i];
  return d;
}

// Ground-truth cameras: a ring of `n` looking at the origin from 3-4 m,
// distinct intrinsics and distortion.
std::vector<Camera> RingCameras(int n, int width, int height) {
  std::vector<Camera> out;
  for (int i = 0; i < n; ++i) {
    Camera c;
    c.width = width;
    c.height = height;
    c.K << 600 + 20 * i, 0, width / 2.0 + i, 0, 610 + 20 * i, height / 2.0 - i, 0, 0, 1;
    c.dist = {-0.2 + 0.01 * i, 0.05, 0.001 * i, -0.0005, 0.01};
    const double a = 2 * M_PI * i / n;
    const Eigen::Vector3d centre(3.5 * std::sin(a), -1.2 - 0.1 * i, -3.5 * std::cos(a));
    const Eigen::Vector3d z = (-centre).normalized();
    const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d r;
    r << x.transpose(), y.transpose(), z.transpose();
    c.cam_from_world.rotation = r;
    c.cam_from_world.translation = -r * centre;
    out.push_back(c);
  }
  return out;
}

void ExpectSameCamera(const Camera& truth, const Camera& got, const std::string& name) {
  SCOPED_TRACE(name);
  EXPECT_EQ(got.width, truth.width);
  EXPECT_EQ(got.height, truth.height);
  EXPECT_LT((got.K - truth.K).cwiseAbs().maxCoeff(), 1e-9);
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(got.dist[i], truth.dist[i], 1e-12);
  EXPECT_LT((got.cam_from_world.rotation - truth.cam_from_world.rotation).cwiseAbs().maxCoeff(),
            1e-9);
  EXPECT_LT((got.cam_from_world.translation - truth.cam_from_world.translation).norm(), 1e-9);
}

// The seated-person layout: cam<i>.xml per camera (CameraMatrix,
// DistortionCoeffs, RotationValues as a Rodrigues vector, TranslationValues
// in mm, no image size) and a video cam<i>.avi beside it.
void WriteSeatedLayout(const fs::path& dir, const std::vector<Camera>& cams, int frames) {
  for (size_t i = 0; i < cams.size(); ++i) {
    const std::string name = "cam" + std::to_string(i + 1);
    cv::FileStorage out((dir / (name + ".xml")).string(), cv::FileStorage::WRITE);
    out << "CameraMatrix" << ToCv(cams[i].K) << "DistortionCoeffs" << Dist(cams[i], 5)
        << "RotationValues" << Rodrigues(cams[i].cam_from_world.rotation) << "TranslationValues"
        << Column(cams[i].cam_from_world.translation * 1000.0);
    out.release();
    cv::VideoWriter video((dir / (name + ".avi")).string(),
                          cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 50.0,
                          cv::Size(cams[i].width, cams[i].height));
    ASSERT_TRUE(video.isOpened()) << "cannot write an MJPG .avi here";
    for (int f = 0; f < frames; ++f)
      video << cv::Mat(cams[i].height, cams[i].width, CV_8UC3, cv::Scalar(40 * f, 90, 160));
  }
}

TEST(ImportOpenCv, PerCameraXmlInMillimetresWithVideos) {
  const fs::path dir = test_util::FreshTestDir("import_opencv", "seated");
  const std::vector<Camera> truth = RingCameras(4, 644, 486);
  WriteSeatedLayout(dir, truth, 3);
  ImportOptions options;
  options.unit = "mm";
  const Capture c = ImportOpenCv(dir, options);
  ASSERT_EQ(c.NumViews(), 4);
  EXPECT_EQ(c.num_frames, 3);
  EXPECT_NEAR(c.fps, 50.0, 1e-6);
  EXPECT_TRUE(c.source_frames.empty());  // videos: consecutive frames
  for (int v = 0; v < 4; ++v) {
    EXPECT_EQ(c.views[v].name, "cam" + std::to_string(v + 1));
    EXPECT_EQ(c.views[v].source.kind, FrameSource::Kind::kVideo);
    ExpectSameCamera(truth[v], c.views[v].cameras[0], c.views[v].name);
  }
  // The same files read in metres are 1000x too far: the unit is applied.
  const auto in_m = ReadOpenCvCalibration(dir, 1.0);
  EXPECT_NEAR(in_m[0].camera.cam_from_world.translation.norm(),
              1000.0 * truth[0].cam_from_world.translation.norm(), 1e-6);
  EXPECT_EQ(in_m[0].camera.width, 0);  // no size in the files: taken from the frames
}

// One YAML with a section per camera, the spellings of OpenCV's calibration
// samples (image_width, image_height, camera_matrix, distortion_coefficients)
// and solvePnP's (rvec, tvec); the rotation as a vector in one section and a
// matrix in another; 8 distortion values (rational terms 0); image folders.
TEST(ImportOpenCv, SingleYamlWithSampleSpellingsAndImageFolders) {
  const fs::path dir = test_util::FreshTestDir("import_opencv", "yaml");
  const std::vector<Camera> truth = RingCameras(3, 320, 240);
  fs::create_directories(dir / "calibration");
  {
    cv::FileStorage out((dir / "calibration" / "rig.yml").string(), cv::FileStorage::WRITE);
    out << "calibration_time"
        << "today"
        << "nframes" << 12;
    for (size_t i = 0; i < truth.size(); ++i) {
      const Camera& c = truth[i];
      out << "cam_" + std::to_string(i) << "{";
      out << "image_width" << c.width << "image_height" << c.height;
      out << "camera_matrix" << ToCv(c.K) << "distortion_coefficients" << Dist(c, i == 2 ? 8 : 5);
      if (i == 1)
        out << "rvec" << ToCv(c.cam_from_world.rotation);
      else
        out << "rvec" << Rodrigues(c.cam_from_world.rotation);
      out << "tvec" << Column(c.cam_from_world.translation) << "avg_reprojection_error" << 0.3;
      out << "}";
    }
  }
  for (size_t i = 0; i < truth.size(); ++i) {
    const fs::path folder = dir / "images" / ("cam_" + std::to_string(i));
    fs::create_directories(folder);
    for (int f = 0; f < 2; ++f)
      cv::imwrite((folder / fmt::format("cam_{}_{:04d}.png", i, f + 7)).string(),
                  cv::Mat(240, 320, CV_8UC3, cv::Scalar(10, 20, 30)));
  }
  const Capture c = ImportOpenCv(dir);
  ASSERT_EQ(c.NumViews(), 3);
  EXPECT_EQ(c.num_frames, 2);  // frames paired by number across differently named files
  EXPECT_EQ(c.source_frames, (std::vector<int64_t>{7, 8}));  // consecutive: no cut
  EXPECT_TRUE(ContinuesFrom(c, 1, 1.0));
  for (int v = 0; v < 3; ++v) {
    EXPECT_EQ(c.views[v].name, "cam_" + std::to_string(v));
    EXPECT_EQ(c.views[v].source.kind, FrameSource::Kind::kImages);
    ExpectSameCamera(truth[v], c.views[v].cameras[0], c.views[v].name);
  }
  // The file itself as the source: its folder's parent holds the frames.
  EXPECT_EQ(ImportOpenCv(dir / "calibration" / "rig.yml").NumViews(), 3);
}

// A real calibration (CMU Panoptic, 31 cameras with distortion) written out
// by cv::FileStorage in both layouts and read back.
TEST(ImportOpenCv, RealPanopticCalibrationRoundTrip) {
  const fs::path json = DataDir() / "panoptic_demo" / "camera_parameters.json";
  U4D_SKIP_WITHOUT_SHARED_DATA(json);
  const std::vector<NamedCamera> truth = ReadPanopticCalibration(json);
  ASSERT_GT(truth.size(), 10u);
  // Per camera XML, Rodrigues rotation, millimetres, size keys ImageWidth/Height.
  const fs::path xml_dir = test_util::FreshTestDir("import_opencv", "panoptic_xml");
  for (const NamedCamera& nc : truth) {
    const Camera& c = nc.camera;
    cv::FileStorage out((xml_dir / (nc.name + ".xml")).string(), cv::FileStorage::WRITE);
    out << "ImageWidth" << c.width << "ImageHeight" << c.height << "CameraMatrix" << ToCv(c.K)
        << "DistortionCoeffs" << Dist(c, 5) << "RotationValues"
        << Rodrigues(c.cam_from_world.rotation) << "TranslationValues"
        << Column(c.cam_from_world.translation * 1000.0);
  }
  // One YAML, rotation matrices, centimetres, image_size.
  const fs::path yml = test_util::FreshTestDir("import_opencv", "panoptic_yml") / "all.yaml";
  {
    cv::FileStorage out(yml.string(), cv::FileStorage::WRITE);
    for (const NamedCamera& nc : truth) {
      const Camera& c = nc.camera;
      out << "c" + nc.name << "{"
          << "image_size" << std::vector<int>{c.width, c.height} << "K" << ToCv(c.K) << "dist"
          << Dist(c, 5) << "R" << ToCv(c.cam_from_world.rotation) << "T"
          << Column(c.cam_from_world.translation * 100.0) << "}";
    }
  }
  const auto from_xml = ReadOpenCvCalibration(xml_dir, 1e-3);
  const auto from_yml = ReadOpenCvCalibration(yml, 1e-2);
  ASSERT_EQ(from_xml.size(), truth.size());
  ASSERT_EQ(from_yml.size(), truth.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    // Files are read in name order; the YAML keeps the file's order.
    EXPECT_EQ(from_yml[i].name, "c" + truth[i].name);
    auto it = std::find_if(from_xml.begin(), from_xml.end(),
                           [&](const NamedCamera& n) { return n.name == truth[i].name; });
    ASSERT_NE(it, from_xml.end()) << truth[i].name;
    ExpectSameCamera(truth[i].camera, it->camera, "xml " + truth[i].name);
    ExpectSameCamera(truth[i].camera, from_yml[i].camera, "yaml " + truth[i].name);
  }
}

// Writes each (text, reason) of `bad` to a file in `dir` and expects reading
// it as a calibration to fail naming the file, the reason and `rule`.
void ExpectYamlRefused(const fs::path& dir,
                       const std::vector<std::pair<std::string, std::string>>& bad,
                       const std::string& rule) {
  for (size_t i = 0; i < bad.size(); ++i) {
    const fs::path p = dir / ("bad" + std::to_string(i) + ".yml");
    WriteTextFileAtomic(p, bad[i].first);
    ExpectErrorMentions([&] { ReadOpenCvCalibration(p, 1); }, {p.string(), bad[i].second, rule});
  }
}

// OpenCV's YAML parser never returns on these (multi-document input, see
// io/file_storage.cc); they are refused, naming the file and the line, and a
// file as cv::FileStorage writes it ('%YAML:1.0', '---', one document) reads.
TEST(ImportOpenCv, OnlyOneYamlDocumentReachesOpenCvsParser) {
  const fs::path dir = test_util::FreshTestDir("import_opencv", "yaml_documents");
  const Camera cam = RingCameras(1, 64, 48)[0];
  const fs::path good = dir / "good.yml";
  {
    cv::FileStorage out(good.string(), cv::FileStorage::WRITE);
    out << "K" << ToCv(cam.K) << "rvec" << Rodrigues(cam.cam_from_world.rotation) << "tvec"
        << Column(Eigen::Vector3d(1, 2, 3));
  }
  EXPECT_EQ(ReadTextFile(good).substr(0, 14), "%YAML:1.0\n---\n");
  EXPECT_EQ(ReadOpenCvCalibration(good, 1).size(), 1u);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"%YAML:1.0\n---%YAML:1.0\n-\n--\nK: 1\n", "content on the '---' line"},
      {"%YAML:1.0\n---\nK: 1\n...\n-\n--\n", "content after the document's end"},
      {"%YAML:1.0\nK: 1\n---\n- 1\n", "a second document"}};
  ExpectYamlRefused(dir, bad, "only one YAML document");
}

// Nor on other malformed YAML the fuzzer found (io/file_storage.cc): only
// the subset cv::FileStorage writes reaches it. That subset, with matrices
// and a flow sequence over several lines, reads.
TEST(ImportOpenCv, OnlyTheYamlOpenCvWritesReachesItsParser) {
  const fs::path dir = test_util::FreshTestDir("import_opencv", "yaml_lines");
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"%YAML:1.0\nK:\n  dt: d\n abc: 1\n", "indented as no enclosing block"},
      {"%YAML:1.0\nK:\n  dt: d\n abc-x\n", "neither 'key: value'"},
      {"%YAML:1.0\nK: 1\nd: \xff\n", "non-text byte"},
      {"%YAML:1.0\nK: [ 1, 2\n", "not closed"},
      {"%YAML:1.0\nK: 1 ]\n", "closes nothing"},
      {"%YAML:1.0\n---\n a: 1\n- x\n", "first line is indented"}};
  ExpectYamlRefused(dir, bad, "only the YAML that cv::FileStorage writes");
  const fs::path good = dir / "good.yml";
  WriteTextFileAtomic(good,
                      "%YAML:1.0\n---\nK: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                      "   data: [ 100., 0., 32., 0., 100.,\n       24., 0., 0., 1. ]\n"
                      "rvec: !!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n"
                      "   data: [ 0., 0., 0. ]\ntvec: !!opencv-matrix\n   rows: 3\n   cols: 1\n"
                      "   dt: d\n   data: [ 1., 2., 3. ]\nnames:\n  - \"a\"\n");
  EXPECT_EQ(ReadOpenCvCalibration(good, 1).size(), 1u);
}

TEST(ImportOpenCv, BadFilesNameTheFileAndKey) {
  const fs::path dir = test_util::FreshTestDir("import_opencv", "bad");
  const Camera cam = RingCameras(1, 64, 48)[0];
  auto write = [&](const std::string& file, const std::function<void(cv::FileStorage&)>& body) {
    const fs::path p = dir / file;
    cv::FileStorage out(p.string(), cv::FileStorage::WRITE);
    body(out);
    return p;
  };
  const fs::path no_k = write("no_k.yml", [&](cv::FileStorage& o) {
    o << "rvec" << Rodrigues(cam.cam_from_world.rotation) << "tvec"
      << Column(Eigen::Vector3d(1, 2, 3));
  });
  ExpectErrorMentions([&] { ReadOpenCvCalibration(no_k, 1); },
                      {no_k.string(), "no camera found", "camera_matrix"});
  const fs::path short_t = write("short_t.xml", [&](cv::FileStorage& o) {
    o << "camera_matrix" << ToCv(cam.K) << "rvec" << Rodrigues(cam.cam_from_world.rotation)
      << "tvec" << cv::Mat(cv::Mat::zeros(2, 1, CV_64F));
  });
  ExpectErrorMentions([&] { ReadOpenCvCalibration(short_t, 1); },
                      {short_t.string(), "'tvec'", "3 values, found 2"});
  const fs::path no_r = write("no_r.xml", [&](cv::FileStorage& o) {
    o << "K" << ToCv(cam.K) << "T" << Column(Eigen::Vector3d(1, 2, 3));
  });
  ExpectErrorMentions([&] { ReadOpenCvCalibration(no_r, 1); },
                      {no_r.string(), "no rotation", "RotationValues"});
  const fs::path not_rot = write("not_rot.yml", [&](cv::FileStorage& o) {
    o << "K" << ToCv(cam.K) << "R" << ToCv(2.0 * cam.cam_from_world.rotation) << "T"
      << Column(Eigen::Vector3d(1, 2, 3));
  });
  ExpectErrorMentions([&] { ReadOpenCvCalibration(not_rot, 1); },
                      {not_rot.string(), "'R'", "not a rotation"});
  const fs::path rational = write("rational.yml", [&](cv::FileStorage& o) {
    cv::Mat d = Dist(cam, 8);
    d.at<double>(5) = 0.1;
    o << "K" << ToCv(cam.K) << "dist" << d << "rvec" << Rodrigues(cam.cam_from_world.rotation)
      << "tvec" << Column(Eigen::Vector3d(1, 2, 3));
  });
  ExpectErrorMentions([&] { ReadOpenCvCalibration(rational, 1); },
                      {rational.string(), "'dist'", "only k1, k2, p1, p2, k3"});
  const fs::path nan_k = write("nan_k.yml", [&](cv::FileStorage& o) {
    cv::Mat k = ToCv(cam.K);
    k.at<double>(0, 0) = std::nan("");
    o << "camera_matrix" << k << "rvec" << Rodrigues(cam.cam_from_world.rotation) << "tvec"
      << Column(Eigen::Vector3d(1, 2, 3));
  });
  ExpectErrorMentions([&] { ReadOpenCvCalibration(nan_k, 1); },
                      {nan_k.string(), "'camera_matrix'", "non-finite"});
  const fs::path garbled = dir / "garbled.yml";
  WriteTextFileAtomic(garbled, "%YAML:1.0\ncamera_matrix: [1, 2\n");
  ExpectErrorMentions([&] { ReadOpenCvCalibration(garbled, 1); }, {garbled.string()});
  ExpectErrorMentions([&] { ReadOpenCvCalibration(dir / "missing.xml", 1); }, {"missing.xml"});
  // A good camera without frames: the importer names the camera.
  const fs::path lone_dir = test_util::FreshTestDir("import_opencv", "lone");
  {
    cv::FileStorage o((lone_dir / "cam7.xml").string(), cv::FileStorage::WRITE);
    o << "CameraMatrix" << ToCv(cam.K) << "RotationValues" << Rodrigues(cam.cam_from_world.rotation)
      << "TranslationValues" << Column(cam.cam_from_world.translation);
  }
  ExpectErrorMentions([&] { ImportOpenCv(lone_dir); }, {"no frames for camera 'cam7'"});
  ImportOptions bad_unit;
  bad_unit.unit = "inch";
  ExpectErrorMentions([&] { ImportOpenCv(lone_dir, bad_unit); }, {"unit", "inch"});
}

}  // namespace
}  // namespace u4d
