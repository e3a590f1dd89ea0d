// Objects the detector missed in every view (issue 27): a detector trained
// on a fixed list of classes (COCO has no box) gives no mask for a prop at
// all, so no view's masks can lend it to another. With given masks on static
// cameras, the foreground against each view's background (init/init.h steps
// 1 and 2: a clean plate when the capture has one, else the median of its
// frames; without its ghosts, step 5) that no given instance explains, and that the other views'
// unexplained foreground confirms (init.h step 3 on those masks alone),
// becomes an instance of class `class_name` in the view's masks. The initial
// stage then makes an object of it like any instance of a class that is not
// a person (initial_objects.h).
//
// Why these rules:
//   - A prop that stays where the background has it is background; one that
//     moved is foreground, and so found.
//   - A person's part that one view's detector dropped (a forearm, a foot)
//     lies inside a given instance in the other views, so it is not their
//     unexplained foreground and fails the cross-view check (the solve's hull
//     support brings such parts back to the person, joint/hull_support.h).
//   - Near a given instance (margin_px) the foreground is its boundary error,
//     not a new object.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "u4d/geometry/camera.h"
#include "u4d/init/chroma_key.h"
#include "u4d/init/init.h"
#include "u4d/io/instance_mask.h"

namespace u4d {

struct UnlabelledObjectOptions {
  bool enabled = true;  // look for them (given masks, static cameras)
  // Foreground within this distance of a given instance is that instance's
  // (its boundary error); 0 = 1 px per 60 px of image height.
  int margin_px = 0;
  // Of the other views that see a point of the unexplained foreground, the
  // share whose unexplained foreground holds it too (init.h
  // CrossViewOptions::min_view_fraction; lower than the people's, because
  // people in front of a prop hide it in some views).
  double min_view_fraction = 0.5;
  // Components smaller than this share of the image's pixels are dropped.
  double min_area_fraction = 1e-3;
  std::string class_name = "object";  // the class of what is found

  void Check() const;  // throws u4d::Error naming the bad field
};

// CV_8U, 255 where an instance of `given` lies within margin_px: the pixels
// its instances explain. Empty for a view without a mask. The background
// median leaves these pixels out of the frame's vote (init.h
// EstimateBackground), so that a person who stood on a pixel in most frames
// does not leave a ghost there that would become an object.
cv::Mat ExplainedPixels(const InstanceMask& given, const UnlabelledObjectOptions& options);

// Per view: CV_8U (255 = the foreground of `images[v]` that no instance of
// `given[v]` explains and the other views confirm). `backgrounds[v]` is
// used for a view that `keys` (empty = none) does not key; a keyed view's
// foreground is its chroma key's. A view whose `given` ids are empty (no mask
// file: the detector did not run there) has none. Throws on size mismatches
// or fewer than 2 views.
std::vector<cv::Mat> UnexplainedForeground(const std::vector<Camera>& cameras,
                                           const std::vector<cv::Mat>& images,
                                           const std::vector<BackgroundModel>& backgrounds,
                                           const std::vector<ChromaKey>& keys,
                                           const std::vector<InstanceMask>& given,
                                           const InitOptions& init,
                                           const UnlabelledObjectOptions& options);

// Each connected component of `unexplained[v]` of at least
// min_area_fraction of the image becomes a new instance of given[v] (class
// options.class_name, score 1, ids after the largest given id); a view
// without a mask gets none. Returns the number of instances added. Throws
// when the vectors' lengths or a view's sizes differ.
int AddUnlabelledObjects(const std::vector<cv::Mat>& unexplained,
                         const UnlabelledObjectOptions& options, std::vector<InstanceMask>* given);

}  // namespace u4d
