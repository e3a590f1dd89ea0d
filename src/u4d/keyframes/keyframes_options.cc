#include "u4d/keyframes/keyframes_options.h"

namespace u4d {

void DeclareOptions(OptionRegistry& r, KeyframeOptions* o) {
  r.Add("threshold", &o->threshold, "frames are similar when KS > threshold (paper: 0.75)");
  r.Add("use_correspondence", &o->use_correspondence, "term M");
  r.Add("use_semantic", &o->use_semantic, "term L");
  r.Add("use_distance", &o->use_distance, "term D");
  r.Add("use_pose", &o->use_pose, "term P");
  r.Add("use_shape", &o->use_shape, "term I");
  r.Add("distance_scale", &o->distance_scale,
        "D saturates (= 1) at a centroid shift of this fraction of the image diagonal");
  r.Add("pose_scale_m", &o->pose_scale_m, "P saturates at this root-relative MPJPE (m)");
  r.Add("min_common_joints", &o->min_common_joints,
        "two poses with fewer common joints count as dissimilar (P = 1)");
  r.Add("view_median", &o->view_median,
        "KS is the median over the views of their own KS (robust to one view's detector "
        "failure); false: the paper's mean over the views");
}

}  // namespace u4d
