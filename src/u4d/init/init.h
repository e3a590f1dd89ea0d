// Unsupervised initial instance masks: what U4D starts from when a capture
// has neither initial masks (masks/) nor poses (issue 5; the paper, Sec. 2,
// assumes an off-the-shelf instance segmentation, this module replaces it
// for static cameras). Three steps, each usable alone:
//
// 1. Background model (static camera). Per view, the per-pixel median of up
//    to `max_frames` frames spread evenly over the sequence, in CIE Lab
//    (OpenCV's 8-bit Lab: L in [0, 255], a and b offset by 128). The noise
//    level sigma is estimated from the same frames: the median over pixels
//    and sampled frames of the Lab distance to the background, divided by
//    1.54 (the median of a 3-dof chi distribution, i.e. per-channel Gaussian
//    noise of std sigma); moving people cover a minority of the pixels, so
//    the median sees the noise. A per-pixel noise level (the median distance
//    of that pixel over the samples / 1.54) raises the threshold where the
//    background itself flickers (compression, leaves, screens).
//
// 2. Foreground. A pixel is foreground when its Lab distance to the
//    background exceeds threshold_sigmas * max(sigma, pixel sigma, floor),
//    unless it is a shadow: darker than the background by a factor in
//    [shadow_min_ratio, shadow_max_ratio] in L with a chroma (a, b) change
//    below shadow_chroma_sigmas * sigma. The binary mask is cleaned by a
//    morphological opening and closing and by removing connected components
//    smaller than min_blob_fraction of the image area; holes smaller than
//    that are filled.
//
// 3. Cross-view consistency (calibrated static cameras; a visual-hull test
//    on the silhouettes). At a reduced resolution (longest side
//    consistency_max_side), a foreground pixel of view c is consistent when
//    its ray has a depth at which it projects into the (dilated) foreground
//    of at least ceil(min_view_fraction * n) of the n other views in whose
//    image it falls, with n >= min(min_views_seeing, views - 1). Requiring
//    two views matters: points just in front of camera c project, in the
//    camera facing it, onto the people between the two. The ray is marched
//    from min_depth_m to max_depth_m with steps adapted so that its
//    projection moves about step_px (reduced) pixels in the other views
//    (0.5x..2x per step, between 1 mm and 0.25 m). A connected component of
//    the full-resolution mask is kept when at least min_consistent_fraction of
//    its pixels are consistent; with carve_pixels, inconsistent pixels are
//    also removed inside kept components.
//
// 4. People instances. Connected components of the foreground, dilated by
//    group_radius_px (fragments of one person stay together), are the
//    instances. Optionally (grabcut_box_iterations > 0, off by default: on
//    the synthetic rig HOG's false boxes lower the IoU, docs/init.md), HOG
//    boxes with little foreground are filled by GrabCut before the
//    cross-view check (AddDetectedPeople), for people who stand still and
//    are thus in the background model. OpenCV's HOG people
//    detector (Dalal-Triggs, HOGDescriptor::getDefaultPeopleDetector, 64x128 windows; the image is
//    upscaled so that people of min_person_height_px fit the window) gives
//    boxes: a component holding two or more boxes whose centres are apart
//    horizontally is split between them (each pixel goes to the box whose
//    centre column is nearest, among the boxes containing it when any does).
//    Without detections, a component is split at a deep valley of its column
//    profile (people standing side by side touching with an arm). With
//    require_detection, components no box overlaps are dropped. Optionally
//    each instance is refined by cv::grabCut seeded from the mask (sure
//    foreground = eroded mask, probable foreground = the mask's convex hull,
//    probable background = a ring around the hull, background elsewhere in
//    its box and on other instances).
//
// Output: CV_16UC1 ids per view, 0 = background, 1..n local to the view
// (sorted left to right by the instance's centroid), the format of the
// capture's masks/ (io/instance_mask.h, docs/formats.md). Ids are NOT the
// same person across views or frames.
//
// Failure modes: throws u4d::Error on empty images, a size that differs
// between a frame and its background or camera, a non-BGR image, mismatched
// vector sizes, or bad options. It does not detect people who stand still
// for most of the sampled frames (they become background), nor separate
// people who overlap in a view without a HOG detection for each.
#pragma once

#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"
#include "u4d/io/instance_mask.h"

namespace u4d {

struct BackgroundOptions {
  int max_frames = 25;  // frames sampled evenly over the sequence for the median (>= 1)

  void Check() const;  // throws u4d::Error when max_frames < 1
};

// A static camera's background.
struct BackgroundModel {
  cv::Mat lab;          // CV_8UC3 per-pixel median in OpenCV 8-bit Lab
  cv::Mat bgr;          // CV_8UC3 the same in BGR (for pictures)
  cv::Mat pixel_sigma;  // CV_32FC1 per-pixel noise level (Lab units)
  double sigma = 0;     // global noise level (Lab units), see above
  int frames_used = 0;  // frames in the median

  bool Empty() const { return lab.empty(); }
  int Width() const { return lab.cols; }
  int Height() const { return lab.rows; }
};

// From BGR frames (CV_8UC3, all the same size). Uses up to max_frames of
// them, evenly spread. Throws on no frames, an empty or non-BGR frame, or
// differing sizes (naming the frame index).
BackgroundModel EstimateBackground(const std::vector<cv::Mat>& frames,
                                   const BackgroundOptions& options = {});
// The same, reading frame k in [0, num_frames) through `read_frame` (e.g. a
// FrameReader); only the sampled frames are read, in increasing order.
BackgroundModel EstimateBackground(int num_frames, const std::function<cv::Mat(int)>& read_frame,
                                   const BackgroundOptions& options = {});

struct InitOptions {
  // Foreground (step 2).
  double threshold_sigmas = 4.0;      // foreground: distance > this * noise level
  double min_noise_sigma = 2.0;       // floor of the noise level (Lab units)
  bool suppress_shadows = true;       // classify darker, same-chroma pixels as background
  double shadow_min_ratio = 0.45;     // shadow: L / L_background >= this
  double shadow_max_ratio = 0.95;     // shadow: L / L_background <= this
  double shadow_chroma_sigmas = 3.0;  // shadow: chroma change <= this * noise level
  int morph_radius_px = 0;            // opening/closing radius; 0 = 1 px per 360 px of height
  double min_blob_fraction = 2e-4;    // components (and holes) smaller than this * area go
  // Cross-view consistency (step 3).
  bool cross_view = true;                // run it when >= 2 calibrated views are given
  int consistency_max_side = 160;        // longest image side at which rays are tested (px)
  double step_px = 0.8;                  // ray march step: projected motion in other views (px)
  double min_depth_m = 0.3;              // nearest depth tested (m)
  double max_depth_m = 0;                // farthest; 0 = 1.5 x the largest camera baseline
  double min_view_fraction = 0.75;       // of the other views seeing the point, in foreground
  int min_views_seeing = 2;              // a depth counts only when this many others see it
                                         // (capped at views - 1)
  int consistency_dilation_px = 1;       // dilation of the other views' masks (reduced px)
  double min_consistent_fraction = 0.3;  // a component is kept above this consistent share
  bool carve_pixels = false;             // also drop inconsistent pixels in kept components
  // People instances (step 4).
  bool use_hog = true;                  // split/confirm components with HOG people boxes
  double hog_threshold = 0.0;           // HOG SVM hit threshold (higher: fewer boxes)
  int min_person_height_px = 96;        // upscale so that people this tall fit 128 px windows
  int hog_max_side = 800;               // longest side at which HOG runs (downscale above)
  bool require_detection = false;       // drop components with no HOG box
  int group_radius_px = 0;              // fragments closer than this are one instance; 0 = h/100
  double box_min_coverage = 0.25;       // HOG boxes with less foreground get GrabCut (below)
  int grabcut_box_iterations = 0;       // GrabCut iterations in such boxes; 0 = off (see docs)
  bool split_by_profile = true;         // split wide components at column-profile valleys
  double profile_valley_ratio = 0.3;    // valley < this * the smaller neighbouring peak
  double min_instance_fraction = 5e-4;  // instances smaller than this * area are dropped
  int grabcut_iterations = 0;           // cv::grabCut iterations per instance; 0 = off
  int grabcut_max_side = 200;           // instance box is downscaled to this side for GrabCut

  void Check() const;  // throws u4d::Error naming the offending field
};

// Step 2: CV_8UC1 mask (255 = foreground) of a BGR image against its view's
// background. Throws on an empty image, a non-BGR image or a size mismatch.
cv::Mat ForegroundMask(const cv::Mat& image_bgr, const BackgroundModel& background,
                       const InitOptions& options = {});

// Step 3: the masks (CV_8UC1, one per view, same sizes as the cameras) with
// the cross-view-inconsistent foreground removed. `consistent_share`
// (optional) receives per view the share of foreground pixels consistent at
// the reduced resolution. Throws on size mismatches or fewer than 2 views.
std::vector<cv::Mat> CrossViewConsistentMasks(const std::vector<Camera>& cameras,
                                              const std::vector<cv::Mat>& masks,
                                              const InitOptions& options = {},
                                              std::vector<double>* consistent_share = nullptr);

// Step 4: HOG people boxes (pixels of `image_bgr`) with their SVM scores.
struct PersonBox {
  cv::Rect box;
  double score = 0;
};
std::vector<PersonBox> DetectPeople(const cv::Mat& image_bgr, const InitOptions& options = {});

// Step 4a: the foreground plus, in every HOG box whose foreground covers
// less than box_min_coverage of it (a person standing still is part of the
// background), what cv::grabCut finds in the box: probable foreground in its
// central half and on the existing foreground, probable background in the
// rest of the box, background in a margin around it. Cleaned as step 2.
cv::Mat AddDetectedPeople(const cv::Mat& image_bgr, const cv::Mat& foreground,
                          const std::vector<PersonBox>& boxes, const InitOptions& options = {});

// Step 4: instance ids (CV_16UC1, 1..n left to right) from a foreground mask
// and the image; `boxes` as from DetectPeople (may be empty).
cv::Mat SplitInstances(const cv::Mat& image_bgr, const cv::Mat& foreground,
                       const std::vector<PersonBox>& boxes, const InitOptions& options = {});

// The whole chain for one time step: cameras[v], images_t[v] (BGR) and
// backgrounds[v] per view; cameras may be empty (no cross-view check).
// Returns CV_16UC1 ids per view (0 = background, 1..n per view).
std::vector<cv::Mat> UnsupervisedInstanceMasks(const std::vector<Camera>& cameras,
                                               const std::vector<cv::Mat>& images_t,
                                               const std::vector<BackgroundModel>& backgrounds,
                                               const InitOptions& options = {});

// The ids as an InstanceMask (class "person", score 1 for every id present),
// ready for WriteInstanceMask.
InstanceMask ToInstanceMask(const cv::Mat& ids);

}  // namespace u4d
