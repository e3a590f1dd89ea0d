// Tests of the calibration importers on the real data in /work/shared/data.
// Each format's calibration is checked against the images (or, for Shelf,
// against independent 2D detections), and against a deliberately wrong copy
// of the same calibration, so a check that cannot fail is not counted.
#include <algorithm>
#include <fstream>
#include <random>

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "u4d/geometry/epipolar.h"
#include "u4d/io/frame_reader.h"
#include "u4d/io/import_calibration.h"
#include "u4d/io/import_fourda.h"
#include "u4d/io/import_internal.h"
#include "u4d/util/check.h"
#include "u4d/util/data_dir.h"
#include "u4d/util/testing.h"

namespace u4d {
namespace {

const fs::path kData = DataDir();

// A fresh temporary directory, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& tag)
      : path_(fs::temp_directory_path() /
              fmt::format("u4d_import_test_{}_{}", tag, static_cast<long>(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

double Percentile(std::vector<double> v, double p) {
  U4D_ASSERT(!v.empty());
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// Least-squares point closest to all optical axes, and each axis' distance to it.
Eigen::Vector3d AxesCentre(const std::vector<Camera>& cams, std::vector<double>* distances) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Camera& c : cams) {
    const Eigen::Vector3d d = c.ViewDirection().normalized();
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - d * d.transpose();
    a += p;
    b += p * c.Center();
  }
  const Eigen::Vector3d x = a.ldlt().solve(b);
  distances->clear();
  for (const Camera& c : cams) {
    const Eigen::Vector3d d = c.ViewDirection().normalized();
    const Eigen::Vector3d v = x - c.Center();
    distances->push_back((v - v.dot(d) * d).norm());
  }
  return x;
}

std::vector<Camera> Cameras(const Capture& c) {
  std::vector<Camera> out;
  for (const CaptureView& v : c.views) out.push_back(v.cameras[0]);
  return out;
}

struct Matches {
  std::vector<Eigen::Vector2d> x1, x2;  // raw (distorted) pixels
};

// SIFT matches with Lowe's ratio test (0.7) and a mutual-nearest check.
Matches SiftMatches(const cv::Mat& image1, const cv::Mat& image2) {
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(4000);
  std::vector<cv::KeyPoint> k1, k2;
  cv::Mat d1, d2, g1, g2;
  cv::cvtColor(image1, g1, cv::COLOR_BGR2GRAY);
  cv::cvtColor(image2, g2, cv::COLOR_BGR2GRAY);
  sift->detectAndCompute(g1, cv::noArray(), k1, d1);
  sift->detectAndCompute(g2, cv::noArray(), k2, d2);
  cv::BFMatcher matcher(cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> m12, m21;
  matcher.knnMatch(d1, d2, m12, 2);
  matcher.knnMatch(d2, d1, m21, 1);
  Matches out;
  for (const auto& m : m12) {
    if (m.size() < 2 || m[0].distance > 0.7f * m[1].distance) continue;
    if (m21[m[0].trainIdx].empty() || m21[m[0].trainIdx][0].trainIdx != m[0].queryIdx) continue;
    const cv::Point2f p1 = k1[m[0].queryIdx].pt, p2 = k2[m[0].trainIdx].pt;
    out.x1.emplace_back(p1.x, p1.y);
    out.x2.emplace_back(p2.x, p2.y);
  }
  return out;
}

// Symmetric epipolar distances (pixels, mean of both directions) of the
// matches under the two cameras, after undistorting the keypoints.
std::vector<double> EpipolarDistances(const Matches& m, const Camera& cam1, const Camera& cam2) {
  const Eigen::Matrix3d f12 = FundamentalFromCameras(cam1, cam2);
  const Eigen::Matrix3d f21 = FundamentalFromCameras(cam2, cam1);
  std::vector<double> d;
  for (size_t i = 0; i < m.x1.size(); ++i) {
    const Eigen::Vector2d u1 = UndistortPixel(cam1, m.x1[i]);
    const Eigen::Vector2d u2 = UndistortPixel(cam2, m.x2[i]);
    d.push_back(0.5 * (EpipolarDistance(f12, u1, u2) + EpipolarDistance(f21, u2, u1)));
  }
  return d;
}

// The same camera turned by `degrees` about `axis` of its own frame.
Camera Rotated(Camera cam, double degrees, const Eigen::Vector3d& axis) {
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(degrees * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  const Eigen::Vector3d centre = cam.Center();
  cam.cam_from_world.rotation = turn * cam.cam_from_world.rotation;
  cam.cam_from_world.translation = -cam.cam_from_world.rotation * centre;
  return cam;
}

// The statistic we judge a calibration by. The views of these rigs are 45-60
// degrees apart, so ratio-test SIFT matches are mostly wrong (measured: the
// median epipolar distance is hundreds of pixels under any calibration) and
// a median or low percentile is not a usable statistic. We therefore score
// the calibration the way RANSAC scores a model: the number of matches
// within 3 px of their epipolar lines (symmetric distance; SIFT localises to
// about a pixel). A wrong match lands in that 6 px band by chance with a
// probability of roughly 6 / (image extent) ~ 0.5%, so a correct calibration
// gathers a consensus that a wrong one -- the same calibration with camera 2
// turned by 1 degree about its x or y axis (whichever moves the lines more),
// which moves the lines by up to f tan(1 deg) ~ 20-30 px -- cannot.
struct EpipolarResult {
  int matches = 0;
  int inliers = 0;        // matches within kInlierPx under the calibration
  int inliers_wrong = 0;  // same, camera 2 turned by 1 degree
  double inlier_median = 0;
};
constexpr double kInlierPx = 3.0;

EpipolarResult CheckEpipolar(const Camera& cam1, const std::vector<cv::Mat>& images1,
                             const Camera& cam2, const std::vector<cv::Mat>& images2,
                             const std::string& what) {
  Matches m;
  for (size_t i = 0; i < images1.size(); ++i) {
    const Matches mi = SiftMatches(images1[i], images2[i]);
    m.x1.insert(m.x1.end(), mi.x1.begin(), mi.x1.end());
    m.x2.insert(m.x2.end(), mi.x2.begin(), mi.x2.end());
  }
  EpipolarResult r;
  r.matches = static_cast<int>(m.x1.size());
  std::vector<double> in;
  for (double d : EpipolarDistances(m, cam1, cam2))
    if (d < kInlierPx) in.push_back(d);
  r.inliers = static_cast<int>(in.size());
  if (!in.empty()) r.inlier_median = Percentile(in, 0.5);
  // A turn moves the lines only where its image motion crosses them: take the
  // more damaging of turns about the camera's x and y axes.
  r.inliers_wrong = r.matches;
  for (const Eigen::Vector3d axis : {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()}) {
    int n = 0;
    for (double d : EpipolarDistances(m, cam1, Rotated(cam2, 1.0, axis))) n += d < kInlierPx;
    r.inliers_wrong = std::min(r.inliers_wrong, n);
  }
  std::printf(
      "[epipolar] %s: %d matches, %d within %.0f px (median %.2f px); camera 2 turned by 1 deg: "
      "%d within %.0f px\n",
      what.c_str(), r.matches, r.inliers, kInlierPx, r.inlier_median, r.inliers_wrong, kInlierPx);
  return r;
}

template <typename F>
void ExpectErrorNaming(F&& f, const std::string& needle, const std::string& what) {
  try {
    f();
    ADD_FAILURE() << what << ": no u4d::Error thrown";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
        << what << ": message does not name '" << needle << "': " << e.what();
  }
}

void WriteText(const fs::path& p, const std::string& s) {
  std::ofstream out(p, std::ios::binary);
  out << s;
}

// ---- Panoptic ----------------------------------------------------------------

// The two closest pairs of the five Panoptic views (00_06-00_13 at 47 deg,
// 00_03-00_12 at 59 deg), matches pooled over the five instants.
void CheckPanopticLikeEpipolar(const Capture& capture, const std::string& what, int num_pairs = 2) {
  FrameReader reader(capture);
  std::vector<std::pair<std::string, std::string>> pairs = {{"00_06", "00_13"}, {"00_03", "00_12"}};
  pairs.resize(num_pairs);
  for (auto [na, nb] : pairs) {
    const int a = capture.ViewIndex(na), b = capture.ViewIndex(nb);
    std::vector<cv::Mat> ia, ib;
    for (int f = 0; f < capture.num_frames; ++f) {
      ia.push_back(reader.Read(a, f));
      ib.push_back(reader.Read(b, f));
    }
    const EpipolarResult r =
        CheckEpipolar(capture.views[a].cameras[0], ia, capture.views[b].cameras[0], ib,
                      what + " " + na + "-" + nb);
    EXPECT_GE(r.inliers, 10) << na << "-" << nb;
    EXPECT_GE(r.inliers, 3 * std::max(1, r.inliers_wrong)) << na << "-" << nb;
  }
}

TEST(ImportPanoptic, CalibrationGeometry) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "panoptic_demo");
  const auto cams = ReadPanopticCalibration(kData / "panoptic_demo/camera_parameters.json");
  ASSERT_EQ(cams.size(), 31u);
  std::vector<Camera> c;
  for (const auto& nc : cams) c.push_back(nc.camera);
  std::vector<double> dist;
  const Eigen::Vector3d centre = AxesCentre(c, &dist);
  // The HD cameras sit on a dome of about 2.5-3.5 m radius (so the cm -> m
  // conversion is right) and look at its middle.
  for (size_t i = 0; i < c.size(); ++i) {
    const double radius = (c[i].Center() - centre).norm();
    EXPECT_GT(radius, 1.5) << cams[i].name;
    EXPECT_LT(radius, 5.0) << cams[i].name;
    EXPECT_LT(dist[i], 0.6) << cams[i].name << " optical axis misses the dome centre";
    EXPECT_TRUE(c[i].InImage(c[i].Project(centre))) << cams[i].name;
  }
  std::printf("[panoptic] axes centre (%.2f %.2f %.2f) m, max axis distance %.3f m\n", centre.x(),
              centre.y(), centre.z(), *std::max_element(dist.begin(), dist.end()));
}

TEST(ImportPanoptic, EpipolarOnImages) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "panoptic_demo");
  const Capture capture = ImportPanoptic(kData / "panoptic_demo");
  ASSERT_EQ(capture.NumViews(), 5);
  ASSERT_EQ(capture.num_frames, 5);
  EXPECT_EQ(capture.views[0].name, "00_03");
  // The five instants of the demo, tens of seconds apart (file names).
  EXPECT_EQ(capture.source_frames, (std::vector<int64_t>{4500, 5514, 6859, 9348, 13007}));
  EXPECT_FALSE(ContinuesFrom(capture, 1, 1.0));
  CheckPanopticLikeEpipolar(capture, "panoptic");
}

TEST(ImportPanoptic, BadInput) {
  TempDir tmp("panoptic");
  const fs::path missing = tmp.path() / "nope.json";
  ExpectErrorNaming([&] { ReadPanopticCalibration(missing); }, missing.string(), "missing file");
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "panoptic_demo");
  const std::string text = ReadTextFile(kData / "panoptic_demo/camera_parameters.json");
  const fs::path truncated = tmp.path() / "truncated.json";
  WriteText(truncated, text.substr(0, text.size() / 2));
  ExpectErrorNaming([&] { ReadPanopticCalibration(truncated); }, truncated.string(), "truncated");
  nlohmann::json j = nlohmann::json::parse(text);
  j["cameras"][3]["K"][2] = {0, 1};  // 8 numbers instead of 9
  const fs::path wrong_size = tmp.path() / "wrong_size.json";
  WriteText(wrong_size, j.dump());
  ExpectErrorNaming([&] { ReadPanopticCalibration(wrong_size); }, wrong_size.string(),
                    "wrong K size");
  j = nlohmann::json::parse(text);
  j["cameras"][0]["R"][0][0] = 2.0;  // not a rotation
  const fs::path not_rot = tmp.path() / "not_rotation.json";
  WriteText(not_rot, j.dump());
  ExpectErrorNaming([&] { ReadPanopticCalibration(not_rot); }, not_rot.string(), "not rotation");
  j = nlohmann::json::parse(text);
  j["cameras"][0]["resolution"][1] = 540.5;  // not a whole number of pixels
  const fs::path half = tmp.path() / "half_pixel.json";
  WriteText(half, j.dump());
  ExpectErrorNaming([&] { ReadPanopticCalibration(half); }, "image height", "fractional height");
}

// ---- Qualisys ----------------------------------------------------------------

TEST(ImportQualisys, CalibrationAndEpipolar) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "pose2sim_single");
  const Capture capture = ImportQualisys(kData / "pose2sim_single");
  ASSERT_EQ(capture.NumViews(), 4);
  EXPECT_EQ(capture.num_frames, 100);
  const std::vector<Camera> cams = Cameras(capture);
  for (const Camera& c : cams) {
    // 1088 in the file; some videos decode cropped to 1080 (codec crop).
    EXPECT_GE(c.width, 1080);
    EXPECT_LE(c.width, 1088);
    EXPECT_EQ(c.height, 1920);
  }
  std::vector<double> dist;
  const Eigen::Vector3d centre = AxesCentre(cams, &dist);
  for (size_t i = 0; i < cams.size(); ++i) {
    EXPECT_LT(dist[i], 1.0) << capture.views[i].name;
    EXPECT_TRUE(cams[i].InImage(cams[i].Project(centre))) << capture.views[i].name;
    const double range = (cams[i].Center() - centre).norm();
    EXPECT_GT(range, 1.5);
    EXPECT_LT(range, 8.0);
  }
  std::printf("[qualisys] axes centre (%.2f %.2f %.2f) m, max axis distance %.3f m\n", centre.x(),
              centre.y(), centre.z(), *std::max_element(dist.begin(), dist.end()));
  // The principal point is near the image centre only if the /64 scaling and
  // the fov_video offset are right.
  for (const Camera& c : cams) {
    EXPECT_NEAR(c.K(0, 2), 0.5 * c.width, 0.05 * c.width);
    EXPECT_NEAR(c.K(1, 2), 0.5 * c.height, 0.05 * c.height);
  }
  // Qualisys' world is z up with the floor at z = 0: cameras on tripods
  // stand 1-3 m high and look slightly down.
  for (const Camera& c : cams) {
    EXPECT_GT(c.Center().z(), 1.0);
    EXPECT_LT(c.Center().z(), 3.0);
    EXPECT_LT(c.ViewDirection().z(), 0.0);
  }
  // Epipolar consensus on the closest pair (cam01-cam02, 49 deg apart);
  // the rig is static, so frames 0 and 99 add matches on the moving person.
  FrameReader reader(capture);
  const EpipolarResult r =
      CheckEpipolar(cams[0], {reader.Read(0, 0), reader.Read(0, 99)}, cams[1],
                    {reader.Read(1, 0), reader.Read(1, 99)}, "qualisys cam01-cam02");
  EXPECT_GE(r.inliers, 3 * std::max(1, r.inliers_wrong));

  // The views are videos: decoded concurrently (one reader, every view at
  // once, as the pipeline reads them), the frames are those decoded one view
  // at a time.
  ASSERT_EQ(capture.views[0].source.kind, FrameSource::Kind::kVideo);
  FrameReader serial(capture), parallel(capture);
  for (const int frame : {3, 4}) {
    std::vector<cv::Mat> one_by_one(capture.NumViews()), together(capture.NumViews());
    for (int v = 0; v < capture.NumViews(); ++v) one_by_one[v] = serial.Read(v, frame);
    tbb::parallel_for(0, capture.NumViews(), [&](int v) { together[v] = parallel.Read(v, frame); });
    for (int v = 0; v < capture.NumViews(); ++v)
      EXPECT_EQ(cv::norm(one_by_one[v], together[v], cv::NORM_INF), 0.0) << "view " << v;
  }
}

TEST(ImportQualisys, BadInput) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "pose2sim_single");
  TempDir tmp("qualisys");
  const std::string text = ReadTextFile(kData / "pose2sim_single/Calib.qca.txt");
  const fs::path nan = tmp.path() / "nan.qca.txt";
  std::string t = text;
  t.replace(t.find("r11=\"") + 5, 4, "nan ");
  WriteText(nan, t);
  ExpectErrorNaming([&] { ReadQualisysCalibration(nan); }, nan.string(), "NaN");
  const fs::path truncated = tmp.path() / "truncated.qca.txt";
  WriteText(truncated, text.substr(0, text.find("</camera>") + 200));
  ExpectErrorNaming([&] { ReadQualisysCalibration(truncated); }, truncated.string(), "truncated");
  const fs::path no_attr = tmp.path() / "no_attr.qca.txt";
  t = text;
  t.replace(t.find("focalLengthU"), 12, "focalLengthX");
  WriteText(no_attr, t);
  ExpectErrorNaming([&] { ReadQualisysCalibration(no_attr); }, "focalLengthU", "missing attribute");
  const fs::path huge = tmp.path() / "huge.qca.txt";
  t = text;
  const size_t fov = t.find("right=\"", t.find("<fov_video ")) + 7;
  t.replace(fov, t.find('"', fov) - fov, "1e30");
  WriteText(huge, t);
  ExpectErrorNaming([&] { ReadQualisysCalibration(huge); }, "image width", "width beyond int");
  // A calibration without its videos names the missing video.
  const fs::path alone = tmp.path() / "alone" / "Calib.qca.txt";
  fs::create_directories(alone.parent_path());
  WriteText(alone, text);
  ExpectErrorNaming([&] { ImportQualisys(alone.parent_path()); }, "cam01.mp4", "no videos");
}

// ---- 4D Association (Shelf) --------------------------------------------------

// Projects the Shelf ground-truth joints into every camera and measures the
// distance to the nearest OpenPose detection of the same joint type (BODY25,
// normalised coordinates times the image size). Frames where the joint is
// not detected are skipped. Returns the median over cameras, frames, people
// and joints.
double ShelfMedianDistance(const std::vector<NamedCamera>& cams, const FourdaGroundTruth& gt,
                           const std::vector<FourdaDetections>& dets, int* count) {
  std::vector<double> d;
  for (size_t c = 0; c < cams.size(); ++c) {
    const Camera& cam = cams[c].camera;
    for (size_t f = 0; f < gt.frames.size(); f += 3) {
      const FourdaDetectionFrame& det = dets[c].frames.at(f);
      for (const FourdaPerson3d& p : gt.frames[f]) {
        for (int j = 0; j < gt.num_joints; ++j) {
          const int bj = ShelfToBody25()[j];
          if (bj < 0 || det.joints[bj].cols() == 0) continue;
          const Eigen::Vector2d x = cam.Project(p.joints.col(j).head<3>());
          if (!x.allFinite() || !cam.InImage(x)) continue;
          double best = 1e9;
          for (int k = 0; k < det.joints[bj].cols(); ++k) {
            const Eigen::Vector2d y(det.joints[bj](0, k) * cam.width,
                                    det.joints[bj](1, k) * cam.height);
            best = std::min(best, (x - y).norm());
          }
          d.push_back(best);
        }
      }
    }
  }
  *count = static_cast<int>(d.size());
  return d.empty() ? 1e9 : Percentile(d, 0.5);
}

TEST(ImportFourda, ShelfGroundTruthMatchesDetections) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "shelf_pose");
  const fs::path dir = kData / "shelf_pose";
  const auto cams = ReadFourdaCalibration(dir / "calibration.json");
  ASSERT_EQ(cams.size(), 5u);
  const FourdaGroundTruth gt = ReadFourdaGroundTruth(dir / "gt.txt");
  EXPECT_EQ(gt.num_joints, 15);
  ASSERT_EQ(gt.frames.size(), 301u);
  std::vector<FourdaDetections> dets;
  for (const auto& nc : cams) {
    dets.push_back(ReadFourdaDetections(dir / "detection" / (nc.name + ".txt")));
    ASSERT_EQ(dets.back().frames.size(), 301u);
  }
  int n = 0;
  const double median = ShelfMedianDistance(cams, gt, dets, &n);
  // Wrong calibration: every camera takes the next camera's pose.
  std::vector<NamedCamera> wrong = cams;
  for (size_t c = 0; c < cams.size(); ++c)
    wrong[c].camera.cam_from_world = cams[(c + 1) % cams.size()].camera.cam_from_world;
  int n_wrong = 0;
  const double median_wrong = ShelfMedianDistance(wrong, gt, dets, &n_wrong);
  std::printf(
      "[shelf] GT joint to nearest same-type detection: median %.1f px over %d (poses "
      "rotated among cameras: %.1f px over %d)\n",
      median, n, median_wrong, n_wrong);
  EXPECT_GT(n, 1000);
  // A joint is ~10-20 px wide at this range; GT and OpenPose disagree on
  // where exactly it is, so 'a few tens of pixels at most'.
  EXPECT_LT(median, 20.0);
  EXPECT_GT(median_wrong, 5.0 * median);

  // The capture: five video views named 0-4 with 301 frames (the Shelf files
  // as published carry no video, so frames are unreadable and say so).
  const Capture capture = ImportFourda(dir);
  EXPECT_EQ(capture.NumViews(), 5);
  EXPECT_EQ(capture.num_frames, 301);
  FrameReader reader(capture);
  ExpectErrorNaming([&] { reader.Read(0, 0); }, "0.mp4", "missing video");
}

TEST(ImportFourda, BadInput) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "shelf_pose");
  TempDir tmp("fourda");
  const fs::path dir = kData / "shelf_pose";
  const std::string gt = ReadTextFile(dir / "gt.txt");
  const fs::path truncated = tmp.path() / "gt.txt";
  WriteText(truncated, gt.substr(0, gt.size() / 3));
  ExpectErrorNaming([&] { ReadFourdaGroundTruth(truncated); }, truncated.string(), "truncated gt");
  const std::string det = ReadTextFile(dir / "detection/0.txt");
  const fs::path garbled = tmp.path() / "det.txt";
  std::string g = det;
  g.replace(g.find("0.638639"), 8, "0.6x8639");
  WriteText(garbled, g);
  ExpectErrorNaming([&] { ReadFourdaDetections(garbled); }, garbled.string(), "garbled det");
  nlohmann::json j = ReadJsonFile(dir / "calibration.json");
  j["2"]["RT"].erase(j["2"]["RT"].begin());  // 11 numbers
  const fs::path wrong = tmp.path() / "calibration.json";
  WriteText(wrong, j.dump());
  ExpectErrorNaming([&] { ReadFourdaCalibration(wrong); }, wrong.string(), "RT size");
  ExpectErrorNaming([&] { ImportFourda(tmp.path() / "nope"); }, "nope", "missing folder");
}

// ---- Middlebury --------------------------------------------------------------

TEST(ImportMiddlebury, DinoSilhouettesInsideProjectedBox) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "dino_sparse_ring");
  const Capture capture = ImportMiddlebury(kData / "dino_sparse_ring");
  ASSERT_EQ(capture.NumViews(), 16);
  EXPECT_EQ(capture.num_frames, 1);
  // The tight bounding box from the dataset's README (same units as the file).
  const Eigen::Vector3d lo(-0.061897, -0.018874, -0.057845), hi(0.010897, 0.068227, 0.015495);
  const std::vector<Camera> cams = Cameras(capture);
  std::vector<double> dist;
  const Eigen::Vector3d centre = AxesCentre(cams, &dist);
  std::printf("[middlebury] axes centre (%.3f %.3f %.3f), box centre (%.3f %.3f %.3f)\n",
              centre.x(), centre.y(), centre.z(), 0.5 * (lo + hi).x(), 0.5 * (lo + hi).y(),
              0.5 * (lo + hi).z());
  EXPECT_LT((centre - 0.5 * (lo + hi)).norm(), 0.05);
  // Silhouette consistency. Silhouettes: grey > 0.19, dilated by 10 and
  // eroded by 7 pixels (the README's recipe). Carve a voxel grid over the
  // box with every view but v (a voxel survives unless some view sees it on
  // background; views it falls outside of do not vote), then project the
  // survivors into view v: with a right calibration they land on v's
  // silhouette; with view v turned by 2 degrees about its x or y axis (the
  // more damaging; f tan(2 deg) ~ 115 px) they do not.
  FrameReader reader(capture);
  std::vector<cv::Mat> sil;
  for (int v = 0; v < capture.NumViews(); ++v) {
    cv::Mat grey, mask;
    cv::cvtColor(reader.Read(v, 0), grey, cv::COLOR_BGR2GRAY);
    cv::threshold(grey, mask, 0.19 * 255, 255, cv::THRESH_BINARY);
    cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, {21, 21}));
    cv::erode(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, {15, 15}));
    sil.push_back(mask);
  }
  const int n = 40;
  std::vector<Eigen::Vector3d> grid;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        grid.push_back(lo + Eigen::Vector3d((i + 0.5) / n * (hi - lo).x(),
                                            (j + 0.5) / n * (hi - lo).y(),
                                            (k + 0.5) / n * (hi - lo).z()));
  auto on_silhouette = [&](const Camera& cam, const cv::Mat& mask, const Eigen::Vector3d& p) {
    const Eigen::Vector2d x = cam.Project(p);
    if (!x.allFinite() || !cam.InImage(x)) return -1;  // no vote
    return mask.at<uchar>(static_cast<int>(std::lround(x.y())),
                          static_cast<int>(std::lround(x.x()))) > 0
               ? 1
               : 0;
  };
  double worst = 1, best_wrong = 0;
  for (int v = 0; v < capture.NumViews(); ++v) {
    const Camera wrong_x = Rotated(cams[v], 2.0, Eigen::Vector3d::UnitX());
    const Camera wrong_y = Rotated(cams[v], 2.0, Eigen::Vector3d::UnitY());
    int kept = 0, hit = 0, seen = 0, hit_x = 0, seen_x = 0, hit_y = 0, seen_y = 0;
    for (const Eigen::Vector3d& p : grid) {
      bool carved = false;
      for (int u = 0; u < capture.NumViews() && !carved; ++u)
        carved = u != v && on_silhouette(cams[u], sil[u], p) == 0;
      if (carved) continue;
      ++kept;
      const int s1 = on_silhouette(cams[v], sil[v], p);
      const int sx = on_silhouette(wrong_x, sil[v], p);
      const int sy = on_silhouette(wrong_y, sil[v], p);
      if (s1 >= 0) ++seen, hit += s1;
      if (sx >= 0) ++seen_x, hit_x += sx;
      if (sy >= 0) ++seen_y, hit_y += sy;
    }
    ASSERT_GT(kept, 100) << capture.views[v].name << ": the hull of the other views is empty";
    worst = std::min(worst, seen ? static_cast<double>(hit) / seen : 0.0);
    const double share_x = seen_x ? static_cast<double>(hit_x) / seen_x : 0.0;
    const double share_y = seen_y ? static_cast<double>(hit_y) / seen_y : 0.0;
    best_wrong = std::max(best_wrong, std::min(share_x, share_y));
  }
  std::printf(
      "[middlebury] hull of the other views on the view's silhouette: worst view %.3f; "
      "view turned by 2 deg: best %.3f\n",
      worst, best_wrong);
  // Every view under the right calibration beats every view under a wrong
  // one (measured 0.950 vs 0.841; no margin is asserted, since any margin
  // would have been chosen after seeing these numbers).
  EXPECT_GT(worst, best_wrong);
}

TEST(ImportMiddlebury, BadInput) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "dino_sparse_ring");
  TempDir tmp("middlebury");
  const std::string text = ReadTextFile(kData / "dino_sparse_ring/dinoSR_par.txt");
  const fs::path nan = tmp.path() / "nan_par.txt";
  std::string t = text;
  t.replace(t.find("3310.400000"), 11, "nan");
  WriteText(nan, t);
  ExpectErrorNaming([&] { ReadMiddleburyCalibration(nan, 640, 480); }, nan.string(), "NaN");
  const fs::path truncated = tmp.path() / "truncated_par.txt";
  WriteText(truncated, text.substr(0, text.size() / 2));
  ExpectErrorNaming([&] { ReadMiddleburyCalibration(truncated, 640, 480); }, truncated.string(),
                    "truncated");
  // The par file without its images names the missing image.
  ExpectErrorNaming([&] { ImportMiddlebury(truncated); }, "dinoSR0001.png", "missing image");
}

// ---- EasyMocap (written from Panoptic, read back) -----------------------------

TEST(ImportEasyMocap, RoundTripFromPanoptic) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "panoptic_demo");
  TempDir tmp("easymocap");
  const Capture panoptic = ImportPanoptic(kData / "panoptic_demo");
  WriteEasyMocap(panoptic, tmp.path());
  const Capture em = ImportEasyMocap(tmp.path());
  ASSERT_EQ(em.NumViews(), panoptic.NumViews());
  ASSERT_EQ(em.num_frames, panoptic.num_frames);
  for (int v = 0; v < em.NumViews(); ++v) {
    const Camera& a = panoptic.views[v].cameras[0];
    const Camera& b = em.views[v].cameras[0];
    EXPECT_EQ(em.views[v].name, panoptic.views[v].name);
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_LT((a.K - b.K).norm(), 1e-9);
    for (int i = 0; i < 5; ++i) EXPECT_NEAR(a.dist[i], b.dist[i], 1e-12);
    EXPECT_LT((a.cam_from_world.rotation - b.cam_from_world.rotation).norm(), 1e-9);
    EXPECT_LT((a.cam_from_world.translation - b.cam_from_world.translation).norm(), 1e-9);
  }
  // The calibration read back agrees with the copied real images.
  // (one pair: the JPEG bytes are copies, so this checks the written cameras)
  CheckPanopticLikeEpipolar(em, "easymocap", 1);

  // Without Rot_ the reader falls back on the Rodrigues vector R_; without
  // H_/W_ on the image size.
  std::string extri = ReadTextFile(tmp.path() / "extri.yml");
  size_t pos;
  while ((pos = extri.find("Rot_")) != std::string::npos) extri.replace(pos, 4, "Xot_");
  WriteText(tmp.path() / "extri.yml", extri);
  std::string intri = ReadTextFile(tmp.path() / "intri.yml");
  while ((pos = intri.find("H_")) != std::string::npos) intri.replace(pos, 2, "Q_");
  WriteText(tmp.path() / "intri.yml", intri);
  const auto cams = ReadEasyMocapCalibration(tmp.path() / "intri.yml", tmp.path() / "extri.yml",
                                             tmp.path() / "images");
  ASSERT_EQ(cams.size(), panoptic.views.size());
  for (size_t v = 0; v < cams.size(); ++v) {
    EXPECT_LT((cams[v].camera.cam_from_world.rotation -
               panoptic.views[v].cameras[0].cam_from_world.rotation)
                  .norm(),
              1e-9);
    EXPECT_EQ(cams[v].camera.height, 1080);
  }

  // Bad input: a garbled file, a wrong matrix size, a NaN, a missing file.
  const fs::path garbled = tmp.path() / "garbled.yml";
  WriteText(garbled, intri.substr(0, intri.size() / 2) + "\n  ]]: {{\n");
  ExpectErrorNaming([&] { ReadEasyMocapCalibration(garbled, tmp.path() / "extri.yml"); },
                    garbled.string(), "garbled yml");
  const fs::path wrong_size = tmp.path() / "wrong_size.yml";
  // Simplest wrong size: K with 6 values.
  std::string ws = intri;
  {
    const size_t kk = ws.find("K_00_03");
    const size_t d0 = ws.find("data: [", kk) + 7;
    const size_t d1 = ws.find("]", d0);
    ws.replace(ws.find("rows: 3", kk), 7, "rows: 2");
    ws.replace(d0, d1 - d0, " 1., 0., 2., 0., 1., 3. ");
  }
  WriteText(wrong_size, ws);
  ExpectErrorNaming(
      [&] {
        ReadEasyMocapCalibration(wrong_size, tmp.path() / "extri.yml", tmp.path() / "images");
      },
      wrong_size.string(), "wrong K size");
  std::string nan = extri;
  {
    const size_t tt = nan.find("T_00_06");
    const size_t d0 = nan.find("data: [", tt) + 7;
    nan.insert(d0, " .nan,");
    const size_t d1 = nan.find("]", d0);
    nan.erase(nan.rfind(",", d1), d1 - nan.rfind(",", d1));
  }
  const fs::path nan_path = tmp.path() / "nan_extri.yml";
  WriteText(nan_path, nan);
  ExpectErrorNaming(
      [&] { ReadEasyMocapCalibration(tmp.path() / "intri.yml", nan_path, tmp.path() / "images"); },
      nan_path.string(), "NaN");
  ExpectErrorNaming([&] { ImportEasyMocap(tmp.path() / "missing"); }, "missing", "missing dir");
}

// ---- self-contained native capture ------------------------------------------

// File names' frame keys as source frame numbers: digits only, increasing,
// else none (the frames are then taken as consecutive).
TEST(ImportCapture, SourceFrameNumbersFromKeys) {
  using import_internal::SourceFrameNumbers;
  EXPECT_EQ(SourceFrameNumbers({"000100", "000101", "000250"}),
            (std::vector<int64_t>{100, 101, 250}));
  EXPECT_TRUE(SourceFrameNumbers({"000100", "take2"}).empty());
  EXPECT_TRUE(SourceFrameNumbers({"10", "9"}).empty());  // text order is not number order
  EXPECT_TRUE(SourceFrameNumbers({"1234567890123456789"}).empty());  // 19 digits
  EXPECT_TRUE(SourceFrameNumbers({""}).empty());
}

TEST(ImportCapture, WriteImportedCaptureIsSelfContained) {
  U4D_SKIP_WITHOUT_SHARED_DATA(kData / "panoptic_demo");
  TempDir tmp("native");
  ImportOptions options;
  options.max_frames = 2;
  const Capture imported = ImportCapture(ImportFormat::kPanoptic, kData / "panoptic_demo", options);
  EXPECT_EQ(imported.num_frames, 2);
  const Capture native = WriteImportedCapture(imported, tmp.path() / "cap");
  EXPECT_EQ(native.num_frames, 2);
  // max_frames keeps the first frames' source numbers; the written capture
  // reads them back.
  EXPECT_EQ(ReadCapture(tmp.path() / "cap").source_frames, (std::vector<int64_t>{4500, 5514}));
  ASSERT_EQ(native.NumViews(), 5);
  FrameReader a(imported), b(native);
  for (int v = 0; v < 5; ++v) {
    EXPECT_TRUE(fs::exists(tmp.path() / "cap/images" / native.views[v].name / "000001.jpg"));
    const cv::Mat ia = a.Read(v, 1), ib = b.Read(v, 1);
    EXPECT_EQ(cv::norm(ia, ib, cv::NORM_INF), 0.0);  // byte copies decode identically
    EXPECT_LT((native.views[v].cameras[0].cam_from_world.translation -
               imported.views[v].cameras[0].cam_from_world.translation)
                  .norm(),
              1e-9);
  }
  EXPECT_EQ(ImportFormatFromString("qualisys"), ImportFormat::kQualisys);
  ExpectErrorNaming([] { ImportFormatFromString("colmap"); }, "colmap", "unknown format");
}

}  // namespace
}  // namespace u4d
