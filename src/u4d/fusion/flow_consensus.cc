#include "u4d/fusion/flow_consensus.h"

#include <cmath>

#include <tbb/parallel_for.h>
#include <Eigen/Dense>

#include "u4d/fusion/depth_sampling.h"
#include "u4d/util/check.h"

namespace u4d {

using fusion_internal::CheckMap;
using fusion_internal::SampleId;
using fusion_internal::SampleObjectDepth;
using fusion_internal::SampleObjectFlow;

void FlowConsensusOptions::Check() const {
  U4D_CHECK(min_views >= 2, "flow_consensus.min_views must be >= 2, got {}", min_views);
  U4D_CHECK(visibility_tolerance > 0, "flow_consensus.visibility_tolerance must be > 0, got {}",
            visibility_tolerance);
  U4D_CHECK(depth_sigma_rel >= 0, "flow_consensus.depth_sigma_rel must be >= 0, got {}",
            depth_sigma_rel);
  U4D_CHECK(max_depth_jump > 0, "flow_consensus.max_depth_jump must be > 0, got {}",
            max_depth_jump);
  U4D_CHECK(robust_scale_px > 0, "flow_consensus.robust_scale_px must be > 0, got {}",
            robust_scale_px);
  U4D_CHECK(iterations >= 1, "flow_consensus.iterations must be >= 1, got {}", iterations);
}

namespace {

constexpr int kLeastSquaresSteps = 2;

// One view's observation of a point's position at t+1: it must project to `moved`.
struct Observation {
  const Camera* camera_t1;
  Eigen::Vector2d moved;
};

// The views that see `point` of object `label`, with where it moves in each.
std::vector<Observation> Observe(const std::vector<FlowConsensusView>& views,
                                 const Eigen::Vector3d& point, int label,
                                 const FlowConsensusOptions& o) {
  std::vector<Observation> seen;
  for (const FlowConsensusView& u : views) {
    if (u.flow.empty()) continue;
    const Eigen::Vector2d q = u.camera_t.Project(point);
    if (!std::isfinite(q.x()) || !u.camera_t.InImage(q)) continue;
    if (SampleId(u.labels, q) != label) continue;
    const double z = u.camera_t.Depth(point);
    const double d = SampleObjectDepth(u.depth, u.labels, label, q, o.max_depth_jump);
    if (d <= 0 || std::abs(z - d) > o.visibility_tolerance + 2 * o.depth_sigma_rel * z) continue;
    // The nearest pixel is the object's (above), so the flow is the object's.
    seen.push_back({&u.camera_t1, q + SampleObjectFlow(u.flow, u.labels, label, q)});
  }
  return seen;
}

// Jacobian of the pinhole projection (distortion's own Jacobian left out:
// Gauss-Newton evaluates the residuals with it and converges all the same).
Eigen::Matrix<double, 2, 3> ProjectionJacobian(const Camera& camera, const Eigen::Vector3d& world) {
  const Eigen::Vector3d c = camera.cam_from_world * world;
  const double fx = camera.K(0, 0), fy = camera.K(1, 1), iz = 1.0 / c.z();
  Eigen::Matrix<double, 2, 3> a;
  a << fx * iz, 0, -fx * c.x() * iz * iz, 0, fy * iz, -fy * c.y() * iz * iz;
  return a * camera.cam_from_world.rotation;
}

// Y minimising the Cauchy loss of the reprojections, from `start`: the
// first kLeastSquaresSteps steps weigh every view alike (the least-squares
// motion, so that a start on one view's wrong flow does not hold the solution
// in its basin), the rest reweigh by the Cauchy loss.
Eigen::Vector3d RobustMotion(const std::vector<Observation>& seen, const Eigen::Vector3d& start,
                             const FlowConsensusOptions& o) {
  Eigen::Vector3d y = start;
  const double s2 = o.robust_scale_px * o.robust_scale_px;
  for (int it = 0; it < kLeastSquaresSteps + o.iterations; ++it) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const Observation& ob : seen) {
      if (ob.camera_t1->Depth(y) <= 0) continue;
      const Eigen::Vector2d r = ob.camera_t1->Project(y) - ob.moved;
      const double w = it < kLeastSquaresSteps ? 1.0 : 1.0 / (1.0 + r.squaredNorm() / s2);
      const Eigen::Matrix<double, 2, 3> j = ProjectionJacobian(*ob.camera_t1, y);
      h += w * j.transpose() * j;
      g += w * j.transpose() * r;
    }
    // A little damping keeps a direction few views constrain near its start.
    h += 1e-6 * (h.trace() + 1e-12) * Eigen::Matrix3d::Identity();
    const Eigen::Vector3d step = h.ldlt().solve(-g);
    if (!step.allFinite()) break;
    y += step;
  }
  return y;
}

void CheckView(const FlowConsensusView& v, int index) {
  const int w = v.camera_t.width, h = v.camera_t.height;
  const std::string name = "FlowConsensus: view " + std::to_string(index);
  CheckMap(v.labels, CV_16UC1, w, h, name + " labels");
  CheckMap(v.depth, CV_32FC1, w, h, name + " depth");
  if (!v.flow.empty()) CheckMap(v.flow, CV_32FC2, w, h, name + " flow");
  U4D_CHECK(v.camera_t1.width == w && v.camera_t1.height == h,
            "{}: the cameras at t and t+1 differ in size", name);
}

cv::Mat ViewConsensus(const std::vector<FlowConsensusView>& views, int index,
                      const FlowConsensusOptions& o) {
  const FlowConsensusView& v = views[index];
  cv::Mat out = v.flow.clone();
  tbb::parallel_for(0, v.labels.rows, [&](int y) {
    for (int x = 0; x < v.labels.cols; ++x) {
      const int label = v.labels.at<uint16_t>(y, x);
      const double d = v.depth.at<float>(y, x);
      if (label == 0 || !(d > 0)) continue;
      const Eigen::Vector2d p(x, y);
      const Eigen::Vector3d point = v.camera_t.Unproject(p, d);
      const std::vector<Observation> seen = Observe(views, point, label, o);
      if (static_cast<int>(seen.size()) < o.min_views) continue;
      const cv::Vec2f f = v.flow.at<cv::Vec2f>(y, x);
      const Eigen::Vector3d start = v.camera_t1.Unproject(p + Eigen::Vector2d(f[0], f[1]), d);
      const Eigen::Vector2d moved = v.camera_t1.Project(RobustMotion(seen, start, o));
      if (!moved.allFinite()) continue;
      out.at<cv::Vec2f>(y, x) = cv::Vec2f(moved.x() - x, moved.y() - y);
    }
  });
  return out;
}

}  // namespace

std::vector<cv::Mat> FlowConsensus(const std::vector<FlowConsensusView>& views,
                                   const FlowConsensusOptions& options) {
  options.Check();
  for (size_t i = 0; i < views.size(); ++i) CheckView(views[i], static_cast<int>(i));
  std::vector<cv::Mat> flows(views.size());
  for (size_t i = 0; i < views.size(); ++i)
    if (!views[i].flow.empty()) flows[i] = ViewConsensus(views, static_cast<int>(i), options);
  return flows;
}

}  // namespace u4d
