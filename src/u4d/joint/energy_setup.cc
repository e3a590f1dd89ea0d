#include "u4d/joint/energy_setup.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include "u4d/baselines/dense_flow.h"
#include "u4d/joint/contrast.h"
#include "u4d/joint/depth_cost.h"
#include "u4d/joint/motion_labels.h"
#include "u4d/joint/motion_regularisation.h"
#include "u4d/mrf/expansion.h"
#include "u4d/util/check.h"

namespace u4d {
namespace {

// The label unaries and E_c alone (the appearance refits, before d and m exist).
struct LabelOnlyEnergy : mrf::GridEnergy {
  const JointEnergy& energy;
  explicit LabelOnlyEnergy(const JointEnergy& e) : energy(e) {}
  double Unary(int p, int label) const override { return energy.LabelUnary(p, label); }
  double Pairwise(int p, int q, int lp, int lq) const override {
    return energy.terms.contrast ? ContrastCost(lp, lq, energy.contrast.At(p, q, energy.width))
                                 : 0.0;
  }
};

// The labels of the objects the view holds (whose hulls HullConfirmation cast).
std::vector<bool> HeldLabels(const JointViewInput& in) {
  std::vector<bool> held(in.num_labels, false);
  for (const JointObject& obj : in.objects)
    if (obj.id >= 0 && obj.id < in.num_labels) held[obj.id] = true;
  return held;
}

// The label maps E_sem combines (JointViewOptions::semantic_temporal): the
// initial labels of t and every other labelled image of ψ_T (t−1, t+1)
// carried to t by dense flow (OpenCV DIS, medium preset) from the reference
// image to that image: map(p) = labels(p + f(p)), nearest, clamped at the border.
std::vector<cv::Mat> SemanticLabelMaps(const JointViewInput& in) {
  std::vector<cv::Mat> maps = {in.initial_labels};
  const cv::Mat& ref = in.images_t[in.ref_view];
  for (const LabelledImage& li : in.appearance_training) {
    if (li.labels.data == in.initial_labels.data || li.image.data == ref.data || li.other_view)
      continue;
    if (li.image.size() != ref.size() || li.labels.size() != ref.size() ||
        li.labels.type() != CV_16UC1)
      continue;
    const cv::Mat flow =
        baselines::DenseFlow(baselines::DenseFlowMethod::kDisMedium, ref, li.image);
    cv::Mat map_x(ref.size(), CV_32F), map_y(ref.size(), CV_32F);
    for (int y = 0; y < ref.rows; ++y)
      for (int x = 0; x < ref.cols; ++x) {
        const cv::Vec2f& f = flow.at<cv::Vec2f>(y, x);
        map_x.at<float>(y, x) = x + f[0];
        map_y.at<float>(y, x) = y + f[1];
      }
    cv::Mat carried;
    cv::remap(li.labels, carried, map_x, map_y, cv::INTER_NEAREST, cv::BORDER_REPLICATE);
    maps.push_back(carried);
  }
  return maps;
}

}  // namespace

void CheckJointViewInput(const JointViewInput& in) {
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
  U4D_CHECK(in.hull_support.empty() || (in.hull_support.type() == CV_16UC1 &&
                                        in.hull_support.size() == in.initial_labels.size()),
            "SolveJointView: the hull support must be CV_16U of the view's size");
  U4D_CHECK(in.hull_confirmed.empty() || (in.hull_confirmed.type() == CV_16UC1 &&
                                          in.hull_confirmed.size() == in.initial_labels.size()),
            "SolveJointView: the confirmed labels must be CV_16U of the view's size");
  U4D_CHECK(in.hull_confirmed_alone.empty() ||
                (in.hull_confirmed_alone.type() == CV_8UC1 &&
                 in.hull_confirmed_alone.size() == in.initial_labels.size()),
            "SolveJointView: the confirmed labels' `alone` must be CV_8U of the view's size");
}

cv::Mat GrowRegion(const cv::Mat& mask, int margin) {
  if (margin <= 0) return mask;
  cv::Mat grown;
  cv::dilate(
      mask, grown,
      cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * margin + 1, 2 * margin + 1)));
  return grown;
}

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
  return GrowRegion(roi, margin);
}

JointEnergy MakeJointEnergy(const JointViewInput& in, const JointViewOptions& options,
                            const cv::Mat& roi) {
  const Camera& cam = in.cameras_t[in.ref_view];
  JointEnergy energy;
  energy.weights = options.weights;
  energy.terms = options.terms;
  energy.pose_options = options.pose;
  energy.smoothness.spatial_weight = options.weights.smooth * options.weights.smooth_spatial;
  energy.smoothness.temporal_weight = options.weights.smooth * options.weights.smooth_temporal;
  energy.smoothness.truncation = options.depth_truncation;
  energy.motion_reg.truncation_px = options.motion_truncation_px;
  energy.motion_reg.quadratic = options.motion_reg_quadratic;
  energy.motion_reg.edge_aware = options.motion_reg_edge_aware;
  energy.motion_reg.boundary = options.motion_reg_boundary;
  energy.width = cam.width;
  energy.height = cam.height;
  energy.num_pixels = cam.width * cam.height;
  energy.num_labels = in.num_labels;
  energy.camera_t = &cam;
  energy.camera_t1 = in.images_t1.empty() ? &cam : &in.cameras_t1[in.ref_view];
  energy.grid.width = energy.width;
  energy.grid.height = energy.height;
  energy.grid.connectivity = 8;
  energy.grid.active.assign(roi.datastart, roi.dataend);
  energy.pairs = mrf::NeighbourPairs(energy.grid);
  // Rays: the world point at depth z is centre + z * rays[p].
  energy.centre = cam.Center();
  energy.rays.resize(energy.num_pixels);
  for (int p = 0; p < energy.num_pixels; ++p)
    energy.rays[p] =
        cam.Unproject(Eigen::Vector2d(p % energy.width, p / energy.width), 1.0) - energy.centre;
  return energy;
}

LabelTermVolumes SetUpLabelUnaries(const JointViewInput& in, const JointViewOptions& options,
                                   const cv::Mat& roi, JointEnergy* energy) {
  const int v = in.ref_view;
  LabelTermVolumes volumes;
  volumes.training = in.appearance_training;
  if (volumes.training.empty()) volumes.training.push_back({in.images_t[v], in.initial_labels});
  // E_a is read in the region (unaries) and one pixel around it (the 3x3
  // windows of WindowSpread for E_r's weights): evaluated there only.
  cv::dilate(roi, volumes.appearance_where, cv::Mat::ones(3, 3, CV_8U));
  volumes.appearance = AppearanceCosts(in.images_t[v], volumes.training, in.num_labels, in.markers,
                                       options.labels, volumes.appearance_where);
  if (!in.hull_confirmed.empty())
    TrustConfirmedLabels(in.hull_confirmed, in.hull_confirmed_alone, HeldLabels(in),
                         &volumes.appearance);
  volumes.semantic = SemanticCosts(
      options.semantic_temporal ? SemanticLabelMaps(in) : std::vector{in.initial_labels},
      in.num_labels, options.labels,
      options.labels.detector_scores ? in.label_scores : std::vector<double>{});
  if (!in.hull_support.empty())
    RelaxSemanticCosts(in.initial_labels, in.hull_support, &volumes.semantic);
  energy->use_pose = options.terms.pose && !in.people.empty();
  const double pose_norm = options.weights.pose_2d + options.weights.pose_3d;
  if (energy->use_pose && pose_norm > 0) {
    energy->pose = RenderPosePrior(in.cameras_t[v], *energy->camera_t1, in.images_t[v], in.people,
                                   options.pose);
    energy->pose_2d_share = options.weights.pose * options.weights.pose_2d / pose_norm;
    energy->pose_3d_share = options.weights.pose * options.weights.pose_3d / pose_norm;
  } else {
    energy->use_pose = false;
  }
  FillLabelUnary(options, volumes, energy);
  return volumes;
}

void FillLabelUnary(const JointViewOptions& options, const LabelTermVolumes& volumes,
                    JointEnergy* energy) {
  const int num_labels = energy->num_labels;
  energy->label_unary.assign(static_cast<size_t>(energy->num_pixels) * num_labels, 0.f);
  tbb::parallel_for(0, energy->num_pixels, [&](int p) {
    for (int l = 0; l < num_labels; ++l) {
      double e = 0;
      if (options.terms.appearance) e += options.weights.appearance * volumes.appearance.At(p, l);
      if (options.terms.semantic) e += options.weights.semantic * volumes.semantic.At(p, l);
      if (energy->use_pose) e += energy->pose_2d_share * PoseLabelCost(energy->pose, p, l);
      energy->label_unary[static_cast<size_t>(p) * num_labels + l] = static_cast<float>(e);
    }
  });
}

void SetUpContrast(const JointViewInput& in, const JointViewOptions& options,
                   const LabelTermVolumes& volumes, JointEnergy* energy) {
  const cv::Mat& image = in.images_t[in.ref_view];
  const std::vector<float> colour =
      ContrastWeights(image.isContinuous() ? image : image.clone(), energy->pairs);
  const std::vector<float> semantic = SemanticContrastWeights(volumes.semantic, energy->pairs);
  energy->contrast = ContrastPairCosts(colour, semantic, energy->pairs, energy->width,
                                       energy->num_pixels, options.weights);
  if (options.motion_reg_edge_aware) {
    energy->reg_edge.Assign(energy->num_pixels, 0.f);
    for (size_t i = 0; i < energy->pairs.size(); ++i) {
      const auto [p, q] = energy->pairs[i];
      energy->reg_edge.At(p, q, energy->width) = colour[i];
    }
  }
}

bool RefitAppearance(const JointViewInput& in, const JointViewOptions& options,
                     LabelTermVolumes* volumes, JointEnergy* energy) {
  if (!(options.terms.appearance && options.appearance_refits > 0 && !volumes->training.empty()))
    return false;
  const int v = in.ref_view, n = energy->num_pixels;
  std::vector<int> candidates(in.num_labels);
  for (int i = 0; i < in.num_labels; ++i) candidates[i] = i;
  mrf::ExpansionOptions expansion_options;
  expansion_options.max_sweeps = options.sweeps_per_block;
  expansion_options.algorithm = options.algorithm;
  // Frame t's entry of ψ_T (the one holding this view's image); added when
  // the caller's list lacks it.
  std::vector<LabelledImage>& training = volumes->training;
  size_t frame_t = 0;
  while (frame_t < training.size() && training[frame_t].image.data != in.images_t[v].data)
    ++frame_t;
  if (frame_t == training.size()) training.push_back({in.images_t[v], in.initial_labels});
  for (int it = 0; it < options.appearance_refits; ++it) {
    std::vector<int> labels(n);
    for (int p = 0; p < n; ++p) labels[p] = in.initial_labels.ptr<uint16_t>()[p];
    mrf::AlphaExpansion(energy->grid, LabelOnlyEnergy(*energy), candidates, &labels,
                        expansion_options);
    cv::Mat refined(energy->height, energy->width, CV_16U);
    for (int p = 0; p < n; ++p) refined.ptr<uint16_t>()[p] = static_cast<uint16_t>(labels[p]);
    training[frame_t].labels = refined;
    volumes->appearance = AppearanceCosts(in.images_t[v], training, in.num_labels, in.markers,
                                          options.labels, volumes->appearance_where);
    if (!in.hull_confirmed.empty())
      TrustConfirmedLabels(in.hull_confirmed, in.hull_confirmed_alone, HeldLabels(in),
                           &volumes->appearance);
    FillLabelUnary(options, *volumes, energy);
  }
  return true;
}

void SetUpMotionRegWeights(const JointViewInput& in, const JointViewOptions& options,
                           const LabelTermVolumes& volumes, JointEnergy* energy) {
  energy->reg_pixel_weight = MotionRegPixelWeights(volumes.semantic, volumes.appearance,
                                                   in.initial_labels, options.weights);
}

void SetUpDepthTerms(const JointViewInput& in, const JointViewOptions& options, const cv::Mat& roi,
                     JointEnergy* energy) {
  const int n = energy->num_pixels;
  double near = 1e30, far = 0;
  for (const JointObject& obj : in.objects)
    if (obj.depth_near > 0 && obj.depth_far > obj.depth_near) {
      near = std::min(near, obj.depth_near);
      far = std::max(far, obj.depth_far);
    }
  U4D_CHECK(far > near, "SolveJointView: view {} has no object with a depth range", in.ref_view);
  energy->depth =
      ComputeDepthCostVolume(in.cameras_t, in.images_t, in.ref_view, roi, near, far, options.depth);
  energy->unknown = energy->depth.NumLabels();
  energy->smoothness.unknown = energy->unknown;
  const int unknown = energy->unknown;
  if (options.depth_object_ranges) {
    // A pixel may take the depths of the objects whose region (grown like the
    // ROI) holds it; one in no object's region keeps every depth.
    energy->depth_lo.assign(n, std::numeric_limits<int16_t>::max());
    energy->depth_hi.assign(n, -1);
    for (const JointObject& obj : in.objects) {
      if (!(obj.depth_near > 0 && obj.depth_far > obj.depth_near)) continue;
      int lo = unknown, hi = -1;
      for (int i = 0; i < unknown; ++i)
        if (energy->depth.depths[i] >= obj.depth_near && energy->depth.depths[i] <= obj.depth_far)
          lo = std::min(lo, i), hi = std::max(hi, i);
      if (hi < 0) continue;
      cv::Mat own = in.initial_labels == obj.id;
      if (!obj.region.empty()) own |= obj.region > 0;
      const cv::Mat grown = GrowRegion(own, options.roi_margin_px);  // as the ROI
      for (int p = 0; p < n; ++p)
        if (grown.data[p]) {
          energy->depth_lo[p] = static_cast<int16_t>(std::min<int>(energy->depth_lo[p], lo));
          energy->depth_hi[p] = static_cast<int16_t>(std::max<int>(energy->depth_hi[p], hi));
        }
    }
    for (int p = 0; p < n; ++p)
      if (energy->depth_hi[p] < 0)
        energy->depth_lo[p] = 0, energy->depth_hi[p] = static_cast<int16_t>(unknown - 1);
  }
  if (!in.previous_depth.empty()) {  // the temporal E_s (no caller sets it: smoothness.h)
    energy->previous_depth_label.assign(n, -1);
    const std::vector<float>& z = energy->depth.depths;
    for (int p = 0; p < n; ++p) {
      const float zp = in.previous_depth.ptr<float>()[p];
      if (!(zp > 0)) continue;
      // Nearest label in inverse depth.
      int best = 0;
      for (int i = 1; i < unknown; ++i)
        if (std::abs(1 / z[i] - 1 / zp) < std::abs(1 / z[best] - 1 / zp)) best = i;
      energy->previous_depth_label[p] = best;
    }
  }
}

FlowCostInput SetUpFlowTerms(const JointViewInput& in, const JointViewOptions& options,
                             const cv::Mat& roi, JointEnergy* energy, cv::Mat* plane_sweep_depth) {
  const bool has_next = !in.images_t1.empty();
  std::vector<SparseMotion> sparse = in.sparse;
  if (energy->use_pose) {  // the paper adds the projected joints to the sparse tracks
    for (const PriorBone& bone : energy->pose.bones) {
      if (!bone.has_motion) continue;
      const Eigen::Vector2d a = energy->camera_t->Project(bone.a),
                            a1 = energy->camera_t1->Project(bone.a1);
      if (a.allFinite() && a1.allFinite() && energy->camera_t->InImage(a))
        sparse.push_back({a, a1 - a, bone.object_id});
    }
  }
  *plane_sweep_depth = WinnerTakeAllDepth(energy->depth, roi);
  FlowCostInput flow_in;
  if (has_next) {
    flow_in.ref_view = in.ref_view;
    flow_in.cameras_t = in.cameras_t;
    flow_in.cameras_t1 = in.cameras_t1;
    flow_in.images_t = in.images_t;
    flow_in.images_t1 = in.images_t1;
    flow_in.depth_t = *plane_sweep_depth;
    flow_in.sparse = sparse;
    flow_in.roi = roi;
    if (options.flow.sparse && options.flow.dense_support)
      flow_in.dense_matches =
          baselines::DenseFlow(baselines::DenseFlowMethod::kDisFine, in.images_t[in.ref_view],
                               in.images_t1[in.ref_view]);
    energy->motion =
        ComputeFlowCostVolume(flow_in, BuildMotionLabels(sparse, options.motion_labels),
                              options.motion_labels, options.flow);
    const int parts = (options.flow.temporal ? 1 : 0) + (options.flow.cross_view ? 1 : 0);
    energy->flow_scale =
        parts > 0 ? static_cast<float>(1.0 / (parts * options.flow.truncation)) : 1.f;
  } else {  // last frame: no motion to estimate
    energy->motion.width = energy->width;
    energy->motion.height = energy->height;
    energy->motion.motions = {Eigen::Vector2f::Zero()};
    energy->motion.slots = MakeRoiSlots(roi, energy->width, energy->height);
    energy->motion.cost.assign(energy->motion.slots.count, 0.f);
  }
  return flow_in;
}

JointLabelling InitialLabelling(const JointViewInput& in, const JointEnergy& energy) {
  const int n = energy.num_pixels, num_motions = energy.motion.NumLabels();
  int zero_motion = 0;
  for (int i = 0; i < num_motions; ++i)
    if (energy.motion.motions[i].isZero()) zero_motion = i;
  JointLabelling labelling;
  labelling.labels.resize(n);
  for (int p = 0; p < n; ++p) labelling.labels[p] = in.initial_labels.ptr<uint16_t>()[p];
  labelling.depths.assign(n, energy.unknown);
  labelling.motions.assign(n, zero_motion);
  tbb::parallel_for(0, n, [&](int p) {
    if (!energy.grid.IsActive(p)) return;
    double best = 1e300;
    for (int i = 0; i <= energy.unknown; ++i) {
      if (!energy.DepthAllowed(p, i)) continue;
      const double e =
          energy.DepthUnary(p, i, labelling.labels[p], energy.motion.motions[zero_motion]);
      if (e < best) best = e, labelling.depths[p] = i;
    }
    best = 1e300;
    for (int i = 0; i < num_motions; ++i) {
      const double e = energy.MotionUnary(p, energy.motion.motions[i], energy.motion.At(p, i),
                                          labelling.labels[p], labelling.depths[p]);
      if (e < best) best = e, labelling.motions[p] = i;
    }
  });
  energy.SetMotionsFromLabels(&labelling);
  return labelling;
}

}  // namespace u4d
