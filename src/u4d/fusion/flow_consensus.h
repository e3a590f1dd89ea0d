// The flow of every view from the motion all views see (paper Sec. 3: the
// per-view results are "combined across views"; Sec. 4: "combining the most
// consistent motion information from all views for each 3D point").
//
// Each view's joint solve finds its flow t -> t+1 alone, so its error is its
// own: weak texture, blur and the regularisation's guesses differ from view
// to view. A surface point seen by several views has one 3D motion, and each
// view's flow constrains that motion's two components across its ray. The
// consensus estimates that motion per pixel and puts it back into the view:
//
//   point    X = Unproject_{v,t}(p, depth_v(p)) for a pixel p of view v with
//            an object label l and a depth;
//   seen     view u (v included) sees X when q_u = Project_{u,t}(X) lies in
//            its image, carries label l there, and the depth of l at q_u
//            (bilinear, fusion/depth_sampling.h) is within
//            visibility_tolerance + 2 depth_sigma_rel z of z_u(X);
//   moved    m_u = q_u + flow_u(q_u) (bilinear where the four neighbours
//            carry l, else the nearest pixel's; fusion/depth_sampling.h);
//   motion   Y minimises sum_u rho(|Project_{u,t+1}(Y) - m_u|) with rho the
//            Cauchy loss of scale robust_scale_px: Gauss-Newton from
//            Y0 = Unproject_{v,t+1}(p + flow_v(p), depth_v(p)) (the view's
//            own flow at constant depth), two least-squares steps (every
//            view alike, so that a wrong own flow does not hold the start),
//            then `iterations` steps reweighted by the loss (IRLS);
//   flow     flow_v(p) := Project_{v,t+1}(Y) - p, where at least min_views
//            views see X; elsewhere the view's flow is kept.
//
// With two or more views at an angle the flows triangulate the motion, so a
// view's error that the others do not share (a wrong match in a textureless
// patch, a blob from another object's motion) is outvoted, and a surface
// point that leaves the view at t+1 still gets the motion the others see.
// Background pixels (label 0) and pixels without depth are not changed.
//
// Inputs per view (the solve's working resolution): the cameras at t and
// t+1 (the same for a static rig), CV_16UC1 labels, CV_32FC1 depth (z
// metres, 0 = unknown) and CV_32FC2 flow, each of its camera's size; a view
// with an empty flow (no next frame) is neither changed nor used. Throws
// u4d::Error naming the view and the map on a mismatch.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"

namespace u4d {

struct FlowConsensusOptions {
  bool enabled = true;
  int min_views = 2;                   // views that must see a point for its flow to change
  double visibility_tolerance = 0.03;  // metres (as scene_flow's), plus 2 depth_sigma_rel z
  double depth_sigma_rel = 0.01;       // the depth maps' relative error
  double max_depth_jump = 0.05;        // metres; bilinear depth only across smaller steps
  double robust_scale_px = 1.0;        // Cauchy scale of a view's flow residual, working pixels
  int iterations = 4;                  // IRLS steps after the two least-squares steps
  void Check() const;                  // throws u4d::Error naming the bad field
};

struct FlowConsensusView {
  Camera camera_t;
  Camera camera_t1;
  cv::Mat labels;  // CV_16UC1
  cv::Mat depth;   // CV_32FC1
  cv::Mat flow;    // CV_32FC2, or empty: no next frame
};

// The views' flows after the consensus (see above), one per view (empty
// where the input's is).
std::vector<cv::Mat> FlowConsensus(const std::vector<FlowConsensusView>& views,
                                   const FlowConsensusOptions& options);

}  // namespace u4d
