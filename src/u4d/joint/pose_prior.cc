#include "u4d/joint/pose_prior.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include <Eigen/Geometry>

#include "u4d/util/check.h"

namespace u4d {
namespace {

// The capsule radius at the parent joint a and at the child joint b.
std::pair<double, double> BoneRadii(int a, int b, const PosePriorOptions& o) {
  using namespace h36m17;
  const auto is = [&](int x, int y) { return (a == x && b == y) || (a == y && b == x); };
  if (is(kNeck, kHead)) return {o.head_radius_m, o.head_radius_m};
  if (is(kPelvis, kSpine) || is(kSpine, kThorax)) return {o.torso_radius_m, o.torso_radius_m};
  if (is(kPelvis, kLeftHip) || is(kPelvis, kRightHip) || is(kThorax, kLeftShoulder) ||
      is(kThorax, kRightShoulder) || is(kThorax, kNeck))
    return {o.torso_radius_m, o.taper_torso_ends ? o.limb_radius_m : o.torso_radius_m};
  return {o.limb_radius_m, o.limb_radius_m};
}

// The parameter in [0, 1] of the point of the segment [a, b] nearest to x.
template <typename V>
double SegmentParameter(const V& x, const V& a, const V& b) {
  const V ab = b - a;
  const double len2 = ab.squaredNorm();
  return len2 > 0 ? std::clamp((x - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
}

// Distance from point x to the segment [a, b].
template <typename V>
double SegmentDistance(const V& x, const V& a, const V& b) {
  return (a + SegmentParameter(x, a, b) * (b - a) - x).norm();
}

// The depth of the nearest surface of `person`'s capsules with the arm and leg
// radii raised to options.occluder_limb_radius_m (infinity where none covers).
cv::Mat RenderOuterDepth(const Camera& camera, const PersonPose& person,
                         const PosePriorOptions& options) {
  const int w = camera.width, h = camera.height;
  cv::Mat z_min(h, w, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
  for (const auto& [ja, jb] : H36m17Bones()) {
    const Eigen::Vector4d& a4 = person.at_t.joints[ja];
    const Eigen::Vector4d& b4 = person.at_t.joints[jb];
    if (a4.w() < options.min_confidence || b4.w() < options.min_confidence) continue;
    auto [ra, rb] = BoneRadii(ja, jb, options);
    // Arm and leg bones: the clothed limb's outer radius; the torso and head
    // radii already bound the body.
    if (ra == options.limb_radius_m && rb == options.limb_radius_m)
      ra = rb = std::max(options.limb_radius_m, options.occluder_limb_radius_m);
    Eigen::Vector3d a = a4.head<3>(), b = b4.head<3>();
    if (options.head_joint_on_crown && jb == h36m17::kHead) {
      const double len = (b - a).norm();
      if (len > 0) b = b - (b - a) * std::min(rb / len, 1.0);
    }
    for (int s = 0; s <= options.samples_per_bone; ++s) {
      const double u = static_cast<double>(s) / options.samples_per_bone;
      const Eigen::Vector3d x = a + u * (b - a);
      const double z = camera.Depth(x);
      if (!(z > 0)) continue;
      const Eigen::Vector2d c = camera.Project(x);
      if (!c.allFinite()) continue;
      const double radius_m = ra + u * (rb - ra);
      const double radius_px = camera.K(0, 0) * radius_m / z;
      const int cx = static_cast<int>(std::lround(c.x())),
                cy = static_cast<int>(std::lround(c.y()));
      const int r = static_cast<int>(std::ceil(radius_px));
      for (int y = std::max(0, cy - r); y <= std::min(h - 1, cy + r); ++y)
        for (int xx = std::max(0, cx - r); xx <= std::min(w - 1, cx + r); ++xx) {
          const double off_px = (Eigen::Vector2d(xx, y) - c).norm();
          if (off_px > radius_px) continue;
          const double off_m = off_px / radius_px * radius_m;
          const float zs =
              static_cast<float>(z - std::sqrt(std::max(0.0, radius_m * radius_m - off_m * off_m)));
          float& cur = z_min.at<float>(y, xx);
          cur = std::min(cur, zs);
        }
    }
  }
  return z_min;
}

}  // namespace

void PosePriorOptions::Check() const {
  U4D_CHECK(limb_radius_m > 0 && torso_radius_m > 0 && head_radius_m > 0,
            "PosePriorOptions: capsule radii must be > 0");
  U4D_CHECK(core_fraction > 0, "PosePriorOptions.core_fraction must be > 0");
  U4D_CHECK(occluder_limb_radius_m >= 0, "PosePriorOptions.occluder_limb_radius_m must be >= 0");
  U4D_CHECK(samples_per_bone >= 2, "PosePriorOptions.samples_per_bone must be >= 2");
  U4D_CHECK(min_confidence >= 0 && min_confidence <= 1,
            "PosePriorOptions.min_confidence must be in [0, 1]");
  U4D_CHECK(sigma_motion_px > 0 && sigma_shape_m > 0, "PosePriorOptions: sigmas must be > 0");
}

PosePriorMap RenderPosePrior(const Camera& camera_t, const Camera& camera_t1, const cv::Mat& image,
                             const std::vector<PersonPose>& people,
                             const PosePriorOptions& options) {
  options.Check();
  U4D_CHECK(
      image.type() == CV_8UC3 && image.cols == camera_t.width && image.rows == camera_t.height,
      "RenderPosePrior: image must be BGR {}x{}", camera_t.width, camera_t.height);
  const int w = camera_t.width, h = camera_t.height;
  PosePriorMap map;
  map.width = w;
  map.height = h;
  map.bone = cv::Mat(h, w, CV_32S, cv::Scalar(-1));
  map.object = cv::Mat::zeros(h, w, CV_16U);
  map.weight = cv::Mat::zeros(h, w, CV_32F);
  map.colour_weight = cv::Mat::zeros(h, w, CV_32F);
  map.motion_2d = cv::Mat::zeros(h, w, CV_32FC2);
  map.has_motion = cv::Mat::zeros(h, w, CV_8U);
  cv::Mat zbuf(h, w, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
  cv::Mat axis_colour(h, w, CV_8UC3, cv::Scalar::all(0));
  // Per person, the nearest surface of its capsules with clothed limbs
  // (occluder_limb_radius_m): where another person's body may be in front, a
  // capsule behind it claims nothing.
  std::vector<cv::Mat> outer_z;
  if (options.occluder_limb_radius_m > options.limb_radius_m && people.size() > 1)
    for (const PersonPose& person : people)
      outer_z.push_back(RenderOuterDepth(camera_t, person, options));

  for (size_t pi = 0; pi < people.size(); ++pi) {
    const PersonPose& person = people[pi];
    U4D_CHECK(person.object_id >= 1, "RenderPosePrior: person object id must be >= 1");
    for (const auto& [ja, jb] : H36m17Bones()) {
      const Eigen::Vector4d& a4 = person.at_t.joints[ja];
      const Eigen::Vector4d& b4 = person.at_t.joints[jb];
      if (a4.w() < options.min_confidence || b4.w() < options.min_confidence) continue;
      PriorBone bone;
      bone.object_id = person.object_id;
      bone.a = a4.head<3>();
      bone.b = b4.head<3>();
      bone.a1 = bone.a;
      bone.b1 = bone.b;
      bone.rotation.setIdentity();
      std::tie(bone.radius_a, bone.radius_b) = BoneRadii(ja, jb, options);
      bone.radius = std::max(bone.radius_a, bone.radius_b);
      // The head joint is the crown: the head capsule's end cap stops there
      // instead of one radius above it.
      const bool crown = options.head_joint_on_crown && jb == h36m17::kHead;
      const auto inset = [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
        const double len = (to - from).norm();
        return len > 0 ? Eigen::Vector3d(to - (to - from) * std::min(bone.radius_b / len, 1.0))
                       : to;
      };
      if (crown) bone.b = inset(bone.a, bone.b), bone.b1 = bone.b;
      if (person.has_t1 && person.at_t1.joints[ja].w() >= options.min_confidence &&
          person.at_t1.joints[jb].w() >= options.min_confidence) {
        bone.a1 = person.at_t1.joints[ja].head<3>();
        bone.b1 = person.at_t1.joints[jb].head<3>();
        if (crown) bone.b1 = inset(bone.a1, bone.b1);
        bone.rotation = Eigen::Quaterniond::FromTwoVectors(bone.b - bone.a, bone.b1 - bone.a1)
                            .toRotationMatrix();
        bone.has_motion = true;
      }
      const int bone_index = static_cast<int>(map.bones.size());
      map.bones.push_back(bone);
      for (int s = 0; s <= options.samples_per_bone; ++s) {
        const double u = static_cast<double>(s) / options.samples_per_bone;
        const Eigen::Vector3d x = bone.a + u * (bone.b - bone.a);
        const double z = camera_t.Depth(x);
        if (!(z > 0)) continue;
        const Eigen::Vector2d c = camera_t.Project(x);
        if (!c.allFinite()) continue;
        const double radius_m = bone.radius_a + u * (bone.radius_b - bone.radius_a);
        const double radius_px = camera_t.K(0, 0) * radius_m / z;
        Eigen::Vector2f delta(0, 0);
        bool moving = false;
        if (bone.has_motion) {
          const Eigen::Vector3d x1 = bone.a1 + bone.rotation * (x - bone.a);
          const Eigen::Vector2d c1 = camera_t1.Project(x1);
          if (c1.allFinite()) {
            delta = (c1 - c).cast<float>();
            moving = true;
          }
        }
        const int cx = static_cast<int>(std::lround(c.x())),
                  cy = static_cast<int>(std::lround(c.y()));
        const cv::Vec3b colour = (cx >= 0 && cy >= 0 && cx < w && cy < h)
                                     ? image.at<cv::Vec3b>(cy, cx)
                                     : cv::Vec3b(0, 0, 0);
        const int r = static_cast<int>(std::ceil(radius_px));
        // Distances in the image to the projected bone axis.
        const Eigen::Vector2d pa = camera_t.Project(bone.a), pb = camera_t.Project(bone.b);
        for (int y = std::max(0, cy - r); y <= std::min(h - 1, cy + r); ++y)
          for (int xx = std::max(0, cx - r); xx <= std::min(w - 1, cx + r); ++xx) {
            const Eigen::Vector2d px(xx, y);
            const double off_px = (px - c).norm();
            if (off_px > radius_px) continue;
            // Depth of the disc's sphere surface facing the camera at this
            // pixel (not of its centre): a thick torso in front of a thin limb
            // must win even where the limb's axis is nearer than the torso's.
            const double off_m = off_px / radius_px * radius_m;
            const double z_surface =
                z - std::sqrt(std::max(0.0, radius_m * radius_m - off_m * off_m));
            if (z_surface >= zbuf.at<float>(y, xx)) continue;
            bool occluded = false;
            for (size_t j = 0; j < outer_z.size() && !occluded; ++j)
              occluded = j != pi && outer_z[j].at<float>(y, xx) < z_surface;
            if (occluded) continue;
            zbuf.at<float>(y, xx) = static_cast<float>(z_surface);
            const double dist =
                (pa.allFinite() && pb.allFinite()) ? SegmentDistance(px, pa, pb) : (px - c).norm();
            const double rr = dist / std::max(radius_px, 1.0) / options.core_fraction;
            map.bone.at<int>(y, xx) = bone_index;
            map.object.at<uint16_t>(y, xx) = static_cast<uint16_t>(person.object_id);
            map.weight.at<float>(y, xx) = static_cast<float>(std::exp(-0.5 * rr * rr));
            map.motion_2d.at<cv::Vec2f>(y, xx) = cv::Vec2f(delta.x(), delta.y());
            map.has_motion.at<uint8_t>(y, xx) = moving ? 1 : 0;
            axis_colour.at<cv::Vec3b>(y, xx) = colour;
          }
      }
    }
  }
  // e_2d^L: colour similarity to the axis, σ_L the mean squared difference.
  double sum = 0;
  int count = 0;
  cv::Mat diff2(h, w, CV_32F, cv::Scalar(0));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (map.bone.at<int>(y, x) < 0) continue;
      const cv::Vec3i d =
          cv::Vec3i(image.at<cv::Vec3b>(y, x)) - cv::Vec3i(axis_colour.at<cv::Vec3b>(y, x));
      diff2.at<float>(y, x) = static_cast<float>(d.dot(d));
      sum += d.dot(d);
      ++count;
    }
  const double sigma = count > 0 ? std::max(sum / count, 1.0) : 1.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (map.bone.at<int>(y, x) >= 0)
        map.colour_weight.at<float>(y, x) =
            static_cast<float>(std::exp(-diff2.at<float>(y, x) / sigma));
  return map;
}

double PoseLabelCost(const PosePriorMap& map, int p, int label) {
  const int k = map.object.ptr<uint16_t>()[p];
  if (k == 0 || label == k) return 0;
  const double w = map.weight.ptr<float>()[p];
  return w * (1.0 + map.colour_weight.ptr<float>()[p]);
}

double PoseMotion2dCost(const PosePriorMap& map, int p, const Eigen::Vector2f& motion,
                        const PosePriorOptions& options) {
  if (!map.has_motion.ptr<uint8_t>()[p]) return 0;
  const cv::Vec2f d = map.motion_2d.ptr<cv::Vec2f>()[p];
  const double e2 = (motion - Eigen::Vector2f(d[0], d[1])).squaredNorm();
  const double s2 = options.sigma_motion_px * options.sigma_motion_px;
  return map.weight.ptr<float>()[p] * (1.0 - std::exp(-e2 / (2 * s2)));
}

double Pose3dCost(const PosePriorMap& map, int p, const Eigen::Vector3d& point_in_world,
                  const Eigen::Vector2d& moved_pixel, const Camera& camera_t1,
                  const PosePriorOptions& options) {
  const int bi = map.bone.ptr<int>()[p];
  if (bi < 0) return 0;
  const PriorBone& bone = map.bones[bi];
  const double w = map.weight.ptr<float>()[p];
  const double u = SegmentParameter(point_in_world, bone.a, bone.b);
  const double outside = std::max(0.0, (bone.a + u * (bone.b - bone.a) - point_in_world).norm() -
                                           (bone.radius_a + u * (bone.radius_b - bone.radius_a)));
  const double ss = options.sigma_shape_m;
  double cost = 1.0 - std::exp(-outside * outside / (2 * ss * ss));
  if (bone.has_motion) {
    const Eigen::Vector3d moved = bone.a1 + bone.rotation * (point_in_world - bone.a);
    const Eigen::Vector2d predicted = camera_t1.Project(moved);
    if (predicted.allFinite()) {
      const double sm = options.sigma_motion_px;
      cost += 1.0 - std::exp(-(moved_pixel - predicted).squaredNorm() / (2 * sm * sm));
    }
  }
  return w * cost;
}

}  // namespace u4d
