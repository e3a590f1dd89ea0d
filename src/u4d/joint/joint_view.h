// The joint per-view optimisation of instance label l, depth d and motion m
// (paper Sec. 2.1, Eq. 1) for one view at frame t:
//
//   E(l,d,m) = λ_d E_d + λ_a E_a + λ_sem E_sem + λ_f E_f
//            + λ_s E_s + λ_c E_c + λ_r E_r + λ_p E_p
//
// Terms (each normalised to about [0, 1] per pixel or neighbour pair):
//   E_d   depth_cost.h (multi-view ZNCC over the k best auxiliary views; U at M_U)
//   E_a   label_costs.h AppearanceCosts (10-component colour GMMs, ψ_T masks + sparse markers)
//   E_sem label_costs.h SemanticCosts (soft initial instance masks)
//   E_f   flow_cost.h (temporal and cross-view brightness constancy; sparse-track windows)
//   E_s   smoothness.h: [l_p = l_q] (λ_s^s min(|d_p − d_q|, τ_d) / τ_d) over 8-neighbours,
//         depth in label steps (inverse depth), U against a depth costs 1; plus the temporal
//         part λ_s^t min(|d_p − d^{t−1}_p|, τ_d) / τ_d against the previous frame's depth
//         carried to t by its flow (JointViewInput::previous_depth; no caller sets it, so it
//         is off in the pipeline: smoothness.h)
//   E_c   contrast.h: [l_p ≠ l_q] (λ_ca c_pq + λ_cl s_pq) / (λ_ca + λ_cl): colour and semantic
//         contrast
//   E_r   motion_regularisation.h: w_pq min(||m_p − m_q||², τ_m²) / τ_m² over 8-neighbours
//         (the paper's squared difference, truncated), w_pq = (1 + λ_r^L e_r^L + λ_r^A e_r^A) c_pq
//         with e_r^X(p) = mean − min of E_X over p's 3x3 window at the initial labels (fixed for
//         the whole optimisation, so the energy is one function) and c_pq the colour-contrast
//         weight of E_c (edge-aware, as Tao et al. 2012; motion_reg_edge_aware). At label
//         boundaries (MotionRegBoundary): by default charged for every pair whatever the labels.
//         The paper gates it by [l_p = l_q]; read literally, a label cut then removes the
//         motion-smoothness cost of a pair, so wherever the estimated motion varies inside a
//         person a cut is the cheaper way out and the labels fragment. Motion
//         smoothness must not reward cuts. Charged
//         regardless of the labels, E_r does not depend on l and label boundaries are left
//         to E_c, E_a, E_sem, E_p and E_s; the other form that never rewards a cut (a
//         boundary pays the truncated maximum, kDiscontinuity) pulls boundaries to jumps of
//         the estimated motion (docs/joint.md, "Choices where the paper is not explicit").
//   E_p   pose_prior.h, (λ_2d e_2d + λ_3d e_3d) / (λ_2d + λ_3d)
//
// The code: joint_energy.h holds the energy (every term's weights and data,
// EnergyOf a labelling), energy_setup.h fills it from a JointViewInput,
// block_schedule.h runs the blocks and flow_fusion.h the fusion stage;
// SolveJointView is those steps in order.
//
// Flow fusion (flow_fusion.h): after the blocks the motion is made continuous: fusion moves
// (mrf::FusionMove, Lempitsky et al. 2010) of the current field with dense
// proposals (the discrete solution refined by parabola fits, OpenCV DIS at
// its finest scale and at the medium preset, their mean, the current field
// smoothed; FlowFusionOptions) under the full energy with l and
// d fixed. E_f of a sub-pixel motion is FlowFieldCosts (bilinear sampling, same
// patch and truncation as the volume); its e_F^S is that of the nearest
// integer offset in M (forbidden when that offset is not in M). The energy is
// the same function (integer motions cost what their labels cost), and every
// fusion is accepted only when it lowers it.
//
// Solver (block_schedule.h): the product label space L × D × M is optimised by alternating
// α-expansion over each factor with the others fixed (mrf/expansion.h): a
// label block (α ∈ L), a depth block (α ∈ D ∪ {U}) and a motion block
// (α ∈ M; in the first `motion_rounds` rounds), `rounds` times; from the second round the label
// block moves (label, depth) pairs, a pixel taking label l taking the depth of the nearest pixel
// labelled l (label_moves_carry_depth). Every move is an expansion move of the full energy
// restricted to what it changes and is accepted only when the full energy decreases, so the energy
// never increases (JointViewResult::energy_trace). Tractability (the design brief): only pixels of
// the objects' regions (dilated) are optimised, depth labels span the objects' depth range (a
// pixel taking those of the objects near it: depth_object_ranges), motion
// labels are windows around the sparse track displacements, and the problem is solved at a working
// resolution (JointViewOptions::working_width).
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"
#include "u4d/joint/background_flow.h"
#include "u4d/joint/depth_cost.h"
#include "u4d/joint/flow_cost.h"
#include "u4d/joint/label_costs.h"
#include "u4d/joint/motion_labels.h"
#include "u4d/joint/motion_regularisation.h"  // MotionRegBoundary
#include "u4d/joint/parameters.h"
#include "u4d/joint/pose_prior.h"
#include "u4d/mrf/max_flow.h"

namespace u4d {

// The flow fusion stage (after the discrete blocks): the motion becomes
// continuous and is improved by fusion moves (mrf::FusionMove) of the current
// field with dense proposals under the full energy, l and d fixed.
struct FlowFusionOptions {
  bool enabled = true;    // run the stage (only when E_f is on: the proposals are photometric)
  bool refined = true;    // proposal: the discrete solution refined by parabola fits of E_f
  bool deepflow = false;  // proposal: OpenCV DeepFlow of the reference view t -> t+1
  // Proposal: OpenCV DIS (medium preset) down to the finest pyramid scale
  // (setFinestScale(0)) with 10 variational refinement iterations: a lower
  // EPE than DeepFlow as a proposal, in a fraction of its time.
  bool dis_fine = true;
  bool dis = true;  // proposal: OpenCV DIS (medium preset)
  // With exactly two of the three above, their mean is a proposal too.
  bool smoothed = true;  // proposal: the current field, Gaussian-smoothed (σ = 1 px, 5x5)
  int rounds = 2;        // passes over the proposals (>= 1)
  void Check() const;    // throws u4d::Error naming the bad field
};

struct JointViewOptions {
  JointWeights weights;              // λ's (PaperWeights by default)
  JointTerms terms;                  // which terms are on (presets: AblationTerms)
  LabelCostOptions labels;           // E_a, E_sem
  DepthCostOptions depth;            // E_d
  MotionLabelOptions motion_labels;  // M and e_F^S
  FlowCostOptions flow;              // E_f
  PosePriorOptions pose;             // E_p
  int rounds = 2;                    // alternations of the l, d, m blocks
  // The motion block runs in the first motion_rounds rounds only (>= 1): the
  // flow fusion refines the motion after the last round, so a later motion
  // block has almost nothing left to lower.
  int motion_rounds = 1;
  // Expansion sweeps per block and round. The rounds already alternate the
  // blocks, so a second sweep within a block has little left to lower.
  int sweeps_per_block = 1;
  double depth_truncation = 4;  // τ_d, depth label steps
  // Coarse-to-fine depth block: > 1 runs the expansion first over every
  // depth_coarse_step-th depth (and U), then over all depths with each pixel
  // allowed to move by at most depth_coarse_step labels (mrf::GridEnergy::MayTake);
  // 0 or 1: one pass over all depths, every pixel a candidate for each.
  int depth_coarse_step = 0;
  // From the second round on, the depth block lets a pixel with a depth move
  // by at most this many labels (or to U; a pixel at U may take any depth):
  // the first round has placed every pixel, the later ones refine. 0 = no
  // limit.
  int depth_refine_band = 4;
  // A pixel may take only the depths of the objects whose region (grown by
  // roi_margin_px) holds it, each object's [depth_near, depth_far], or U; a
  // pixel in no object's region may take every depth (false: every pixel
  // every depth of the union range).
  bool depth_object_ranges = true;
  // > 0: in the motion block a pixel may take only the motions among its
  // motion_candidates_per_pixel lowest unaries (at its labels after the depth
  // block; ties included) or keep its own; 0 = every motion. The flow fusion
  // after the blocks is not limited and recovers most of what the limit
  // costs. On fast motion the limit costs some temporal coherence (S_e); 0 is
  // the setting there (docs/joint.md, "The solver").
  int motion_candidates_per_pixel = 12;
  double motion_truncation_px = 4;  // τ_m, pixels (working resolution)
  // E_r's distance: min(|Δm|², τ_m²) / τ_m² (the paper's squared difference; true) or
  // min(|Δm|, τ_m) / τ_m (a metric, every expansion move submodular; false).
  bool motion_reg_quadratic = true;
  // E_r's pair weight also multiplied by the colour contrast weight of E_c
  // (label_costs.h ContrastWeights, in (0, 1]): motion smoothing fades across colour edges.
  bool motion_reg_edge_aware = true;
  MotionRegBoundary motion_reg_boundary = MotionRegBoundary::kIgnoreLabels;  // E_r across labels
  // E_sem over the temporal neighbourhood ψ_T, as the paper sums it: P_sem from the
  // initial masks of t and of the other labelled frames of appearance_training
  // (t−1, t+1), each carried to t by dense flow (DIS) from the reference image,
  // combined by the median signed distance to each label's boundary (label_costs.h).
  // A detector's errors that differ between frames (a boundary dilated by a few
  // pixels, a dropped forearm) are then outvoted instead of copied (the same volume
  // feeds E_c's semantic contrast and E_r's e_r^L); but where the
  // flow is wrong (a swinging foot) the carried masks outvote the right one.
  // Off by default: where the flow is wrong (a swinging foot) the carried masks
  // outvote the right one, and an error the detector makes in every frame stays. false: the initial
  // mask of t only.
  bool semantic_temporal = false;
  FlowFusionOptions fusion;  // continuous flow proposals fused after the blocks
  // The flow outside the objects' regions: the rigid flow of the camera's
  // motion (background_flow.h; 0 on a still camera).
  BackgroundFlowOptions background_flow;
  int roi_margin_px = 8;  // dilation of the objects' regions (working pixels)
  // Before the energy is fixed: minimise the label unaries + E_c alone and
  // re-learn frame t's colour GMMs from that labelling, this many times
  // (GrabCut's iteration; 0 = the GMMs of the initial masks, as the paper).
  int appearance_refits = 1;
  // Label moves after the first round change a pixel's depth with its label:
  // a pixel that takes label l takes the depth of the nearest pixel labelled l
  // (false: the label block moves labels at fixed depth).
  bool label_moves_carry_depth = true;
  mrf::MaxFlowAlgorithm algorithm = mrf::MaxFlowAlgorithm::kBoykovKolmogorov;
  void Check() const;
};

// One object in this view: its region and depth range (features/object_regions.h),
// at the working resolution.
struct JointObject {
  int id = 0;                            // label (>= 1)
  cv::Mat region;                        // CV_8U, nonzero inside
  double depth_near = 0, depth_far = 0;  // metres (z in the camera); 0 = unknown
};

// Everything the optimisation of one view at frame t needs, at the working
// resolution (cameras via ScaledCamera, images resized).
struct JointViewInput {
  int ref_view = 0;
  std::vector<Camera> cameras_t, cameras_t1;  // all views
  std::vector<cv::Mat> images_t, images_t1;   // all views, BGR 8-bit; images_t1 empty = last frame
  cv::Mat initial_labels;                     // CV_16U object ids of the reference view
  // Per label: the detector's score of its initial mask in this view (E_sem,
  // label_costs.h LabelScores); empty = 1 for every label.
  std::vector<double> label_scores;
  int num_labels = 1;  // 1 + the largest object id
  std::vector<JointObject> objects;
  std::vector<LabelledImage> appearance_training;     // ψ_T (incl. frame t)
  std::vector<std::vector<Eigen::Vector2d>> markers;  // per label: sparse foreground pixels
  std::vector<PersonPose> people;                     // 3D poses (may be empty)
  std::vector<SparseMotion> sparse;                   // sparse correspondences t -> t+1
  cv::Mat previous_depth;  // CV_32F depth of t−1 carried to t (0 = none); empty = none
  // CV_16U: the object the other views' visual hull puts at a pixel the
  // initial labels call background (hull_support.h), 0 = none; empty = none.
  // E_sem there does not prefer the background over that object.
  cv::Mat hull_support;
  // CV_16U: the view's own label where the other views' hull confirms it
  // (hull_support.h HullConfirmation), 0 = none; empty = none.
  cv::Mat hull_confirmed;
  // CV_8U: those of hull_confirmed whose ray meets no other object's hull;
  // empty = none.
  cv::Mat hull_confirmed_alone;
};

// Energy after each block, with its name ("init", "labels", "depth", "motion", "fusion").
struct EnergyStep {
  std::string block;
  double energy = 0;
  double seconds = 0;
};

struct JointViewResult {
  cv::Mat labels;  // CV_16U object ids (0 = background), working resolution
  cv::Mat depth;   // CV_32F z (0 = background or unknown)
  cv::Mat flow;    // CV_32FC2 forward flow t -> t+1 (pixels, working resolution)
  cv::Mat roi;     // CV_8U the optimised pixels
  // CV_32F winner-take-all of E_d over the same depth labels and roi: the
  // plane-sweep baseline, computed anyway for the cross-view flow term.
  cv::Mat plane_sweep_depth;
  std::vector<EnergyStep> energy_trace;
  int num_depth_labels = 0, num_motion_labels = 0;
  double seconds = 0;
  // Time of the phases, in order: the set-up ("label unaries", "pairwise
  // weights", "depth volume", "flow volume", "initial labelling"), the blocks
  // summed over the rounds ("labels", "depth", "motion") and the fusion stage
  // ("fusion proposals": DeepFlow, DIS; "fusion moves"). For profiling
  // (bench/joint_phases_bench; docs/results.md, "Hot kernels and the phases of
  // one joint view solve").
  struct Phase {
    std::string name;
    double seconds = 0;      // wall clock
    double cpu_seconds = 0;  // process CPU time (all threads; includes any concurrent work)
  };
  std::vector<Phase> phases;
};

// The flow fusion's proposals that do not depend on the state, for grey
// (CV_8U) frames t and t+1 of one size: DeepFlow, DIS fine, DIS medium (the
// ones `options` enables, in that order), then, with exactly two of them, their
// mean. `fine_dis`, when given, is the DIS fine flow of the same frames
// (baselines::DenseFlow, DenseFlowMethod::kDisFine), already computed (E_f's
// dense matches), and is used instead of computing it again.
// Throws u4d::Error on images that are not 8-bit grey of one size.
// Defined in flow_fusion.cc (the stage itself: flow_fusion.h).
std::vector<cv::Mat> FlowFusionProposals(const cv::Mat& grey_t, const cv::Mat& grey_t1,
                                         const FlowFusionOptions& options,
                                         const cv::Mat& fine_dis = {});

// Throws u4d::Error on inconsistent input (sizes, counts, label ids).
JointViewResult SolveJointView(const JointViewInput& input, const JointViewOptions& options);

}  // namespace u4d
