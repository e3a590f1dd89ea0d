#include "u4d/io/poses.h"

#include <algorithm>
#include <cmath>

#include "u4d/util/check.h"

namespace u4d {
namespace {

using nlohmann::json;

double Number(const json& v, const std::string& ctx, const std::string& what) {
  return JsonNumber(v, ctx, what);
}

double Confidence(const json& v, const std::string& ctx, const std::string& what) {
  const double c = Number(v, ctx, what);
  U4D_CHECK(c >= 0 && c <= 1, "{}: {} confidence {} outside [0, 1]", ctx, what, c);
  return c;
}

// Reads the "people" array of one of our own files after checking the header.
const json& OwnPeople(const json& j, const std::string& ctx, const std::string& format,
                      const std::string& skeleton) {
  U4D_CHECK(j.is_object(), "{}: expected a JSON object", ctx);
  const std::string f = JsonGet<std::string>(j, "format", ctx);
  U4D_CHECK(f == format, "{}: format is '{}', expected '{}'", ctx, f, format);
  const std::string s = JsonGet<std::string>(j, "skeleton", ctx);
  U4D_CHECK(s == skeleton, "{}: skeleton is '{}', expected '{}'", ctx, s, skeleton);
  U4D_CHECK(j.contains("people") && j["people"].is_array(), "{}: missing 'people' array", ctx);
  return j["people"];
}

template <int N>
Eigen::Matrix<double, N, 1> Mid(const Eigen::Matrix<double, N, 1>& a,
                                const Eigen::Matrix<double, N, 1>& b) {
  Eigen::Matrix<double, N, 1> m = 0.5 * (a + b);
  m[N - 1] = std::min(a[N - 1], b[N - 1]);
  return m;
}

template <int N>
std::array<Eigen::Matrix<double, N, 1>, 17> H36mFromCoco(
    const std::array<Eigen::Matrix<double, N, 1>, 17>& c) {
  namespace C = coco17;
  namespace H = h36m17;
  std::array<Eigen::Matrix<double, N, 1>, 17> h;
  h[H::kRightHip] = c[C::kRightHip];
  h[H::kRightKnee] = c[C::kRightKnee];
  h[H::kRightAnkle] = c[C::kRightAnkle];
  h[H::kLeftHip] = c[C::kLeftHip];
  h[H::kLeftKnee] = c[C::kLeftKnee];
  h[H::kLeftAnkle] = c[C::kLeftAnkle];
  h[H::kLeftShoulder] = c[C::kLeftShoulder];
  h[H::kLeftElbow] = c[C::kLeftElbow];
  h[H::kLeftWrist] = c[C::kLeftWrist];
  h[H::kRightShoulder] = c[C::kRightShoulder];
  h[H::kRightElbow] = c[C::kRightElbow];
  h[H::kRightWrist] = c[C::kRightWrist];
  h[H::kPelvis] = Mid<N>(c[C::kLeftHip], c[C::kRightHip]);
  h[H::kThorax] = Mid<N>(c[C::kLeftShoulder], c[C::kRightShoulder]);
  h[H::kSpine] = Mid<N>(h[H::kPelvis], h[H::kThorax]);
  const auto present = [&](int k) { return c[k][N - 1] > 0; };
  if (present(C::kLeftEar) && present(C::kRightEar))
    h[H::kHead] = Mid<N>(c[C::kLeftEar], c[C::kRightEar]);
  else if (present(C::kLeftEye) && present(C::kRightEye))
    h[H::kHead] = Mid<N>(c[C::kLeftEye], c[C::kRightEye]);
  else
    h[H::kHead] = c[C::kNose];
  h[H::kNeck] = Mid<N>(h[H::kThorax], h[H::kHead]);
  return h;
}

template <int N>
std::array<Eigen::Matrix<double, N, 1>, 17> CocoFromH36m(
    const std::array<Eigen::Matrix<double, N, 1>, 17>& h) {
  namespace C = coco17;
  namespace H = h36m17;
  std::array<Eigen::Matrix<double, N, 1>, 17> c;
  for (int k : {C::kNose, C::kLeftEye, C::kRightEye, C::kLeftEar, C::kRightEar}) {
    c[k] = h[H::kHead];
    c[k][N - 1] = 0;
  }
  c[C::kLeftShoulder] = h[H::kLeftShoulder];
  c[C::kRightShoulder] = h[H::kRightShoulder];
  c[C::kLeftElbow] = h[H::kLeftElbow];
  c[C::kRightElbow] = h[H::kRightElbow];
  c[C::kLeftWrist] = h[H::kLeftWrist];
  c[C::kRightWrist] = h[H::kRightWrist];
  c[C::kLeftHip] = h[H::kLeftHip];
  c[C::kRightHip] = h[H::kRightHip];
  c[C::kLeftKnee] = h[H::kLeftKnee];
  c[C::kRightKnee] = h[H::kRightKnee];
  c[C::kLeftAnkle] = h[H::kLeftAnkle];
  c[C::kRightAnkle] = h[H::kRightAnkle];
  return c;
}

int PersonIdField(const json& p, const std::string& ctx) {
  if (!p.contains("person_id")) return -1;
  const json& v = p["person_id"];
  const json& n = (v.is_array() && v.size() == 1) ? v[0] : v;
  if (!n.is_number()) return -1;
  const double d = Number(n, ctx, "'person_id'");
  U4D_CHECK(d < 2147483648.0, "{}: 'person_id' {} out of range", ctx, d);
  return d >= 0 ? static_cast<int>(d) : -1;
}

}  // namespace

int Coco17Mirror(int keypoint) {
  U4D_CHECK(keypoint >= 0 && keypoint < coco17::kNumKeypoints,
            "Coco17Mirror: keypoint {} out of range [0, 17)", keypoint);
  if (keypoint == coco17::kNose) return keypoint;
  return (keypoint % 2 == 1) ? keypoint + 1 : keypoint - 1;  // left ids are odd, right even
}

const std::array<std::string, 17>& Coco17Names() {
  static const std::array<std::string, 17> kNames = {
      "nose",           "left_eye",   "right_eye",   "left_ear",   "right_ear",   "left_shoulder",
      "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist", "left_hip",
      "right_hip",      "left_knee",  "right_knee",  "left_ankle", "right_ankle"};
  return kNames;
}

const std::vector<std::pair<int, int>>& H36m17Bones() {
  static const std::vector<std::pair<int, int>> bones = {
      {0, 1}, {1, 2},  {2, 3},  {0, 4},   {4, 5},   {5, 6},  {0, 7},   {7, 8},
      {8, 9}, {9, 10}, {8, 11}, {11, 12}, {12, 13}, {8, 14}, {14, 15}, {15, 16}};
  return bones;
}

const std::array<std::string, 17>& H36m17Names() {
  static const std::array<std::string, 17> kNames = {
      "pelvis",     "right_hip",  "right_knee",     "right_ankle", "left_hip",   "left_knee",
      "left_ankle", "spine",      "thorax",         "neck",        "head",       "left_shoulder",
      "left_elbow", "left_wrist", "right_shoulder", "right_elbow", "right_wrist"};
  return kNames;
}

const std::array<int, 17>& Coco17FromBody25() {
  static const std::array<int, 17> kMap = {0, 16, 15, 18, 17, 5,  2,  6, 3,
                                           7, 4,  12, 9,  13, 10, 14, 11};
  return kMap;
}

const std::array<int, 17>& Coco17FromOpenPoseCoco18() {
  static const std::array<int, 17> kMap = {0, 15, 14, 17, 16, 5, 2,  6, 3,
                                           7, 4,  11, 8,  12, 9, 13, 10};
  return kMap;
}

std::vector<Pose2d> CocoKeypointPoses(const CocoFile& coco, const CocoImage& image,
                                      const CocoMaskOptions& options) {
  const std::vector<const CocoAnnotation*> anns = SelectCocoAnnotations(coco, image, options);
  std::vector<Pose2d> out;
  for (size_t i = 0; i < anns.size(); ++i) {
    const CocoAnnotation& a = *anns[i];
    if (a.keypoints.size() != 51) continue;
    Pose2d pose;
    pose.person_id = static_cast<int>(i) + 1;
    pose.score = a.score.value_or(1.0);
    bool any = false;
    for (int k = 0; k < 17; ++k) {
      const double x = a.keypoints[3 * k], y = a.keypoints[3 * k + 1], v = a.keypoints[3 * k + 2];
      U4D_CHECK(v >= 0, "{}: annotation {} keypoint {} has visibility {} < 0", coco.context, a.id,
                k, v);
      double c = 0;
      if (v > 0) c = a.score ? *a.score : (v >= 1 ? 1.0 : v);
      pose.keypoints[k] = Eigen::Vector3d(x, y, c);
      any = any || c > 0;
    }
    if (any) out.push_back(pose);
  }
  return out;
}

std::vector<Pose2d> ReadCocoKeypoints(const fs::path& path, const std::string& image_file_name) {
  const CocoFile coco = ReadCocoFile(path);
  return CocoKeypointPoses(coco, FindCocoImage(coco, image_file_name));
}

std::vector<Pose2d> ReadOpenPoseJson(const fs::path& path) {
  const json j = ReadJsonFile(path);
  const std::string ctx = path.string();
  U4D_CHECK(j.is_object() && j.contains("people") && j["people"].is_array(),
            "{}: not OpenPose JSON (no 'people' array)", ctx);
  std::vector<Pose2d> out;
  for (size_t i = 0; i < j["people"].size(); ++i) {
    const json& p = j["people"][i];
    const std::string pctx = fmt::format("{}: person {}", ctx, i);
    U4D_CHECK(p.is_object() && p.contains("pose_keypoints_2d") && p["pose_keypoints_2d"].is_array(),
              "{}: missing 'pose_keypoints_2d' array", pctx);
    const json& kp = p["pose_keypoints_2d"];
    if (kp.empty()) continue;
    const std::array<int, 17>* map = nullptr;
    if (kp.size() == 75)
      map = &Coco17FromBody25();
    else if (kp.size() == 54)
      map = &Coco17FromOpenPoseCoco18();
    U4D_CHECK(map != nullptr, "{}: {} keypoint values; expected 75 (BODY_25) or 54 (COCO-18)", pctx,
              kp.size());
    Pose2d pose;
    pose.person_id = PersonIdField(p, pctx);
    double sum = 0;
    int n = 0;
    for (int k = 0; k < 17; ++k) {
      const int s = (*map)[k];
      const double c = Confidence(kp[3 * s + 2], pctx, fmt::format("keypoint {}", s));
      pose.keypoints[k] =
          Eigen::Vector3d(Number(kp[3 * s], pctx, "x"), Number(kp[3 * s + 1], pctx, "y"), c);
      if (c > 0) {
        sum += c;
        ++n;
      }
    }
    pose.score = n > 0 ? sum / n : 0;
    out.push_back(pose);
  }
  return out;
}

std::vector<Pose2d> ReadPoses2d(const fs::path& path) {
  const json j = ReadJsonFile(path);
  const std::string ctx = path.string();
  const json& people = OwnPeople(j, ctx, "u4d-poses2d", "coco17");
  std::vector<Pose2d> out;
  for (size_t i = 0; i < people.size(); ++i) {
    const std::string pctx = fmt::format("{}: person {}", ctx, i);
    const json& p = people[i];
    Pose2d pose;
    pose.person_id = JsonGet<int>(p, "id", pctx);
    pose.score = Confidence(p.contains("score") ? p["score"] : json(), pctx, "'score'");
    U4D_CHECK(p.contains("keypoints") && p["keypoints"].is_array() && p["keypoints"].size() == 17,
              "{}: 'keypoints' must hold 17 [x, y, c] triples", pctx);
    for (int k = 0; k < 17; ++k) {
      const json& t = p["keypoints"][k];
      U4D_CHECK(t.is_array() && t.size() == 3, "{}: keypoint {} must be [x, y, c]", pctx, k);
      pose.keypoints[k] = Eigen::Vector3d(Number(t[0], pctx, "x"), Number(t[1], pctx, "y"),
                                          Confidence(t[2], pctx, Coco17Names()[k]));
    }
    out.push_back(pose);
  }
  return out;
}

void WritePoses2d(const fs::path& path, const std::vector<Pose2d>& people) {
  json arr = json::array();
  for (const Pose2d& p : people) {
    json kps = json::array();
    for (int k = 0; k < 17; ++k) {
      const Eigen::Vector3d& v = p.keypoints[k];
      U4D_CHECK(v.allFinite() && v.z() >= 0 && v.z() <= 1,
                "WritePoses2d({}): person {} keypoint {} is not finite or has confidence "
                "outside [0, 1]",
                path.string(), p.person_id, k);
      kps.push_back({v.x(), v.y(), v.z()});
    }
    U4D_CHECK(std::isfinite(p.score) && p.score >= 0 && p.score <= 1,
              "WritePoses2d({}): person {} score {} outside [0, 1]", path.string(), p.person_id,
              p.score);
    arr.push_back({{"id", p.person_id}, {"score", p.score}, {"keypoints", kps}});
  }
  WriteJsonFileAtomic(path, {{"format", "u4d-poses2d"}, {"skeleton", "coco17"}, {"people", arr}});
}

std::vector<Pose3d> ReadPoses3d(const fs::path& path) {
  const json j = ReadJsonFile(path);
  const std::string ctx = path.string();
  const json& people = OwnPeople(j, ctx, "u4d-poses3d", "h36m17");
  const std::string units = JsonGet<std::string>(j, "units", ctx);
  U4D_CHECK(units == "metres", "{}: units are '{}', expected 'metres'", ctx, units);
  std::vector<Pose3d> out;
  for (size_t i = 0; i < people.size(); ++i) {
    const std::string pctx = fmt::format("{}: person {}", ctx, i);
    const json& p = people[i];
    Pose3d pose;
    pose.person_id = JsonGet<int>(p, "id", pctx);
    U4D_CHECK(p.contains("joints") && p["joints"].is_array() && p["joints"].size() == 17,
              "{}: 'joints' must hold 17 [x, y, z, c] quadruples", pctx);
    for (int k = 0; k < 17; ++k) {
      const json& t = p["joints"][k];
      U4D_CHECK(t.is_array() && t.size() == 4, "{}: joint {} must be [x, y, z, c]", pctx, k);
      pose.joints[k] =
          Eigen::Vector4d(Number(t[0], pctx, "x"), Number(t[1], pctx, "y"), Number(t[2], pctx, "z"),
                          Confidence(t[3], pctx, H36m17Names()[k]));
    }
    out.push_back(pose);
  }
  return out;
}

void WritePoses3d(const fs::path& path, const std::vector<Pose3d>& people) {
  json arr = json::array();
  for (const Pose3d& p : people) {
    json js = json::array();
    for (int k = 0; k < 17; ++k) {
      const Eigen::Vector4d& v = p.joints[k];
      U4D_CHECK(v.allFinite() && v[3] >= 0 && v[3] <= 1,
                "WritePoses3d({}): person {} joint {} is not finite or has confidence outside "
                "[0, 1]",
                path.string(), p.person_id, k);
      js.push_back({v[0], v[1], v[2], v[3]});
    }
    arr.push_back({{"id", p.person_id}, {"joints", js}});
  }
  WriteJsonFileAtomic(
      path,
      {{"format", "u4d-poses3d"}, {"skeleton", "h36m17"}, {"units", "metres"}, {"people", arr}});
}

std::array<Eigen::Vector3d, 17> H36m17FromCoco17(const std::array<Eigen::Vector3d, 17>& coco) {
  return H36mFromCoco<3>(coco);
}
std::array<Eigen::Vector4d, 17> H36m17FromCoco17(const std::array<Eigen::Vector4d, 17>& coco) {
  return H36mFromCoco<4>(coco);
}
std::array<Eigen::Vector3d, 17> Coco17FromH36m17(const std::array<Eigen::Vector3d, 17>& h36m) {
  return CocoFromH36m<3>(h36m);
}
std::array<Eigen::Vector4d, 17> Coco17FromH36m17(const std::array<Eigen::Vector4d, 17>& h36m) {
  return CocoFromH36m<4>(h36m);
}

Pose3d H36m17FromShelf15(const Eigen::Matrix4Xd& s, int person_id) {
  U4D_CHECK(s.cols() == 15, "H36m17FromShelf15: expected 4 x 15 joints, got 4 x {}", s.cols());
  U4D_CHECK(s.allFinite(), "H36m17FromShelf15: non-finite joint values (person {})", person_id);
  namespace H = h36m17;
  Pose3d p;
  p.person_id = person_id;
  const auto j = [&](int k) -> Eigen::Vector4d { return s.col(k); };
  p.joints[H::kRightAnkle] = j(0);
  p.joints[H::kRightKnee] = j(1);
  p.joints[H::kRightHip] = j(2);
  p.joints[H::kLeftHip] = j(3);
  p.joints[H::kLeftKnee] = j(4);
  p.joints[H::kLeftAnkle] = j(5);
  p.joints[H::kRightWrist] = j(6);
  p.joints[H::kRightElbow] = j(7);
  p.joints[H::kRightShoulder] = j(8);
  p.joints[H::kLeftShoulder] = j(9);
  p.joints[H::kLeftElbow] = j(10);
  p.joints[H::kLeftWrist] = j(11);
  p.joints[H::kNeck] = j(12);
  p.joints[H::kPelvis] = j(14);
  p.joints[H::kThorax] = Mid<4>(j(8), j(9));
  p.joints[H::kSpine] = Mid<4>(p.joints[H::kPelvis], p.joints[H::kThorax]);
  p.joints[H::kHead] = Mid<4>(j(12), j(13));
  for (Eigen::Vector4d& v : p.joints) v[3] = std::clamp(v[3], 0.0, 1.0);
  return p;
}

}  // namespace u4d
