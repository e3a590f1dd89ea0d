// Builds the per-view inputs of the joint optimisation (joint_view.h) for one
// frame from the capture's data: images at t−1, t, t+1, the detector's
// initial instance masks, the tracked 3D poses and the sparse temporal
// correspondences, all at full resolution. Everything is resized to the
// working resolution here.
//
// Objects are the tracked people: object id = Pose3d::person_id (>= 1, the
// same in every view and frame). A detector instance of a view takes the
// object whose projected joints fall inside it most often (at least
// `min_joints_inside`); instances with no such person are dropped as false
// positives (they become background in the initial labels). A person's
// region in a view is its instances plus its capsule model (pose_prior.h),
// which restores limbs the detector dropped (paper: "dilating the boundary to
// include the missing joints"); its depth range is the z range of its joints
// widened by `depth_margin_m`.
//
// Without poses (poses_t empty), the objects are given by the masks, which
// must then hold object ids, with each view's depth ranges in
// `object_depth_ranges` (the pipeline's cross-view association,
// features/object_regions.h); the pose term has nothing to act on.
// With poses, `object_depth_ranges` may add objects that are not people (a
// box, a chair: ids that no pose has): their regions are their masks (with
// the hull support below), and the pose term, whose capsules are the
// people's, does not act on them.
//
// With or without poses, each object's region in a view then also holds the
// pixels its visual hull from the other views covers (hull_support.h), and
// JointViewInput::hull_support records them for E_sem. An object with a
// depth range in a view but none of its pixels there (the detector missed
// it, or merged it into another object) is searched for by its hull alone,
// and its colour model (E_a) is learnt from its pixels in the other views at
// t; where it is merged into another object, the view's object labels at
// t−1 and t+1 give no colour sample where its hull support lies at t (they
// likely hold it there too).
#pragma once

#include <map>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/io/capture.h"
#include "u4d/io/frame_reader.h"
#include "u4d/joint/hull_support.h"
#include "u4d/joint/joint_view.h"

namespace u4d {

struct JointFrameData {
  std::vector<Camera> cameras_t, cameras_t1;              // full resolution; t1 empty = last frame
  std::vector<cv::Mat> images_prev, images_t, images_t1;  // BGR; prev / t1 may be empty
  std::vector<cv::Mat> masks_prev, masks_t, masks_t1;     // CV_16U detector ids; empty Mat = none
  // Per view: CV_32F the detector's score at each pixel of its masks at t
  // (io/instance_mask.h ScoreImage), at camera size; empty (or an empty Mat)
  // = 1 everywhere.
  std::vector<cv::Mat> scores_t;
  std::vector<Pose3d> poses_t, poses_t1;          // person_id >= 1
  std::vector<std::vector<SparseMotion>> sparse;  // per view, t -> t+1, full resolution
  // The masks already hold object ids (the same in every view and frame,
  // e.g. from AssignInstancesToPeople or a cross-view association), so they
  // are not assigned to people again.
  bool masks_are_object_ids = false;
  // Per view, object id -> (depth_near, depth_far) in metres: the objects
  // without a pose (all of them without poses; with poses, those that are
  // not people), whose regions are their masks. Ids of people are ignored.
  std::vector<std::map<int, std::pair<double, double>>> object_depth_ranges;
};

struct FrameSetupOptions {
  int working_width = 480;       // the optimisation runs at this width (never upscaled)
  double depth_margin_m = 0.35;  // depth range: joints' z range widened by this
  int min_joints_inside = 3;     // joints needed inside an instance to assign it to a person
  // Split a detector instance that merges touching people (>= min_joints_inside
  // visible joints of each inside) among them by their capsules (see
  // AssignInstancesToPeople); false: the instance goes whole to one person.
  bool split_merged = true;
  double min_joint_confidence = 0.1;
  PosePriorOptions pose;  // capsule model used for the regions and the split
  // Each object's region also holds its leave-one-out visual hull from the
  // other views (hull_support.h): parts one view's mask missed.
  HullSupportOptions hull;
  // The camera-size labels keep the initial masks' detail where the solve
  // kept its input (pipeline/scene_outputs.h KeepInitialDetail); false: the
  // working-resolution labels upscaled by nearest neighbour.
  bool keep_initial_detail = true;
  // The camera-size labels follow the image's colour edges near the solve's
  // boundaries (pipeline/scene_outputs.h GuidedLabels, joint bilateral
  // upsampling); false: nearest neighbour there.
  bool guided_upsampling = true;
  // The camera-size flow of the objects takes, pixel by pixel, the solve's
  // flow or the camera-size dense match, whichever keeps the brightness over
  // a flow_window_px square (pipeline/camera_flow.h); false: the solve's flow
  // upscaled.
  bool flow_at_camera_size = true;
  int flow_window_px = 7;
  // That step also tries each object's own match, with everything outside
  // the object at t and at t+1 greyed out (camera_flow.h): a neighbour that
  // moves otherwise cannot drag its pixels. The objects at t+1 are the next
  // frame's refined labels, or its initial masks where no next frame is
  // solved (the run's end, a gap, an error).
  bool flow_object_matches = true;
  // That step also tries the written camera-size flow of the frame before,
  // carried forward along itself (constant velocity, camera_flow.h
  // CarriedObjectFlow), where frame t-1 continues into t and its maps are
  // in the scene folder: a fast limb's motion that the pair (t, t+1)
  // matches poorly. False: the two images' candidates only.
  bool flow_carried_candidate = true;
  // Then each object's camera-size flow is median-filtered over a square of
  // this side in working pixels, over the object's own pixels in it
  // (camera_flow.h MedianFilterObjectFlow; Sun, Roth and Black 2010's 5x5
  // median, here at the solve's resolution); 0 = off.
  int flow_median_px = 5;
  // Then, with the objects at t+1 (flow_object_matches), the forward-backward
  // check: an object pixel whose backward match does not lead back (occluded
  // at t+1, or a wrong match in a weak texture) takes the affine motion of
  // its object's consistent pixels within this radius in working pixels
  // (camera_flow.h FillInconsistentObjectFlow); 0 = off.
  int flow_fill_radius_px = 6;
  // Last, with the objects at t+1, each object's camera-size flow is moved
  // towards the sub-pixel optimum of brightness and gradient constancy with a
  // smoothness term, on its own pair of images (camera_flow.h
  // RefineObjectFlowVariationally): this many fixed-point iterations; 0 = off.
  int flow_variational_iterations = 20;
  // With several objects in the view, E_a's colour models of each also
  // learn from its pixels in the other views at t (frame_setup.cc
  // BorrowColourSamples): a view whose detector merged two people has mixed
  // samples of both. False: only an object the view's labels lack borrows
  // (for rigs whose cameras render colours very differently).
  bool colour_from_other_views = true;
  void Check() const;
};

// Detector ids -> object ids by the projected joints (see above). CV_16U.
// Merged instances (split_merged): a detector often reports touching people
// (a handshake) as one instance, and giving it whole to one person leaves the
// other with no initial mask, so neither E_sem nor the appearance GMM (both
// learned from the initial labels) supports it. An instance holding at least
// `min_joints_inside` *visible* joints of two or more people is split among
// them: the people's capsules (pose_prior.h with `pose`) are drawn with a
// z-buffer, a joint counts as visible when its own person's capsules claim its
// pixel (so the joints of a person hidden behind another's instance do not
// split that instance), and each pixel of the instance goes to the person
// whose capsules cover it, else to the one whose capsules are nearest in the
// image. The split is the pose's guess of the boundary; the joint optimisation
// refines it (E_sem's softness, E_a, E_c, E_p).
cv::Mat AssignInstancesToPeople(const Camera& camera, const cv::Mat& mask_ids,
                                const std::vector<Pose3d>& poses, const FrameSetupOptions& options);

// One JointViewInput per view (views where no person projects get no objects
// and are still returned; SolveJointView throws for them, so callers skip
// views with empty `objects`). Also returns the working scale.
std::vector<JointViewInput> MakeJointViewInputs(const JointFrameData& data,
                                                const FrameSetupOptions& options, double* scale);

// The flow of view `v` when it has no object to solve: the camera's rigid
// flow (background_flow.h) at the working resolution `scale`, 0 on a still
// camera, on the last frame (no cameras_t1) or with the options disabled.
cv::Mat ViewBackgroundFlow(const JointFrameData& data, int v, double scale,
                           const BackgroundFlowOptions& options);

}  // namespace u4d
