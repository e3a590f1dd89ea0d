// The flow of a view's objects at the camera's size. The joint solve runs at
// a working resolution (frame_setup.working_width), so its flow, upscaled,
// carries the working pixel's imprecision into every camera pixel; the
// camera's image resolves the motion more finely. The paper's e_F^T
// (brightness constancy, Sec. 2.1) decides, at the camera's size, between
// the solve's motion, the camera-size dense matches (the whole image's and
// each object's own) and the frame before's motion carried forward, pixel
// by pixel; a median inside each object then outvotes the pixels whose pick
// went wrong.
#pragma once

#include <opencv2/core.hpp>

namespace u4d {

// For every pixel of an object (`labels` > 0) the flow becomes the one of
// the candidate fields with the lowest brightness-constancy error summed
// over the `window_px` square around it:
//  - the solve's flow upscaled (`flow`, in place);
//  - the dense match of `image_t` to `image_t1` (baselines::DenseFlow
//    kDisFine, the solve's own fusion proposal, here at camera size),
//    computed in the objects' bounding box grown by a tenth of the width, at
//    least the window and 16 pixels;
//  - with `labels_t1` (the objects at t+1, CV_16U; empty = none), the
//    object's own match at each object's pixels: the same dense match
//    between the two images with every pixel outside the object (its labels
//    at t, resp. t+1, grown by kObjectMatchMarginPx) set to mid-grey, in the
//    object's bounding box at t and t+1 grown by a fifth of its width and
//    16 pixels. A neighbour that moves otherwise is then not in the picture:
//    the whole image's match lets it drag the pixels of a person it
//    overlaps (a striped shirt matches one stripe over in either
//    direction; dark trousers match anything). An object absent from
//    `labels_t1` has no such candidate.
//  - with `carried` (CV_32FC2, camera size; empty = none), that field: the
//    motion of the frame before carried forward (CarriedObjectFlow below).
// An image under 16 pixels on both sides keeps its flow. A field's error at
// a pixel is |I_t1(p + f(p)) − I_t(p)| summed over the colour channels
// (I_t1 bilinear, the border replicated).
// Background pixels (label 0) keep their flow: the camera's, which the
// solve computes from the calibration. Everything has the camera's size:
// CV_16U labels, BGR 8-bit images, CV_32FC2 flow. Throws u4d::Error on a
// size or type mismatch or a window that is not odd and positive.
void RefineFlowAtCameraSize(const cv::Mat& labels, const cv::Mat& image_t, const cv::Mat& image_t1,
                            int window_px, cv::Mat* flow, const cv::Mat& labels_t1 = {},
                            const cv::Mat& carried = {});

// The objects' motion of the frame before, carried forward along itself
// (constant velocity): a candidate for the pick above that the two images
// alone do not offer. The paper's temporal coherence (Sec. 2.1.1) follows
// each surface point through the sequence; a limb in flight keeps most of
// its motion from one frame to the next, while in the pair (t, t+1) its
// blurred, weakly textured pixels match a slower neighbour as well. Each
// object pixel p of `labels_prev` (frame t-1, CV_16U) moves with its flow
// `flow_prev` (t-1 -> t, CV_32FC2) to q = p + f(p), rounded; where q lies
// in the image on the same object's `labels` at t, q takes that motion
// again (the mean where several pixels reach q). Every other pixel keeps
// `flow`'s motion, so that there the candidate never beats it. All four of
// one size; throws u4d::Error on a size or type mismatch.
cv::Mat CarriedObjectFlow(const cv::Mat& labels_prev, const cv::Mat& flow_prev,
                          const cv::Mat& labels, const cv::Mat& flow);

// The flow of every object pixel (`labels` > 0) becomes the per-component
// median of the flows of the pixels of its own object in the `window_px`
// square around it (clipped to the image): a pixel that took another motion
// than its neighbours (a wrong match in a weak texture, an ambiguous pick of
// the step above) is outvoted. This is the median filtering of classic flow
// methods (Sun, Roth and Black, "Secrets of optical flow estimation and their
// principles", CVPR 2010: a 5x5 median at each warping step, weighted there
// so that it does not cross motion boundaries), here kept inside each object
// by its labels. Near a boundary the window's pixels of other objects and of
// the background, which move otherwise, do not vote: an object's edge takes
// its own object's motion. The camera-size step above errs most there, as its
// brightness window straddles the boundary. Background pixels keep their flow.
// CV_16U labels and CV_32FC2 flow of one size; throws u4d::Error on a
// mismatch or a window that is not odd and positive.
void MedianFilterObjectFlow(const cv::Mat& labels, int window_px, cv::Mat* flow);

// The forward-backward check of the objects' flow (Sundaram, Brox and
// Keutzer, "Dense point trajectories by GPU-accelerated large displacement
// optical flow", ECCV 2010), the paper's "areas with low confidence" of E_r
// (Sec. 2.1) made explicit: a pixel p of object k whose match q = p + f(p)
// (rounded) lies on k's labels at t+1 is inconsistent when the backward flow
// b there does not lead back,
//   |f(p) + b(q)|^2 > 0.01 (|f(p)|^2 + |b(q)|^2) + 0.5   (their Eq. 5),
// b being each object's own match from t+1 to t (the rest of the images
// greyed out, as above). Such a pixel's surface is occluded at t+1 or its
// match went wrong in a weak texture, where brightness cannot tell; it takes
// the motion of its object's consistent pixels around it instead: the
// affine motion fitted by least squares to those within `radius_px` (the
// radius doubled, up to 8 times, until at least 20 of them, sampled every
// other pixel, are found; else the pixel keeps its flow), where that motion
// takes it onto its object's labels at t+1. A fill that lands on another
// label or off the image is not taken: the fit around a pixel next to an
// occluder is the least sure, and the labels at t+1 say where the object is
// seen. A pixel whose match leaves the image or lands on another label at
// t+1 is not judged (the labels' own error there is the size of the check)
// and does not serve as support. Background pixels keep their flow, and all pixels do
// where `labels_t1` is empty (no objects known at t+1). CV_16U labels of
// one size as the BGR 8-bit images and the CV_32FC2 flow; throws
// u4d::Error on a mismatch or a radius below 1.
void FillInconsistentObjectFlow(const cv::Mat& labels, const cv::Mat& labels_t1,
                                const cv::Mat& image_t, const cv::Mat& image_t1, int radius_px,
                                cv::Mat* flow);

// The variational refinement of the objects' flow (Brox et al.'s
// continuous energy as OpenCV's cv::VariationalRefinement computes it, the
// last step of DIS, Kroeger et al., ECCV 2016): brightness and gradient
// constancy with a smoothness term, minimised by `iterations` fixed-point
// iterations at the camera's size from the flow given. The picks above
// choose between whole-pixel-accurate candidates and the median and the
// fill copy their neighbours' motion, so the field is piecewise right but
// not at the sub-pixel optimum of its data; the refinement moves the field
// towards it, with the smoothness that keeps a weak texture from wandering
// (where the texture is weak, only part of the way: its data term is weak
// there too).
// It runs on each object's own pair of images (the rest greyed out, as for
// its own match above), so the motion of the background or of another
// object does not pull its edge: in the crop, the pixels outside the object
// start from the flow of their nearest object pixel, and only the object's
// pixels take the result. An object absent from `labels_t1`, and all of
// them where `labels_t1` is empty, keep their flow; so does the background.
// CV_16U labels of one size as the BGR 8-bit images and the CV_32FC2 flow;
// throws u4d::Error on a mismatch or `iterations` below 1.
void RefineObjectFlowVariationally(const cv::Mat& labels, const cv::Mat& labels_t1,
                                   const cv::Mat& image_t, const cv::Mat& image_t1, int iterations,
                                   cv::Mat* flow);

// Pixels by which an object's labels are grown before the rest of the image
// is greyed out for its own match: a detector's or the solve's boundary errs
// by about this much, and the object's silhouette edge stays in the picture.
inline constexpr int kObjectMatchMarginPx = 2;

}  // namespace u4d
