#include "u4d/joint/joint_view.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include "u4d/mrf/expansion.h"
#include "u4d/util/check.h"
#include "u4d/util/timer.h"

namespace u4d {
namespace {

// Index of the forward neighbour direction q - p (p < q, 8-connected):
// (1,0) -> 0, (-1,1) -> 1, (0,1) -> 2, (1,1) -> 3.
inline int Direction(int p, int q, int width) {
  const int d = q - p;
  if (d == 1) return 0;
  if (d == width - 1) return 1;
  if (d == width) return 2;
  return 3;
}

// All precomputed terms of one view's energy and the current labelling.
struct Problem {
  const JointViewOptions* o = nullptr;
  int width = 0, height = 0, n = 0;
  int num_labels = 1;
  const Camera* camera_t = nullptr;
  const Camera* camera_t1 = nullptr;
  mrf::GridGraph grid;
  std::vector<std::pair<int, int>> pairs;  // mrf::NeighbourPairs(grid)

  std::vector<float> label_unary;              // [p * num_labels + l], weighted
  std::array<std::vector<float>, 4> contrast;  // λ_c E_c per forward direction
  std::vector<float> reg_weight;               // λ_r w_r(p)
  DepthCostVolume depth;                       // E_d
  int unknown = 0;                             // the label U (= number of depths)
  std::vector<int> previous_depth_label;       // temporal E_s; -1 = none
  MotionCostVolume motion;                     // E_f
  float flow_scale = 1;                        // normalises E_f to [0, 1]
  PosePriorMap pose;
  bool use_pose = false;
  double pose_2d_share = 0, pose_3d_share = 0;  // λ_p λ_2d / (λ_2d + λ_3d), ...
  std::vector<Eigen::Vector3d> rays;            // world direction per pixel with z = 1 in camera
  Eigen::Vector3d centre;

  std::vector<int> l, d, m;  // the labelling

  const JointWeights& w() const { return o->weights; }
  const JointTerms& t() const { return o->terms; }

  Eigen::Vector3d Point(int p, int depth_label) const {
    return centre + depth.depths[depth_label] * rays[p];
  }
  Eigen::Vector2d Moved(int p, int motion_label) const {
    const Eigen::Vector2f mv = motion.motions[motion_label];
    return Eigen::Vector2d(p % width + mv.x(), p / width + mv.y());
  }
  double DepthPair(int dp, int dq) const {
    if (dp == unknown || dq == unknown) return dp == dq ? 0.0 : 1.0;
    return std::min<double>(std::abs(dp - dq), o->depth_truncation) / o->depth_truncation;
  }
  // E_p's 3D part (couples d and m).
  double Pose3d(int p, int dl, int ml) const {
    if (!use_pose || dl == unknown) return 0;
    return pose_3d_share *
           u4d::Pose3dCost(pose, p, Point(p, dl), Moved(p, ml), *camera_t1, o->pose);
  }
  double DepthUnary(int p, int dl, int ml) const {
    double e = 0;
    if (t().depth) e += w().depth * (dl == unknown ? depth.unknown_cost : depth.At(p, dl));
    if (t().smooth && !previous_depth_label.empty() && previous_depth_label[p] >= 0)
      e += w().smooth * w().smooth_temporal * DepthPair(dl, previous_depth_label[p]);
    return e + Pose3d(p, dl, ml);
  }
  double MotionUnary(int p, int ml, int dl) const {
    double e = 0;
    const float f = motion.At(p, ml);
    if (f >= kForbiddenMotion) return mrf::kInfiniteCost;
    if (t().flow) e += w().flow * f * flow_scale;
    if (use_pose) e += pose_2d_share * PoseMotion2dCost(pose, p, motion.motions[ml], o->pose);
    return e + Pose3d(p, dl, ml);
  }
  double LabelUnary(int p, int ll) const {
    return label_unary[static_cast<size_t>(p) * num_labels + ll];
  }
  double Pair(int p, int q, int lp, int lq, int dp, int dq, int mp, int mq) const {
    if (lp != lq) return t().contrast ? contrast[Direction(p, q, width)][p] : 0.0;
    double e = 0;
    if (t().smooth) e += w().smooth * w().smooth_spatial * DepthPair(dp, dq);
    if (t().motion_reg) {
      const double dm = (motion.motions[mp] - motion.motions[mq]).norm();
      e += 0.5 * (reg_weight[p] + reg_weight[q]) * std::min(dm, o->motion_truncation_px) /
           o->motion_truncation_px;
    }
    return e;
  }
  double Energy() const;
};

double Problem::Energy() const {
  double e = 0;
  for (int p = 0; p < n; ++p) {
    if (!grid.IsActive(p)) continue;
    e += LabelUnary(p, l[p]) + DepthUnary(p, d[p], m[p]) + MotionUnary(p, m[p], d[p]);
  }
  for (const auto& [p, q] : pairs)
    if (grid.IsActive(p) || grid.IsActive(q)) e += Pair(p, q, l[p], l[q], d[p], d[q], m[p], m[q]);
  return e;
}

// The energy as a function of one factor, the others fixed.
struct LabelBlock : mrf::GridEnergy {
  const Problem& pr;
  explicit LabelBlock(const Problem& p) : pr(p) {}
  double Unary(int p, int label) const override { return pr.LabelUnary(p, label); }
  double Pairwise(int p, int q, int lp, int lq) const override {
    return pr.Pair(p, q, lp, lq, pr.d[p], pr.d[q], pr.m[p], pr.m[q]);
  }
};
struct DepthBlock : mrf::GridEnergy {
  const Problem& pr;
  explicit DepthBlock(const Problem& p) : pr(p) {}
  double Unary(int p, int label) const override { return pr.DepthUnary(p, label, pr.m[p]); }
  double Pairwise(int p, int q, int dp, int dq) const override {
    return pr.Pair(p, q, pr.l[p], pr.l[q], dp, dq, pr.m[p], pr.m[q]);
  }
};
struct MotionBlock : mrf::GridEnergy {
  const Problem& pr;
  explicit MotionBlock(const Problem& p) : pr(p) {}
  double Unary(int p, int label) const override { return pr.MotionUnary(p, label, pr.d[p]); }
  double Pairwise(int p, int q, int mp, int mq) const override {
    return pr.Pair(p, q, pr.l[p], pr.l[q], pr.d[p], pr.d[q], mp, mq);
  }
};

cv::Mat RegionOfInterest(const JointViewInput& in, int margin) {
  const cv::Size size = in.initial_labels.size();
  cv::Mat roi = in.initial_labels > 0;
  for (const JointObject& obj : in.objects) {
    if (obj.region.empty()) continue;
    U4D_CHECK(obj.region.size() == size && obj.region.type() == CV_8UC1,
              "SolveJointView: region of object {} must be CV_8U {}x{}", obj.id, size.width,
              size.height);
    roi |= obj.region > 0;
  }
  if (margin > 0)
    cv::dilate(
        roi, roi,
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * margin + 1, 2 * margin + 1)));
  return roi;
}

// e_r^X(p): mean minus min of a label cost over the 3x3 window, at the labels.
std::vector<float> WindowSpread(const LabelCostVolume& volume, const cv::Mat& labels) {
  const int w = volume.width, h = volume.height;
  std::vector<float> spread(static_cast<size_t>(w) * h, 0.f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double sum = 0, lo = 1e30;
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const double c = volume.At(qy * w + qx, labels.at<uint16_t>(qy, qx));
          sum += c;
          lo = std::min(lo, c);
          ++count;
        }
      spread[static_cast<size_t>(y) * w + x] = static_cast<float>(sum / count - lo);
    }
  return spread;
}

void CheckInput(const JointViewInput& in) {
  const int v = in.ref_view;
  const int nv = static_cast<int>(in.cameras_t.size());
  U4D_CHECK(nv >= 2, "SolveJointView: need at least two views, got {}", nv);
  U4D_CHECK(v >= 0 && v < nv, "SolveJointView: ref_view {} out of range [0, {})", v, nv);
  U4D_CHECK(static_cast<int>(in.images_t.size()) == nv,
            "SolveJointView: {} images at t for {} cameras", in.images_t.size(), nv);
  U4D_CHECK(in.images_t1.empty() || (static_cast<int>(in.images_t1.size()) == nv &&
                                     static_cast<int>(in.cameras_t1.size()) == nv),
            "SolveJointView: images and cameras at t+1 must cover all {} views", nv);
  const Camera& cam = in.cameras_t[v];
  U4D_CHECK(in.initial_labels.type() == CV_16UC1 && in.initial_labels.cols == cam.width &&
                in.initial_labels.rows == cam.height,
            "SolveJointView: initial labels must be CV_16U {}x{}", cam.width, cam.height);
  U4D_CHECK(in.num_labels >= 1, "SolveJointView: num_labels must be >= 1");
  double max_label = 0;
  cv::minMaxLoc(in.initial_labels, nullptr, &max_label);
  U4D_CHECK(max_label < in.num_labels, "SolveJointView: initial label {} >= num_labels {}",
            max_label, in.num_labels);
  for (const JointObject& obj : in.objects)
    U4D_CHECK(obj.id >= 1 && obj.id < in.num_labels, "SolveJointView: object id {} out of [1, {})",
              obj.id, in.num_labels);
  U4D_CHECK(in.previous_depth.empty() || (in.previous_depth.type() == CV_32FC1 &&
                                          in.previous_depth.size() == in.initial_labels.size()),
            "SolveJointView: previous depth must be CV_32F of the view's size");
}

}  // namespace

void JointViewOptions::Check() const {
  weights.Check();
  labels.Check();
  depth.Check();
  motion_labels.Check();
  flow.Check();
  pose.Check();
  U4D_CHECK(rounds >= 1, "JointViewOptions.rounds must be >= 1, got {}", rounds);
  U4D_CHECK(sweeps_per_block >= 1, "JointViewOptions.sweeps_per_block must be >= 1");
  U4D_CHECK(depth_truncation > 0, "JointViewOptions.depth_truncation must be > 0");
  U4D_CHECK(motion_truncation_px > 0, "JointViewOptions.motion_truncation_px must be > 0");
  U4D_CHECK(roi_margin_px >= 0, "JointViewOptions.roi_margin_px must be >= 0");
}

JointViewResult SolveJointView(const JointViewInput& in, const JointViewOptions& o) {
  o.Check();
  CheckInput(in);
  Timer timer;
  const int v = in.ref_view;
  const Camera& cam = in.cameras_t[v];
  const bool has_next = !in.images_t1.empty();

  Problem pr;
  pr.o = &o;
  pr.width = cam.width;
  pr.height = cam.height;
  pr.n = cam.width * cam.height;
  pr.num_labels = in.num_labels;
  pr.camera_t = &cam;
  pr.camera_t1 = has_next ? &in.cameras_t1[v] : &cam;
  const cv::Mat roi = RegionOfInterest(in, o.roi_margin_px);
  pr.grid.width = pr.width;
  pr.grid.height = pr.height;
  pr.grid.connectivity = 8;
  pr.grid.active.assign(roi.datastart, roi.dataend);

  // Rays: the world point at depth z is centre + z * rays[p].
  pr.centre = cam.Center();
  pr.rays.resize(pr.n);
  for (int p = 0; p < pr.n; ++p)
    pr.rays[p] = cam.Unproject(Eigen::Vector2d(p % pr.width, p / pr.width), 1.0) - pr.centre;

  // ---- Label unaries: E_a, E_sem, E_p (2D label part).
  std::vector<LabelledImage> training = in.appearance_training;
  if (training.empty()) training.push_back({in.images_t[v], in.initial_labels});
  const LabelCostVolume appearance =
      AppearanceCosts(in.images_t[v], training, in.num_labels, in.markers, o.labels);
  const LabelCostVolume semantic = SemanticCosts(in.initial_labels, in.num_labels, o.labels);
  pr.use_pose = o.terms.pose && !in.people.empty();
  const double pose_norm = o.weights.pose_2d + o.weights.pose_3d;
  if (pr.use_pose && pose_norm > 0) {
    pr.pose = RenderPosePrior(cam, *pr.camera_t1, in.images_t[v], in.people, o.pose);
    pr.pose_2d_share = o.weights.pose * o.weights.pose_2d / pose_norm;
    pr.pose_3d_share = o.weights.pose * o.weights.pose_3d / pose_norm;
  } else {
    pr.use_pose = false;
  }
  pr.label_unary.assign(static_cast<size_t>(pr.n) * in.num_labels, 0.f);
  tbb::parallel_for(0, pr.n, [&](int p) {
    for (int l = 0; l < in.num_labels; ++l) {
      double e = 0;
      if (o.terms.appearance) e += o.weights.appearance * appearance.At(p, l);
      if (o.terms.semantic) e += o.weights.semantic * semantic.At(p, l);
      if (pr.use_pose) e += pr.pose_2d_share * PoseLabelCost(pr.pose, p, l);
      pr.label_unary[static_cast<size_t>(p) * in.num_labels + l] = static_cast<float>(e);
    }
  });

  // ---- Pairwise weights: E_c and the E_r weights.
  pr.pairs = mrf::NeighbourPairs(pr.grid);
  const std::vector<std::pair<int, int>>& pairs = pr.pairs;
  const std::vector<float> colour = ContrastWeights(
      in.images_t[v].isContinuous() ? in.images_t[v] : in.images_t[v].clone(), pairs);
  const std::vector<float> sem_contrast = SemanticContrastWeights(semantic, pairs);
  for (auto& c : pr.contrast) c.assign(pr.n, 0.f);
  const double cw = o.weights.contrast_colour + o.weights.contrast_label;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const auto [p, q] = pairs[i];
    const double e =
        cw > 0
            ? (o.weights.contrast_colour * colour[i] + o.weights.contrast_label * sem_contrast[i]) /
                  cw
            : 0.0;
    pr.contrast[Direction(p, q, pr.width)][p] = static_cast<float>(o.weights.contrast * e);
  }
  {
    const std::vector<float> spread_l = WindowSpread(semantic, in.initial_labels);
    const std::vector<float> spread_a = WindowSpread(appearance, in.initial_labels);
    pr.reg_weight.resize(pr.n);
    for (int p = 0; p < pr.n; ++p)
      pr.reg_weight[p] = static_cast<float>(o.weights.motion_reg *
                                            (1.0 + o.weights.motion_reg_label * spread_l[p] +
                                             o.weights.motion_reg_app * spread_a[p]));
  }

  // ---- Depth labels and E_d over the objects' depth range.
  double near = 1e30, far = 0;
  for (const JointObject& obj : in.objects)
    if (obj.depth_near > 0 && obj.depth_far > obj.depth_near) {
      near = std::min(near, obj.depth_near);
      far = std::max(far, obj.depth_far);
    }
  U4D_CHECK(far > near, "SolveJointView: view {} has no object with a depth range", v);
  pr.depth = ComputeDepthCostVolume(in.cameras_t, in.images_t, v, roi, near, far, o.depth);
  pr.unknown = pr.depth.NumLabels();
  if (!in.previous_depth.empty()) {
    pr.previous_depth_label.assign(pr.n, -1);
    const std::vector<float>& z = pr.depth.depths;
    for (int p = 0; p < pr.n; ++p) {
      const float zp = in.previous_depth.ptr<float>()[p];
      if (!(zp > 0)) continue;
      // Nearest label in inverse depth.
      int best = 0;
      for (int i = 1; i < pr.unknown; ++i)
        if (std::abs(1 / z[i] - 1 / zp) < std::abs(1 / z[best] - 1 / zp)) best = i;
      pr.previous_depth_label[p] = best;
    }
  }

  // ---- Motion labels and E_f (cross-view part with the plane-sweep depth).
  std::vector<SparseMotion> sparse = in.sparse;
  if (pr.use_pose) {  // the paper adds the projected joints to the sparse tracks
    for (const PriorBone& bone : pr.pose.bones) {
      if (!bone.has_motion) continue;
      const Eigen::Vector2d a = cam.Project(bone.a), a1 = pr.camera_t1->Project(bone.a1);
      if (a.allFinite() && a1.allFinite() && cam.InImage(a))
        sparse.push_back({a, a1 - a, bone.object_id});
    }
  }
  const cv::Mat wta_depth = WinnerTakeAllDepth(pr.depth, roi);
  if (has_next) {
    FlowCostInput flow_in;
    flow_in.ref_view = v;
    flow_in.cameras_t = in.cameras_t;
    flow_in.cameras_t1 = in.cameras_t1;
    flow_in.images_t = in.images_t;
    flow_in.images_t1 = in.images_t1;
    flow_in.depth_t = wta_depth;
    flow_in.sparse = sparse;
    flow_in.roi = roi;
    pr.motion = ComputeFlowCostVolume(flow_in, BuildMotionLabels(sparse, o.motion_labels),
                                      o.motion_labels, o.flow);
    const int parts = (o.flow.temporal ? 1 : 0) + (o.flow.cross_view ? 1 : 0);
    pr.flow_scale = parts > 0 ? static_cast<float>(1.0 / (parts * o.flow.truncation)) : 1.f;
  } else {  // last frame: no motion to estimate
    pr.motion.width = pr.width;
    pr.motion.height = pr.height;
    pr.motion.motions = {Eigen::Vector2f::Zero()};
    pr.motion.cost.assign(pr.n, 0.f);
  }
  const int num_motions = pr.motion.NumLabels();
  int zero_motion = 0;
  for (int i = 0; i < num_motions; ++i)
    if (pr.motion.motions[i].isZero()) zero_motion = i;

  // ---- Initial labelling: initial masks, then the best depth, then the best motion.
  pr.l.resize(pr.n);
  for (int p = 0; p < pr.n; ++p) pr.l[p] = in.initial_labels.ptr<uint16_t>()[p];
  pr.d.assign(pr.n, pr.unknown);
  pr.m.assign(pr.n, zero_motion);
  tbb::parallel_for(0, pr.n, [&](int p) {
    if (!pr.grid.IsActive(p)) return;
    double best = 1e300;
    for (int i = 0; i <= pr.unknown; ++i) {
      const double e = pr.DepthUnary(p, i, zero_motion);
      if (e < best) best = e, pr.d[p] = i;
    }
    best = 1e300;
    for (int i = 0; i < num_motions; ++i) {
      const double e = pr.MotionUnary(p, i, pr.d[p]);
      if (e < best) best = e, pr.m[p] = i;
    }
  });

  JointViewResult result;
  result.roi = roi;
  result.plane_sweep_depth = wta_depth;
  result.num_depth_labels = pr.unknown + 1;
  result.num_motion_labels = num_motions;
  result.energy_trace.push_back({"init", pr.Energy(), timer.Seconds()});

  mrf::ExpansionOptions eo;
  eo.max_sweeps = o.sweeps_per_block;
  eo.algorithm = o.algorithm;
  std::vector<int> label_candidates(in.num_labels), depth_candidates(pr.unknown + 1),
      motion_candidates(num_motions);
  for (int i = 0; i < in.num_labels; ++i) label_candidates[i] = i;
  for (int i = 0; i <= pr.unknown; ++i) depth_candidates[i] = i;
  for (int i = 0; i < num_motions; ++i) motion_candidates[i] = i;
  for (int round = 0; round < o.rounds; ++round) {
    Timer block_timer;
    mrf::AlphaExpansion(pr.grid, LabelBlock(pr), label_candidates, &pr.l, eo);
    result.energy_trace.push_back({"labels", pr.Energy(), block_timer.Seconds()});
    block_timer = Timer();
    mrf::AlphaExpansion(pr.grid, DepthBlock(pr), depth_candidates, &pr.d, eo);
    result.energy_trace.push_back({"depth", pr.Energy(), block_timer.Seconds()});
    if (has_next) {
      block_timer = Timer();
      mrf::AlphaExpansion(pr.grid, MotionBlock(pr), motion_candidates, &pr.m, eo);
      result.energy_trace.push_back({"motion", pr.Energy(), block_timer.Seconds()});
    }
  }

  // ---- Outputs: labels, sub-sample depth on object pixels, sub-pixel flow.
  result.labels = cv::Mat(pr.height, pr.width, CV_16U);
  std::vector<int> depth_labels(pr.n);
  for (int p = 0; p < pr.n; ++p) {
    result.labels.ptr<uint16_t>()[p] = static_cast<uint16_t>(pr.l[p]);
    depth_labels[p] = (pr.l[p] == 0 || pr.d[p] == pr.unknown) ? -1 : pr.d[p];
  }
  result.depth = RefineDepthLabels(pr.depth, depth_labels);
  if (has_next) {
    std::vector<int> motion_labels(pr.m);
    for (int p = 0; p < pr.n; ++p)
      if (!pr.grid.IsActive(p)) motion_labels[p] = -1;
    result.flow = RefineFlowLabels(pr.motion, motion_labels);
  } else {
    result.flow = cv::Mat::zeros(pr.height, pr.width, CV_32FC2);
  }
  result.seconds = timer.Seconds();
  return result;
}

}  // namespace u4d
