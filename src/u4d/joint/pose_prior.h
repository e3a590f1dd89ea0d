// The human-pose term E_p(l,d,m) of the joint energy (paper Sec. 2.1.2,
// "Human-pose constraints"):
//
//   E_p = Σ_{b_i} λ_2d (e_2d^L(l) + e_2d^S(l) + e_2d^M(m)) + λ_3d (e_3d^S(d) + e_3d^M(d))
//
// The paper places a circle C_i around each projected joint and a sphere S_i
// around each 3D joint. Here the circles and spheres along a bone are swept
// into capsules: every bone of every person is sampled, each sample drawn as a
// disc of the capsule radius at its depth, with a z-buffer (on the depth of
// the sample sphere's visible surface at the pixel, so a thick torso in front
// of a thin limb wins even where the limb's axis is nearer) so that a person
// in front claims the pixels it covers (a joint hidden behind another person
// constrains nothing there). The result, per view and frame, is a PosePriorMap:
// for each covered pixel the person, the bone, a spatial weight w(p) =
// exp(−(r / core_fraction)² / 2) with r the distance to the bone axis in
// capsule radii, the
// colour similarity to the axis (e_2d^L, σ_L the mean over covered pixels as
// the paper's ⟨·⟩), and the 2D displacement of the axis point from t to t+1.
//
// Capsules taper linearly between per-joint radii (hip, shoulder and neck bones:
// torso radius at the pelvis / thorax, limb radius at the joint; taper_torso_ends), and
// the head capsule's end cap is placed by what the head joint is
// (head_joint_on_crown): around the head centre, the internal convention of
// poses built from 2D keypoints (docs/annotations.md), the cap reaches one
// radius past the joint, to the crown; for a crown joint (the synthetic
// ground truth) the capsule ends one radius before it. Either way the cap
// stops at the top of the head, not above it or at the ears.
//
// Sub-terms, each in [0, 1] at a pixel covered by person k:
//   e_2d^S(l)    = w(p) [l ≠ k]                        label near the projected pose
//   e_2d^L(l)    = w(p) c(p) [l ≠ k]                   ... when the colour matches the axis
//   e_2d^M(m)    = w(p) (1 − exp(−||m − δ(p)||² / 2σ_m²))      δ: the axis point's 2D motion
//   e_3d^S(d)    = w(p) (1 − exp(−max(0, dist(Φ(p), bone) − R)² / 2σ_s²))   R at the nearest
//                                                                          axis point
//   e_3d^M(d, m) = w(p) (1 − exp(−||p + m − Π_{t+1}(a' + R_i (Φ(p) − a))||² / 2σ_m²))
// where Φ(p) is the 3D point at the pixel's depth, a / a' the bone's parent
// joint at t / t+1 and R_i the bone's rotation from t to t+1 (the minimal
// rotation taking the bone direction at t to that at t+1): the
// as-rigid-as-possible motion of the points around the joint. e_3d terms are 0
// for the unknown depth U, e_2d^M and e_3d^M need the pose at t+1.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"
#include "u4d/io/poses.h"

namespace u4d {

struct PosePriorOptions {
  double limb_radius_m = 0.06;   // capsule radius of arm and leg bones
  double torso_radius_m = 0.14;  // capsule radius of spine, hip and shoulder bones
  double head_radius_m = 0.10;   // capsule radius of the neck-head bone
  // The bones that leave the torso (pelvis -> hip, thorax -> shoulder,
  // thorax -> neck) taper from torso_radius_m at the pelvis / thorax to
  // limb_radius_m at the hip / shoulder / neck joint, where the body is a
  // limb's root or the neck (a torso-radius cap around the shoulder joint
  // reaches ~8 cm above the shoulder, one around the neck joint fills the
  // gap beside the neck). false: torso radius along the whole bone.
  bool taper_torso_ends = true;
  // false: the head joint is the head centre, as the poses `u4d run` builds
  // from 2D keypoints (the mid-ears, docs/annotations.md) and the documented
  // convention of given 3D poses: the cap reaches one head radius beyond the
  // joint, to the crown. true: the head joint is the crown (Human3.6M's head
  // top, the synthetic ground truth's joints3d, docs/synthetic.md): the
  // neck-head capsule ends one head radius before it, so its cap stops there.
  // A crown setting on centre joints leaves the top of every head (~10 cm)
  // outside its person's capsule, free for a capsule behind it to claim.
  bool head_joint_on_crown = false;
  // Occlusion between people: a capsule's pixel is left unclaimed where another
  // person's capsules, with the arm and leg radius raised to this value, have a
  // surface in front of it. limb_radius_m is a thin core of the limb; a clothed
  // thigh reaches ~10 cm, so where one person's legs are seen in front of the
  // other's, the pixels just beside the front person's limb capsules may show
  // that person, not the capsule behind that would claim them. The torso and
  // head radii already bound the body and are not raised. <= limb_radius_m: the
  // capsules alone decide (plain z-buffer). Off by default: a raised radius
  // removes wrong claims on the other person but also many right ones
  // (joint_view_test, OccluderMarginRemovesSwappedPoseClaims), and costs depth
  // accuracy where legs overlap; kept for comparison in joint_bench
  // (--occluder-limb-radius).
  double occluder_limb_radius_m = 0;
  // e_3d (shape and motion) at a pixel covered by person k's capsule counts
  // only when the pixel is labelled k: the spheres S_i constrain the points of
  // their person (paper: "the nearest neighbour vertices for every joint"),
  // not whatever the pixel sees. This couples l and d: a pixel whose 3D point
  // is off k's capsule (another person's leg seen between k's) pays e_3d to
  // be labelled k, which balances e_2d's pull towards k; and a pixel labelled
  // another person or background is not pulled onto k's capsule in depth.
  // Where a person stands in front of k's capsule outside their own (the
  // front person's flank, shoulder or hair beside the capsule of the person
  // behind), the point seen is far in front of k's capsule: labelled k it
  // pays e_3d, so e_2d's pull towards k no longer wins alone. false: e_3d
  // applies whatever the label (the depth of such pixels is pulled onto the
  // capsule that covers them in the image). Where the initial label is wrong
  // the initial depth agrees with it and the gate helps less.
  bool shape_own_label_only = true;
  double core_fraction = 0.5;    // w(p) = exp(−(r / core_fraction)² / 2), r in capsule radii:
                                 // the pose is trusted most near the bone axis
  int samples_per_bone = 12;     // discs drawn along each bone
  double min_confidence = 0.1;   // joints below this confidence are missing
  double sigma_motion_px = 3.0;  // σ_m of the motion sub-terms (pixels, working resolution)
  double sigma_shape_m = 0.05;   // σ_s of the 3D shape sub-term (metres)
  void Check() const;
};

// A person's 3D pose at t and, when known, at t+1 (H36M-17, world frame).
struct PersonPose {
  int object_id = 0;  // the label of the person (>= 1)
  Pose3d at_t;
  Pose3d at_t1;
  bool has_t1 = false;
};

// One bone as the 3D terms need it.
struct PriorBone {
  int object_id = 0;
  Eigen::Vector3d a, b;               // parent and child joint at t
  Eigen::Vector3d a1, b1;             // at t+1 (equal to a, b without a pose at t+1)
  Eigen::Matrix3d rotation;           // R_i: bone direction at t -> at t+1
  double radius = 0;                  // the larger of radius_a, radius_b (metres)
  double radius_a = 0, radius_b = 0;  // capsule radius at a and at b (tapered in between)
  bool has_motion = false;
};

struct PosePriorMap {
  int width = 0, height = 0;
  std::vector<PriorBone> bones;
  cv::Mat bone;           // CV_32S index into bones; -1 = no person here
  cv::Mat object;         // CV_16U the covering person's label; 0 = none
  cv::Mat weight;         // CV_32F w(p)
  cv::Mat colour_weight;  // CV_32F c(p) in [0, 1]
  cv::Mat motion_2d;      // CV_32FC2 δ(p) (0 without a pose at t+1)
  cv::Mat has_motion;     // CV_8U 1 where δ(p) is known
};

// Draws the capsules of `people` into a view. `camera_t1` is the view at t+1
// (the same for static rigs); `image` (BGR, camera size) gives the colours.
PosePriorMap RenderPosePrior(const Camera& camera_t, const Camera& camera_t1, const cv::Mat& image,
                             const std::vector<PersonPose>& people,
                             const PosePriorOptions& options = {});

// The sub-terms above at pixel index p (p = y * width + x).
double PoseLabelCost(const PosePriorMap& map, int p, int label);  // e_2d^S + e_2d^L
double PoseMotion2dCost(const PosePriorMap& map, int p, const Eigen::Vector2f& motion,
                        const PosePriorOptions& options);
// e_3d^S + e_3d^M for the 3D point `point_in_world` seen at p; `moved_pixel`
// is p + m (the pixel's flow), `camera_t1` the view at t+1.
double Pose3dCost(const PosePriorMap& map, int p, const Eigen::Vector3d& point_in_world,
                  const Eigen::Vector2d& moved_pixel, const Camera& camera_t1,
                  const PosePriorOptions& options);

}  // namespace u4d
