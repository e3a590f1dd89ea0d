#include "u4d/joint/joint_energy.h"

namespace u4d {

double JointEnergy::EnergyOf(const JointLabelling& labelling) const {
  double e = 0;
  for (int p = 0; p < num_pixels; ++p) {
    if (!grid.IsActive(p)) continue;
    e += LabelUnary(p, labelling.labels[p]) + DepthOnlyUnary(p, labelling.depths[p]) +
         MotionOnlyUnary(p, labelling.motion_vectors[p], labelling.flow_costs[p]) +
         Pose3d(p, labelling.labels[p], labelling.depths[p], labelling.motion_vectors[p]);
  }
  for (const auto& [p, q] : pairs)
    if (grid.IsActive(p) || grid.IsActive(q))
      e += Pair(p, q, labelling.labels[p], labelling.labels[q], labelling.depths[p],
                labelling.depths[q], labelling.motion_vectors[p], labelling.motion_vectors[q]);
  return e;
}

void JointEnergy::SetMotionsFromLabels(JointLabelling* labelling) const {
  labelling->motion_vectors.resize(num_pixels);
  labelling->flow_costs.resize(num_pixels);
  for (int p = 0; p < num_pixels; ++p) {
    labelling->motion_vectors[p] = motion.motions[labelling->motions[p]];
    labelling->flow_costs[p] = motion.At(p, labelling->motions[p]);
  }
}

}  // namespace u4d
